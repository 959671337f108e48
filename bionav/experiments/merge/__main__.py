"""``python -m bionav.experiments.merge OUT TASK_DIR...``: the command line of :mod:`bionav.experiments.merge`."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from bionav.errors import UserError
from bionav.experiments.merge import merge_tasks


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m bionav.experiments.merge",
                                description="Join the tasks (experiment.block=[i,n]) of a split run into one run "
                                            "directory with the unsplit run's files (grid_homing, cross_db, "
                                            "route_homing with experiment.protocol=ardin2016).")
    p.add_argument("out", help="directory for the merged run")
    p.add_argument("tasks", nargs="+", help="the tasks' run directories")
    args = p.parse_args(argv)
    try:
        metrics = merge_tasks([Path(t) for t in args.tasks], Path(args.out))
    except UserError as exc:
        print(f"bionav.experiments.merge: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        print(f"bionav.experiments.merge: error: cannot write {exc.filename or args.out}: {exc.strerror or exc}. "
              f"Free space or choose another OUT; the tasks are untouched.", file=sys.stderr)
        return 1
    if "aae" in metrics:
        print(f"merged {metrics['tasks']} {metrics['experiment']} tasks: AAE*={metrics['aae']:.4f} rad, "
              f"MAE*={metrics['mae']:.4f} rad, RR*={metrics['rr']:.4f} -> {args.out}")
    else:
        print(f"merged {metrics['tasks']} {metrics['experiment']} tasks -> {args.out}")
    return 0


if __name__ == "__main__":
    from bionav.cli_main import run_main

    run_main(main, "bionav.experiments.merge")
