"""``experiment=cross_db``: snapshots from one database, current views from another (thesis 5.1.4); splits into tasks."""

from __future__ import annotations

from typing import Any

from bionav.experiments.base import Experiment
from bionav.experiments.cross_db.config import CrossDbConfig


class CrossDb(Experiment):
    """The cross-database test (cross_db.csv, the heatmaps of fig. 5.6)."""

    Config = CrossDbConfig
    plugin_groups = ("homing", "signature")

    @staticmethod
    def merge(task_dirs, out) -> dict[str, Any]:
        """Join the tasks (``experiment.block=[i,n]``) of one split run into ``out`` (``python -m bionav.experiments.merge``)."""
        from bionav.experiments.cross_db.merge import merge

        return merge(task_dirs, out)

    def run(self, ctx) -> dict[str, Any]:
        """One run, or one task of a split run (``experiment.block=[i,n]``: ``cross_db.run.task_units``)."""
        from bionav.experiments.cross_db.run import run

        return run(self.config, ctx)
