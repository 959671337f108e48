"""``experiment=pol_recordings``: the polarized-light compass on real skies (recorded POL-OP rotations)."""

from __future__ import annotations

from typing import Any

from bionav.experiments.base import Experiment
from bionav.experiments.pol_recordings.config import PolRecordingsConfig
from bionav.polcompass.recordings_config import RecordingsConfig


class PolRecordings(Experiment):
    """Every decoder scored on every sample of the recordings (``recordings.path=DIR``)."""

    Config = PolRecordingsConfig
    plugin_groups = ("decoder",)
    group_configs = {"recordings": RecordingsConfig}

    def run(self, ctx) -> dict[str, Any]:
        from bionav.experiments.pol_recordings.run import run

        return run(self.config, ctx)
