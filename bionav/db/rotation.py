"""Random rotation of views (Vardy's protocol for methods that need no aligned images)."""

from __future__ import annotations

import numpy as np

from bionav.db.database import ImageDatabase
from bionav.geometry import TWO_PI


def rotate_views(db: ImageDatabase, *, seed: int) -> ImageDatabase:
    """Rotate every view by a random whole number of columns (Vardy's protocol).

    Image ``i`` becomes ``roll(images[i], -s_i, axis=-1)`` with ``s_i``
    uniform in ``[0, W)`` from ``numpy.random.default_rng(seed)``, and its
    heading becomes ``headings[i] + 2*pi*s_i / W`` (radians CCW from grid +x):
    column ``j`` of the rotated image looks at grid azimuth
    ``heading + 2*pi*j / W`` as :mod:`bionav.geometry` requires.
    """
    rng = np.random.default_rng(seed)
    width = db.images.shape[-1]
    shifts = rng.integers(0, width, size=len(db))
    cols = (np.arange(width)[None, :] + shifts[:, None]) % width
    images = np.take_along_axis(db.images, cols[:, None, :], axis=-1)
    headings = (db.headings + TWO_PI * shifts / width) % TWO_PI
    meta = dict(db.meta, rotation_seed=int(seed), rotation_shifts=shifts.tolist())
    return ImageDatabase(name=db.name, images=images, positions=db.positions, grid_shape=db.grid_shape,
                         geometry=db.geometry, spacing_m=db.spacing_m, headings=headings, raw=db.raw,
                         meta=meta)
