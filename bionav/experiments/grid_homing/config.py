"""Config of ``experiment=grid_homing``.

Units: grid units as named. Checked by the runner before the run
(:func:`bionav.experiments.settings.experiment_config`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

from bionav.experiments.ranges import RADIUS, STEP
from bionav.validation import Range, bounded


@dataclass
class GridHomingConfig:
    """``experiment=grid_homing``: every snapshot position against every other position.

    step_length, success_radius : agent step and success radius, grid units (thesis 3.2.3).
    n_quiver_plots : quiver plots of home-vector fields for this many snapshots.
    snapshots : only these snapshot indices (None = all); handy for quick looks.
    block : ``[i, n]``: only every n-th of those snapshots, starting at the i-th (0 <= i < n): one
        task of a run split into n; ``python -m bionav.experiments.merge`` joins the
        tasks into the unsplit run's files, with identical measures.
    log_views : also write every view to run.mcap (``/grid_homing/views``, ``foxglove.RawImage``, 32-bit float):
        for Foxglove, the live view (``bionav.live``) and ``python -m bionav.logs export-ros2``.
    """

    name: str = "grid_homing"
    step_length: float = bounded(0.5, **STEP)
    success_radius: float = bounded(1.0, **RADIUS)
    n_quiver_plots: int = bounded(4, ge=0, le=1000)
    snapshots: Optional[list[int]] = bounded(None, length=(1, 1_000_000), item=Range(ge=0, le=10**8))
    block: Optional[list[int]] = bounded(None, length=(2, 2), item=Range(ge=0, le=10**6))
    log_views: bool = False
