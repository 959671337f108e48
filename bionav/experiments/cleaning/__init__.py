"""``experiment=cleaning``: meandering cleaning runs of a simulated robot (thesis chapter 7)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from bionav.experiments.base import Experiment
from bionav.experiments.cleaning.config import CleaningConfig
from bionav.robot.layout import LayoutConfig


class Cleaning(Experiment):
    """Cleaning runs of the lane controller (metrics.json, cleaning_runs.csv, trajectories and overlap maps)."""

    Config = CleaningConfig
    plugin_groups = ("controller", "homing")
    group_configs = {"layout": LayoutConfig}

    def run(self, ctx) -> dict[str, Any]:
        from bionav.experiments.cleaning.run import run

        return run(self.config, ctx)

    @staticmethod
    def replay(path: Path, *, runs: list[int] | None = None) -> dict[int, Any]:
        """Replay the runs of a cleaning ``run.mcap`` (``python -m bionav.experiments.cleaning_replay``)."""
        from bionav.experiments.cleaning.replay import replay_log

        return replay_log(path, runs=runs)
