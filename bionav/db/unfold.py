"""Unfolding raw omnidirectional (mirror) camera frames into panoramas."""

from __future__ import annotations

import logging

import numpy as np

log = logging.getLogger(__name__)


def _unfold_maps(center: tuple[float, float], inner_radius: float, outer_radius: float,
                 size: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    width, height = size
    phi = 2.0 * np.pi * np.arange(width) / width
    if height > 1:
        radius = outer_radius + (inner_radius - outer_radius) * np.arange(height) / (height - 1)
    else:
        radius = np.array([0.5 * (inner_radius + outer_radius)])
    map_x = center[0] + radius[:, None] * np.cos(phi)[None, :]
    map_y = center[1] + radius[:, None] * np.sin(phi)[None, :]
    return map_x, map_y


class _Bilinear:
    """Bilinear sampling at fixed ``(map_x, map_y)`` (column, row) of frames of one shape, pixels outside 0.

    The indices, weights and the inside masks are computed once; each call gathers the four neighbours
    of every sample. Exact in float64 (``cv2.remap`` rounds coordinates to 1/32 pixel before OpenCV 5).
    """

    def __init__(self, shape, map_x: np.ndarray, map_y: np.ndarray) -> None:
        h, w = shape
        x0, y0 = np.floor(map_x).astype(np.int64), np.floor(map_y).astype(np.int64)
        self.fx, self.fy = map_x - x0, map_y - y0
        self.corners = []
        for rows, cols in ((y0, x0), (y0, x0 + 1), (y0 + 1, x0), (y0 + 1, x0 + 1)):
            inside = (rows >= 0) & (rows < h) & (cols >= 0) & (cols < w)
            self.corners.append((inside, np.clip(rows, 0, h - 1) * w + np.clip(cols, 0, w - 1)))

    def __call__(self, src: np.ndarray) -> np.ndarray:
        flat = src.reshape(-1)
        a, b, c, d = (np.where(inside, flat[index], 0.0) for inside, index in self.corners)
        top = (1.0 - self.fx) * a + self.fx * b
        bottom = (1.0 - self.fx) * c + self.fx * d
        return (1.0 - self.fy) * top + self.fy * bottom


def _bilinear(src: np.ndarray, map_x: np.ndarray, map_y: np.ndarray) -> np.ndarray:
    """Bilinear samples of ``src`` at ``(map_x, map_y)`` (column, row), pixels outside the frame 0 (:class:`_Bilinear`)."""
    return _Bilinear(src.shape, map_x, map_y)(src)


def unfold_panorama(raw: np.ndarray, *, center, inner_radius: float | None = None,
                    outer_radius: float | None = None, size, radii=None) -> np.ndarray:
    """Unfold a raw omnidirectional camera frame into a panorama (polar to rectangular).

    Column ``j`` of the output samples the ray at polar angle
    ``phi_j = 2*pi*j / W`` around ``center``, measured in the raw frame's pixel
    axes from +column towards +row (i.e. clockwise as the frame is displayed,
    x to the right, y downwards): the point
    ``(cx + r cos(phi_j), cy + r sin(phi_j))``. Row ``i`` samples the radius
    ``r_i = outer_radius + (inner_radius - outer_radius) * i / (H - 1)``, so
    row 0 (top) lies on the outer circle and the last row on the inner circle.
    Sampling is bilinear (exact, in float64); pixels outside the frame read 0.
    A mirror whose radius is not linear in elevation is unfolded to rows
    evenly spaced in elevation by giving every row's radius (``radii``, from
    the mirror profile, e.g.
    :meth:`bionav.world.catadioptric.MirrorProjection.radius_from_elevation`).

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
        Radii in pixels of the bottom and top rows of the panorama (linear in between).
    size : sequence of 2 int
        Output ``(W, H)``.
    radii : array_like, shape (H,) or (H, W), optional
        Radius in pixels of every row (row 0 on top), or of every pixel (a
        tilted camera unfolded as if upright: :func:`bionav.db.camera.unfold_frame`);
        replaces ``inner_radius`` and ``outer_radius``.

    Returns
    -------
    ndarray, shape (H, W), float32
    """
    width, height = int(size[0]), int(size[1])
    if width < 1 or height < 1:
        raise ValueError(f"unfold size must be positive, got {size}")
    if radii is None:
        if inner_radius is None or outer_radius is None:
            raise ValueError("unfold_panorama needs inner_radius and outer_radius, or radii")
        map_x, map_y = _unfold_maps((float(center[0]), float(center[1])), float(inner_radius),
                                    float(outer_radius), (width, height))
    else:
        radius = np.asarray(radii, dtype=np.float64)
        if radius.shape == (height, width):
            pass
        elif radius.size == height:
            radius = radius.reshape(height, 1)
        else:
            raise ValueError(f"radii must give one radius per row ({height}) or per pixel ({height} x {width}), "
                             f"got shape {radius.shape}")
        phi = 2.0 * np.pi * np.arange(width) / width
        map_x = float(center[0]) + radius * np.cos(phi)[None, :]
        map_y = float(center[1]) + radius * np.sin(phi)[None, :]
    src = np.asarray(raw, dtype=np.float64)
    return _bilinear(src, map_x, map_y).astype(np.float32)


def unfold_frames(frames, unfold, *, first: str, threads: int = 1) -> list[np.ndarray]:
    """Unfold raw mirror frames with the ``db.unfold`` settings (:func:`unfold_panorama`).

    ``db.unfold.center`` defaults to the frame's centre, ``db.unfold.outer_radius`` (0) to half the
    shorter side less one pixel. The one unfolding of real frames: folder databases and ROS bags.

    Parameters
    ----------
    frames : sequence of ndarray, shape (h, w)
        Raw frames of one size.
    unfold : UnfoldConfig
        ``center``, ``inner_radius``, ``outer_radius``, ``size``.
    first : str
        Where the first frame comes from (a file, a bag message), for the log.
    threads : int
        Frames unfolded at once on this many threads (NumPy releases the GIL); the results do not depend on it.

    Raises
    ------
    UserError
        Inconsistent ``db.unfold`` values.
    """
    from bionav.errors import UserError

    h, w = frames[0].shape
    center = unfold.center if unfold.center is not None else [(w - 1) / 2.0, (h - 1) / 2.0]
    outer = float(unfold.outer_radius) if unfold.outer_radius else min(w, h) / 2.0 - 1.0
    inner = float(unfold.inner_radius)
    if len(center) != 2 or not 0 <= inner < outer or len(unfold.size) != 2 or min(unfold.size) < 1:
        raise UserError(
            f"db.unfold is inconsistent (center={list(center)}, inner_radius={inner}, "
            f"outer_radius={outer}, size={list(unfold.size)}): need center=[cx,cy], "
            "0 <= inner_radius < outer_radius in pixels of the raw frame, and size=[W,H]."
        )
    log.debug("unfolding %d raw frames of %d x %d (first: %s)", len(frames), w, h, first)
    width, height = int(unfold.size[0]), int(unfold.size[1])
    sample = _Bilinear((h, w), *_unfold_maps((float(center[0]), float(center[1])), inner, outer, (width, height)))

    def one(f):  # unfold_panorama's arithmetic, the maps computed once
        if f.shape != (h, w):
            return unfold_panorama(f, center=center, inner_radius=inner, outer_radius=outer, size=unfold.size)
        return sample(np.asarray(f, dtype=np.float64)).astype(np.float32)

    if threads > 1 and len(frames) > 1:
        from concurrent.futures import ThreadPoolExecutor

        with ThreadPoolExecutor(min(threads, len(frames))) as pool:
            return list(pool.map(one, frames))
    return [one(f) for f in frames]
