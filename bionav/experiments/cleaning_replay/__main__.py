"""Command line of :mod:`bionav.experiments.cleaning_replay`."""

from __future__ import annotations

import argparse
import logging
from pathlib import Path

_DESCRIPTION = "replay logged cleaning runs and check that the controller emits the logged commands"


def main(argv: list[str] | None = None) -> int:
    from bionav import registry

    parser = argparse.ArgumentParser(prog="python -m bionav.experiments.cleaning_replay", description=_DESCRIPTION)
    parser.add_argument("log", help="run.mcap of an experiment=cleaning run, or its run directory")
    parser.add_argument("--run", type=int, action="append", help="only this run (repeatable)")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(levelname)s: %(message)s")  # e.g. legacy keys read as today's
    path = Path(args.log)
    if path.is_dir():
        path = path / "run.mcap"
    cleaning = registry.load_plugin("experiment", "cleaning")  # the experiment's own replay, from the registry
    results = cleaning.replay(path, runs=args.run)  # a UserError becomes "<prog>: error: ..." in run_main
    for k, r in results.items():
        print(f"run {k}: {r.n_ticks} ticks replayed, every command identical")
    return 0


if __name__ == "__main__":
    from bionav.cli_main import run_main

    run_main(main, "bionav.experiments.cleaning_replay")
