"""Config of ``experiment=cross_db`` (thesis 5.1.4, fig. 5.6).

Units: grid units as named. Checked by the runner before the run
(:func:`bionav.experiments.settings.experiment_config`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

from bionav.experiments.ranges import RADIUS, STEP
from bionav.validation import Range, bounded


@dataclass
class CrossDbConfig:
    """``experiment=cross_db`` (thesis 5.1.4, fig. 5.6): snapshots from one database, current views from another.

    family : databases sharing one grid (``db.image_size``, ``db.seed``, ``db.noise`` apply to all).
    snapshot_stride : evaluate every k-th grid cell along x and y as snapshot (1 = all, as the thesis).
    block : ``[i, n]``: only every n-th of those snapshots, from the i-th, for every database pair
        (with more tasks than snapshots: every n-th (snapshot, database pair) unit,
        ``bionav.experiments.cross_db.run.task_units``): task i of a run split into n
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
