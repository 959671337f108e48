"""Config of ``experiment=param_sweep`` (thesis 5.2.1, tables 5.5-5.7).

Units: grid units as named. Checked by the runner before the run
(:func:`bionav.experiments.settings.experiment_config`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from omegaconf import II

from bionav.experiments.ranges import RADIUS, STEP
from bionav.validation import Range, bounded


@dataclass
class ParamSweepConfig:
    """``experiment=param_sweep`` (thesis 5.2.1, tables 5.5-5.7), run as a multirun.

    grid : which sweep grid of ``grids`` the sweeper and the jobs use (``full`` = the thesis', ``ci`` = reduced).
    grids : named sweep grids: ``signature``, ``image_size``, ``preprocess`` (sweeper values) and
        ``rings``, ``n_coeffs`` (evaluated inside each job); the preset ``conf/experiment/param_sweep.yaml``
        holds ``full`` (the thesis') and ``ci`` next to the sweeper parameters that use them.
    rings, n_coeffs : the values each job evaluates (from the selected grid unless overridden).
    scope : ``job`` -- one signature x image size x preprocessing per run (the multirun's jobs);
        ``grid`` -- every signature x image size x preprocessing of the grid in one run on
        ``workers`` processes (``experiment=param_sweep_grid``).
    """

    name: str = "param_sweep"
    scope: str = bounded("job", choices=("job", "grid"))
    grid: str = "full"
    grids: dict[str, Any] = field(default_factory=dict)
    rings: list[int] = bounded(II("experiment.grids.${experiment.grid}.rings"), length=(1, 1000),
                               item=Range(ge=1, le=1000))
    n_coeffs: list[int] = bounded(II("experiment.grids.${experiment.grid}.n_coeffs"), length=(1, 1000),
                                  item=Range(ge=1, le=1000))
    step_length: float = bounded(0.5, **STEP)
    success_radius: float = bounded(1.0, **RADIUS)
