"""``python -m bionav.experiments.merge OUT TASK_DIR...``: join the tasks of a split run.

The tasks are run directories of one experiment with ``experiment.block=[i,n]``
(:mod:`bionav.experiments.tasks`); the experiment's own ``merge`` (the ``merge`` of its plugin
class, :class:`~bionav.experiments.base.Experiment`, found in the registry) writes the unsplit
run's files into OUT (``experiment=grid_homing`` and ``experiment=cross_db`` split this way).
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any, Sequence

from bionav import registry
from bionav.errors import UserError
from bionav.experiments.runner import read_metrics


def splittable() -> list[str]:
    """The installed experiments whose runs split into tasks (their plugin has a ``merge``)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a broken plugin is listed by python -m bionav.plugins
        plugins = registry.plugins_of("experiment", warn=False)
    return sorted(name for name, p in plugins.items() if p.cls is not None and callable(getattr(p.cls, "merge", None)))


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
    merge = None
    if isinstance(name, str) and name in registry.entry_points_of("experiment"):
        merge = getattr(registry.load_plugin("experiment", name), "merge", None)
    if not callable(merge):
        raise UserError(f"{task_dirs[0]} is not a task of a splittable run (its metrics.json names experiment "
                        f"{name!r}); the experiments that split into tasks are {', '.join(splittable())}.")
    return merge([Path(d) for d in task_dirs], Path(out))
