"""``experiment=skyline_homing``: outdoor homing from five-channel images under changing light (beyond thesis 6.5)."""

from __future__ import annotations

from typing import Any

from bionav.experiments.base import Experiment
from bionav.experiments.skyline_homing.config import SkylineHomingConfig


class SkylineHoming(Experiment):
    """Homing on channels, contrasts and skylines with snapshots and current views under different light."""

    Config = SkylineHomingConfig
    plugin_groups = ("homing",)

    def run(self, ctx) -> dict[str, Any]:
        from bionav.experiments.skyline_homing.run import run

        return run(self.config, ctx)
