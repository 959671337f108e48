"""Panorama geometry and angle conventions shared by every part of bionav.

Conventions (used everywhere unless a docstring says otherwise)
-------------------------------------------------------------
* Angles are radians. Positive rotation is counter-clockwise seen from above
  (right-handed grid frame: +x to the right, +y up, +z towards the sky).
* The *grid frame* is the frame of a database's capture grid: a position is
  ``(x, y)`` in grid units (integer indices for grid cells). The home direction
  from current view ``c`` to snapshot ``s`` is ``atan2(s_y - c_y, s_x - c_x)``.
* A *canonical panorama* is an unfolded image of shape ``(H, W)`` (or
  ``(H, W, C)``) in which column ``j`` looks along azimuth
  ``2 * pi * j / W`` measured counter-clockwise from the robot's heading.
  Databases convert their images to canonical panoramas when loading (they
  mirror clockwise images and roll the heading column to column 0), so homing
  methods never see on-disk conventions.
* Rows: row 0 is the top of the image; the elevation of row ``r`` is
  ``(horizon_row - r) * rad_per_row`` (positive above the horizon).
* A robot with heading ``phi`` (CCW from grid +x) sees grid azimuth
  ``phi + 2*pi*j/W`` in column ``j``. An angle returned by a homing method lives
  in the *current view's own frame*; add the current view's heading to get the
  grid-frame angle.

ENU frame (sky, sun, outdoor worlds, compass headings)
------------------------------------------------------
* x east, y north, z up. A direction is a unit vector ``(..., 3)``.
* *Azimuth*: radians counter-clockwise from east seen from above (the grid
  frame's convention with +x east and +y north); *elevation*: radians above
  the horizon. Functions take ``(azimuth, elevation)`` in that order.
* *Compass bearing*: radians clockwise from north (what magnetic compasses and
  ephemerides report); convert with :func:`compass_to_azimuth` and
  :func:`azimuth_to_compass`.
* *Axial* angles (e-vectors, polarizer axes) have period ``pi``; wrap them
  with :func:`wrap_axial`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

TWO_PI = 2.0 * np.pi


def wrap_angle(angle):
    """Wrap angles to ``[-pi, pi)``.

    Parameters
    ----------
    angle : float or ndarray
        Angle(s) in radians.

    Returns
    -------
    float or ndarray
        The same angle(s) wrapped to ``[-pi, pi)``.
    """
    return (np.asarray(angle) + np.pi) % TWO_PI - np.pi


def angular_difference(a, b):
    """Absolute angular difference ``|wrap(a - b)|`` in ``[0, pi]`` (radians)."""
    return np.abs(wrap_angle(np.asarray(a) - np.asarray(b)))


def wrap_axial(angle):
    """Wrap axial angles (period ``pi``, e.g. e-vector orientations) to ``[-pi/2, pi/2)`` (radians)."""
    return (np.asarray(angle) + np.pi / 2.0) % np.pi - np.pi / 2.0


def parabolic_peak_offset(y_before, y_at, y_after):
    """Sub-step position of a peak on an evenly spaced (e.g. angular) grid.

    The vertex of the parabola through ``(-1, y_before)``, ``(0, y_at)`` and
    ``(1, y_after)``, in grid steps from the middle sample, where the three
    samples bend down (``y_at`` the largest: a maximum); 0 where they do not.
    At a grid maximum the offset lies in ``[-0.5, 0.5]``; it is clipped there.
    For a minimum pass the negated values. Shapes broadcast; returns an
    ndarray (0-d for scalars).
    """
    y0, y1, y2 = (np.asarray(v, float) for v in (y_before, y_at, y_after))
    den = y0 - 2.0 * y1 + y2
    peaked = den < 0.0
    return np.clip(np.where(peaked, 0.5 * (y0 - y2) / np.where(peaked, den, -1.0), 0.0), -0.5, 0.5)


# --- ENU frame ---------------------------------------------------------------------------------


def direction_from_angles(azimuth, elevation):
    """Unit vectors from azimuth and elevation (ENU frame).

    Parameters
    ----------
    azimuth, elevation : float or ndarray
        Radians; azimuth counter-clockwise from east, elevation above the
        horizon. Broadcast against each other.

    Returns
    -------
    ndarray, shape ``(..., 3)``
        ``(cos e cos a, cos e sin a, sin e)``: x east, y north, z up.
    """
    azimuth, elevation = np.broadcast_arrays(np.asarray(azimuth, float), np.asarray(elevation, float))
    ce = np.cos(elevation)
    return np.stack([ce * np.cos(azimuth), ce * np.sin(azimuth), np.sin(elevation)], axis=-1)


def angles_from_direction(direction):
    """Azimuth (counter-clockwise from east) and elevation (radians) of ENU vectors ``(..., 3)``."""
    d = np.asarray(direction, float)
    azimuth = np.arctan2(d[..., 1], d[..., 0])
    elevation = np.arctan2(d[..., 2], np.hypot(d[..., 0], d[..., 1]))
    return azimuth, elevation


def compass_to_azimuth(bearing):
    """Compass bearing (radians clockwise from north) to azimuth (radians counter-clockwise from east)."""
    return np.pi / 2.0 - np.asarray(bearing)


def azimuth_to_compass(azimuth):
    """Azimuth (radians counter-clockwise from east) to compass bearing clockwise from north, in ``[0, 2 pi)``."""
    return np.mod(np.pi / 2.0 - np.asarray(azimuth), 2.0 * np.pi)


@dataclass(frozen=True)
class PanoramaGeometry:
    """Pixel geometry of a canonical unfolded panorama.

    Parameters
    ----------
    width : int
        Number of columns ``W``; they span 360 degrees counter-clockwise,
        column 0 along the robot's heading.
    height : int
        Number of rows ``H``.
    horizon_row : float
        Row (may be fractional) that images the horizon (elevation 0).
    rad_per_row : float
        Elevation step per row in radians (rows grow downwards, elevation
        grows upwards).
    """

    width: int
    height: int
    horizon_row: float
    rad_per_row: float

    @classmethod
    def square_pixels(cls, width: int, height: int, *, horizon_row: float | None = None) -> "PanoramaGeometry":
        """Geometry where a pixel spans the same angle vertically and horizontally.

        The horizon defaults to the middle row, ``(height - 1) / 2``.
        """
        if horizon_row is None:
            horizon_row = (height - 1) / 2.0
        return cls(int(width), int(height), float(horizon_row), TWO_PI / width)

    @property
    def rad_per_column(self) -> float:
        """Azimuth step per column in radians (counter-clockwise)."""
        return TWO_PI / self.width

    def column_azimuths(self) -> np.ndarray:
        """Azimuth of every column, shape ``(W,)``, radians CCW from the heading."""
        return np.arange(self.width) * self.rad_per_column

    def row_elevations(self) -> np.ndarray:
        """Elevation of every row, shape ``(H,)``, radians, positive above the horizon."""
        return (self.horizon_row - np.arange(self.height)) * self.rad_per_row

    def resized(self, width: int, height: int) -> "PanoramaGeometry":
        """The same field of view sampled at another size (``H x W`` pixels)."""
        sy = height / self.height
        return PanoramaGeometry(
            int(width),
            int(height),
            (self.horizon_row + 0.5) * sy - 0.5,
            self.rad_per_row / sy,
        )
