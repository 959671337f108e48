"""``experiment=contrast_scan``: 2-D scans with the five-channel sensor on a pan-tilt unit (thesis 6.4, 6.5.1)."""

from __future__ import annotations

from typing import Any

from bionav.experiments.base import Experiment
from bionav.experiments.contrast_scan.config import ContrastScanConfig


class ContrastScan(Experiment):
    """Scans over a day: channel, contrast and separation images, stability of every feature."""

    Config = ContrastScanConfig
    plugin_groups = ("sensor", "pantilt")

    def run(self, ctx) -> dict[str, Any]:
        from bionav.experiments.contrast_scan.run import run

        return run(self.config, ctx)
