"""``experiment=grid_homing``: all-pairs homing on a grid database (thesis 3.2, 5.1); splits into tasks."""

from __future__ import annotations

from typing import Any

from bionav.experiments.base import Experiment
from bionav.experiments.grid_homing.config import GridHomingConfig


class GridHoming(Experiment):
    """All-pairs grid homing: every snapshot position against every other (metrics.json, per_snapshot.csv, plots/)."""

    Config = GridHomingConfig
    plugin_groups = ("homing", "signature")

    def run(self, ctx) -> dict[str, Any]:
        from bionav.experiments.grid_homing.run import run

        return run(self.config, ctx)

    @staticmethod
    def merge(task_dirs, out) -> dict[str, Any]:
        """Join the tasks (``experiment.block=[i,n]``) of one split run into ``out`` (``python -m bionav.experiments.merge``)."""
        from bionav.experiments.grid_homing.merge import merge

        return merge(task_dirs, out)
