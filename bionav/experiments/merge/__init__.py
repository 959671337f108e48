"""``python -m bionav.experiments.merge OUT TASK_DIR...``: join the tasks of a split run.

The tasks are run directories of one experiment with ``experiment.block=[i,n]``
(:mod:`bionav.experiments.tasks`); the experiment's own ``merge`` writes the unsplit run's
files into OUT (``experiment=grid_homing`` and ``experiment=cross_db`` split this way).
"""

from __future__ import annotations

import importlib
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
