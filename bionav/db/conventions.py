"""Conversion between on-disk panorama conventions and canonical panoramas.

An on-disk panorama of width ``W`` is described by two numbers:

* ``azimuth``: ``"clockwise"`` if the azimuth seen by a column grows
  clockwise (seen from above) with the column index, ``"counterclockwise"``
  otherwise;
* ``x_axis_column`` ``c0``: the (possibly fractional) column that looks along
  the grid's +x axis when the robot is aligned with the grid.

Column ``c`` of the disk image then looks at azimuth
``theta(c) = s * 2*pi * (c - c0) / W`` counter-clockwise from grid +x, with
``s = -1`` for clockwise and ``s = +1`` for counter-clockwise images. A
canonical panorama (:mod:`bionav.geometry`) needs ``theta = 2*pi*j / W`` in
column ``j``, so

    canonical[..., j] = disk[..., (c0 + s * j) mod W]

i.e. mirror the columns if clockwise, and roll so that +x is column 0. Rows
are not touched, so the horizon row and the vertical angle per pixel carry
over unchanged. A fractional ``c0`` is resolved by cyclic linear
interpolation between neighbouring columns.

The Bielefeld convention of Vardy's databases is ``azimuth="clockwise"``,
``x_axis_column=0``.
"""

from __future__ import annotations

import numpy as np

from bionav.errors import UserError

_CLOCKWISE = {"clockwise", "cw"}
_COUNTERCLOCKWISE = {"counterclockwise", "ccw", "anticlockwise", "counter-clockwise"}


def azimuth_sign(azimuth: str) -> int:
    """``-1`` for a clockwise on-disk azimuth, ``+1`` for counter-clockwise.

    Raises
    ------
    UserError
        For any other spelling.
    """
    key = str(azimuth).strip().lower()
    if key in _CLOCKWISE:
        return -1
    if key in _COUNTERCLOCKWISE:
        return 1
    raise UserError(
        f"db.azimuth={azimuth!r} is not a known azimuth direction; use db.azimuth=clockwise "
        "(azimuth grows clockwise with the column index, the Bielefeld convention) or "
        "db.azimuth=counterclockwise."
    )


def _sample_columns(images: np.ndarray, source_columns: np.ndarray) -> np.ndarray:
    """``out[..., j] = images[..., source_columns[j]]`` with cyclic linear interpolation."""
    width = images.shape[-1]
    base = np.floor(source_columns)
    frac = (source_columns - base).astype(np.float32)
    i0 = base.astype(np.int64) % width
    if not np.any(frac > 1e-9):
        step = (i0[1] - i0[0]) % width if width > 1 else 1
        if width > 1 and step in (1, width - 1) and np.array_equal(i0, (i0[0] + step * np.arange(width)) % width):
            # a pure roll, or a mirror followed by a roll: slicing is much faster than fancy indexing
            if step == 1:
                return np.roll(images, -int(i0[0]), axis=-1)
            return np.roll(images[..., ::-1], -(width - 1 - int(i0[0])), axis=-1)
        return np.ascontiguousarray(images[..., i0])
    i1 = (i0 + 1) % width
    out = images[..., i0] * (1.0 - frac) + images[..., i1] * frac
    return out.astype(images.dtype, copy=False)


def to_canonical(images: np.ndarray, *, azimuth: str = "clockwise", x_axis_column: float = 0.0) -> np.ndarray:
    """Convert on-disk panoramas to canonical panoramas.

    Parameters
    ----------
    images : ndarray, shape (..., W)
        One image ``(H, W)`` or a stack ``(N, H, W)``; the last axis runs over
        the columns (360 degrees).
    azimuth : {"clockwise", "counterclockwise"}
        How the azimuth grows with the on-disk column index.
    x_axis_column : float
        On-disk column (may be fractional) that looks along the grid's +x axis.

    Returns
    -------
    ndarray, same shape
        ``canonical[..., j] = disk[..., (x_axis_column + s * j) mod W]`` with
        ``s = -1`` (clockwise) or ``+1`` (counter-clockwise); column 0 looks
        along +x and the azimuth grows counter-clockwise.
    """
    images = np.asarray(images)
    width = images.shape[-1]
    s = azimuth_sign(azimuth)
    return _sample_columns(images, float(x_axis_column) + s * np.arange(width, dtype=np.float64))


def from_canonical(images: np.ndarray, *, azimuth: str = "clockwise", x_axis_column: float = 0.0) -> np.ndarray:
    """Inverse of :func:`to_canonical`: write canonical panoramas in an on-disk convention.

    ``disk[..., c] = canonical[..., s * (c - x_axis_column) mod W]``.
    """
    images = np.asarray(images)
    width = images.shape[-1]
    s = azimuth_sign(azimuth)
    return _sample_columns(images, s * (np.arange(width, dtype=np.float64) - float(x_axis_column)))
