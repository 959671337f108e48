"""Experiments: one module per experiment, each exposing ``run(cfg, ctx) -> metrics``."""
