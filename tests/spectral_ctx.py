"""A stand-in for the experiment runner's RunContext (only what the spectral experiments use)."""

from pathlib import Path

import numpy as np


class FakeLog:
    def __init__(self):
        self.messages = []

    def write(self, topic, message, *, schema_name, schema=None, log_time_ns=None):
        self.messages.append((topic, message, schema_name))


def run_with(cfg, ctx):
    """Run ``cfg.experiment`` in ``ctx`` as the runner hands it over (the plugin from the registry, its checked
    config and group nodes), without the runner's files."""
    from bionav.experiments.settings import check_group_nodes, experiment_class, experiment_config

    cls = experiment_class(str(cfg.experiment.name))
    ctx.cfg = cfg
    ctx.nodes = check_group_nodes(cfg, cls)
    return cls(experiment_config(cfg)).run(ctx)


class FakeContext:
    def __init__(self, tmp_path, seed=0):
        self.cfg = None
        self.nodes = {}
        self.dir = Path(tmp_path)
        self.plots = self.dir / "plots"
        self.plots.mkdir(exist_ok=True)
        self.rng = np.random.default_rng(seed)
        self.log = FakeLog()

    def progress(self, iterable, *, desc="", total=None):
        return iterable
