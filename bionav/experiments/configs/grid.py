"""Configs of homing on image grids: ``experiment=grid_homing``, ``cross_db``, ``param_sweep``.

Units: metres and grid units as named; angles in degrees only in keys ending ``_deg``; times ISO 8601
with zone. Checked by :func:`bionav.experiments.configs.experiment_config`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Optional

from omegaconf import II

from bionav.experiments.configs.ranges import RADIUS, STEP
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


@dataclass
class CrossDbConfig:
    """``experiment=cross_db`` (thesis 5.1.4, fig. 5.6): snapshots from one database, current views from another.

    family : databases sharing one grid (``db.image_size``, ``db.seed``, ``db.noise`` apply to all).
    snapshot_stride : evaluate every k-th grid cell along x and y as snapshot (1 = all, as the thesis).
    block : ``[i, n]``: only every n-th of those snapshots, from the i-th, for every database pair
        (with more tasks than snapshots: every n-th (snapshot, database pair) unit,
        ``bionav.experiments.cross_db.task_units``): task i of a run split into n
        (``python -m bionav.experiments.merge`` joins them).
    """

    name: str = "cross_db"
    family: list[str] = bounded(
        ["sim_original", "sim_arboreal", "sim_chairs", "sim_day", "sim_doorlit", "sim_screen", "sim_twilight",
         "sim_winlit"], length=(2, 100))
    snapshot_stride: int = bounded(2, ge=1, le=1000)
    step_length: float = bounded(0.5, **STEP)
    success_radius: float = bounded(1.0, **RADIUS)
    block: Optional[list[int]] = bounded(None, length=(2, 2), item=Range(ge=0, le=10**6))


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
