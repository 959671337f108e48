"""``experiment=param_sweep`` (and the preset ``param_sweep_grid``): the parameter-homing sweep of thesis 5.2.1."""

from __future__ import annotations

from typing import Any

from bionav.experiments.base import Experiment
from bionav.experiments.param_sweep.config import ParamSweepConfig


class ParamSweep(Experiment):
    """The parameter-homing sweep: one signature x image size x preprocessing per job, or the whole grid in one run."""

    Config = ParamSweepConfig
    plugin_groups = ("homing", "signature")

    def run(self, ctx) -> dict[str, Any]:
        if self.config.scope == "grid":
            from bionav.experiments.param_sweep.grid import run_grid

            return run_grid(self.config, ctx)
        from bionav.experiments.param_sweep.run import run

        return run(self.config, ctx)
