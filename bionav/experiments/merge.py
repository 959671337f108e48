"""``python -m bionav.experiments.merge OUT TASK_DIR...``: join the tasks of a split run.

The tasks are run directories of one experiment with ``experiment.block=[i,n]``
(:mod:`bionav.experiments.tasks`); the experiment's own ``merge`` writes the unsplit run's
files into OUT (``experiment=grid_homing`` and ``experiment=cross_db`` split this way).
"""

from __future__ import annotations

import argparse
import importlib
import sys
from pathlib import Path
from typing import Any, Sequence

from bionav.errors import UserError
from bionav.experiments.runner import read_metrics

#: experiments whose runs split into tasks
SPLITTABLE = ("grid_homing", "cross_db")


def merge_tasks(task_dirs: Sequence[Path], out: Path) -> dict[str, Any]:
    """Merge the tasks in ``task_dirs`` into ``out`` with their experiment's ``merge``; the merged metrics."""
    if not task_dirs:
        raise UserError("no task directories given; name the run directories of the tasks to merge.")
    for d in map(Path, task_dirs):
        if not d.is_dir() or not (d / "metrics.json").is_file():
            raise UserError(f"{d} is not a run directory (no metrics.json there); give the run directories of the "
                            f"tasks, e.g. the hydra.run.dir of each experiment.block=[i,n] run.")
    first = read_metrics(task_dirs[0]) or {}
    name = first.get("experiment")
    if name not in SPLITTABLE:
        raise UserError(f"{task_dirs[0]} is not a task of a splittable run (its metrics.json names experiment "
                        f"{name!r}); the experiments that split into tasks are {', '.join(SPLITTABLE)}.")
    return importlib.import_module(f"bionav.experiments.{name}").merge([Path(d) for d in task_dirs], Path(out))


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m bionav.experiments.merge",
                                description="Join the tasks (experiment.block=[i,n]) of a split run into one run "
                                            "directory with the unsplit run's files (grid_homing, cross_db).")
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
    print(f"merged {metrics['tasks']} {metrics['experiment']} tasks: AAE*={metrics['aae']:.4f} rad, "
          f"MAE*={metrics['mae']:.4f} rad, RR*={metrics['rr']:.4f} -> {args.out}")
    return 0


if __name__ == "__main__":
    from bionav.errors import run_main

    run_main(main, "bionav.experiments.merge")
