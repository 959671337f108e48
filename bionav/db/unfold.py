"""Unfolding raw omnidirectional (mirror) camera frames into panoramas."""

from __future__ import annotations

import cv2
import numpy as np


def _unfold_maps(center: tuple[float, float], inner_radius: float, outer_radius: float,
                 size: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    width, height = size
    phi = 2.0 * np.pi * np.arange(width) / width
    if height > 1:
        radius = outer_radius + (inner_radius - outer_radius) * np.arange(height) / (height - 1)
    else:
        radius = np.array([0.5 * (inner_radius + outer_radius)])
    map_x = (center[0] + radius[:, None] * np.cos(phi)[None, :]).astype(np.float32)
    map_y = (center[1] + radius[:, None] * np.sin(phi)[None, :]).astype(np.float32)
    return map_x, map_y


def unfold_panorama(raw: np.ndarray, *, center, inner_radius: float, outer_radius: float, size) -> np.ndarray:
    """Unfold a raw omnidirectional camera frame into a panorama (polar to rectangular).

    Column ``j`` of the output samples the ray at polar angle
    ``phi_j = 2*pi*j / W`` around ``center``, measured in the raw frame's pixel
    axes from +column towards +row (i.e. clockwise as the frame is displayed,
    x to the right, y downwards): the point
    ``(cx + r cos(phi_j), cy + r sin(phi_j))``. Row ``i`` samples the radius
    ``r_i = outer_radius + (inner_radius - outer_radius) * i / (H - 1)``, so
    row 0 (top) lies on the outer circle and the last row on the inner circle.
    Sampling is bilinear (``cv2.remap``); points outside the frame read 0.

    The unfolded image is an *on-disk* panorama: which azimuth direction and
    which column looks along the grid's +x depend on the mirror and the camera
    mounting and are given by ``db.azimuth`` and ``db.x_axis_column`` as for any
    other database (see :mod:`bionav.db.conventions`).

    Parameters
    ----------
    raw : ndarray, shape (h, w), float
        Raw camera frame (grey).
    center : sequence of 2 float
        ``(cx, cy)`` mirror centre in pixels (column, row) of the raw frame.
    inner_radius, outer_radius : float
        Radii in pixels of the bottom and top rows of the panorama.
    size : sequence of 2 int
        Output ``(W, H)``.

    Returns
    -------
    ndarray, shape (H, W), float32
    """
    width, height = int(size[0]), int(size[1])
    if width < 1 or height < 1:
        raise ValueError(f"unfold size must be positive, got {size}")
    map_x, map_y = _unfold_maps((float(center[0]), float(center[1])), float(inner_radius),
                                float(outer_radius), (width, height))
    src = np.asarray(raw, dtype=np.float32)
    return cv2.remap(src, map_x, map_y, interpolation=cv2.INTER_LINEAR,
                     borderMode=cv2.BORDER_CONSTANT, borderValue=0.0)
