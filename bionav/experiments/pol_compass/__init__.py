"""``experiment=pol_compass``: the polarized-light compass of thesis chapter 4 (``mode=<name>`` picks the test)."""

from __future__ import annotations

from typing import Any

from bionav.experiments.base import Experiment
from bionav.experiments.pol_compass.config import PolCompassConfig


class PolCompass(Experiment):
    """The POL-OP compass on a pan-tilt unit: simulated, on hardware, recorded or replayed."""

    Config = PolCompassConfig
    plugin_groups = ("sensor", "pantilt", "decoder")

    def run(self, ctx) -> dict[str, Any]:
        from bionav.experiments.pol_compass.run import run

        return run(self.config, ctx)
