"""Coverage analysis of a cleaning run: how often the cleaning unit passed over each floor cell.

Model (Gerstmayr et al. 2009, thesis section 7.2): the cleaning unit is a
straight segment of width ``w`` (0.30 m) through the robot's reference point,
perpendicular to its heading. Moving along the trajectory it sweeps the floor;
the floor is rasterised on a square grid (1 cm cells by default) and every cell
records the number of *passes* of the unit over its centre. A pass is a
maximal run of consecutive trajectory steps during which the unit covers the
cell: a lane sweeping a cell once is one pass, a later lane sweeping it again
is a second pass, a turn on the spot that rotates the unit over a cell is one
pass. Cells cleaned exactly once count as *coverage*, cells cleaned two or
more times as *overlap*, cells never cleaned as *uncovered*; the three are
fractions of the target area and sum to one.

Between two recorded poses the unit is interpolated linearly (position and
heading) in sub-steps short enough that neither end of the unit moves more
than ``max_step`` (one cell by default); the area swept in one sub-step is the
convex hull of the unit's two positions (exact for translations, a sliver
larger than the true bow-tie for rotations).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from bionav.geometry import wrap_angle

_EPS = 1e-9


@dataclass(frozen=True)
class Raster:
    """A square-celled floor raster.

    Parameters
    ----------
    origin : (float, float)
        World coordinates ``(x0, y0)`` in metres of the lower-left corner of
        cell ``[0, 0]``.
    cell : float
        Cell size in metres.
    shape : (int, int)
        ``(ny, nx)``; row ``i`` covers ``y0 + i*cell .. y0 + (i+1)*cell``
        (row 0 at the *bottom*; plot with ``origin="lower"``).
    """

    origin: tuple[float, float]
    cell: float
    shape: tuple[int, int]

    @classmethod
    def around(cls, lo, hi, *, cell: float = 0.01, margin: float = 0.0) -> "Raster":
        """Raster covering the rectangle ``lo`` .. ``hi`` (metres) plus ``margin`` on every side."""
        x0, y0 = float(lo[0]) - margin, float(lo[1]) - margin
        nx = int(np.ceil((float(hi[0]) + margin - x0) / cell - 1e-9))
        ny = int(np.ceil((float(hi[1]) + margin - y0) / cell - 1e-9))
        return cls((x0, y0), float(cell), (ny, nx))

    def centres(self) -> tuple[np.ndarray, np.ndarray]:
        """Cell-centre coordinates ``(xc (nx,), yc (ny,))`` in metres."""
        ny, nx = self.shape
        xc = self.origin[0] + (np.arange(nx) + 0.5) * self.cell
        yc = self.origin[1] + (np.arange(ny) + 0.5) * self.cell
        return xc, yc

    def rectangle_mask(self, lo, hi) -> np.ndarray:
        """Boolean mask ``(ny, nx)`` of the cells whose centre lies in the rectangle ``lo`` .. ``hi``."""
        xc, yc = self.centres()
        mx = (xc >= lo[0]) & (xc <= hi[0])
        my = (yc >= lo[1]) & (yc <= hi[1])
        return my[:, None] & mx[None, :]

    @property
    def extent(self) -> tuple[float, float, float, float]:
        """``(x_min, x_max, y_min, y_max)`` for ``matplotlib.imshow(extent=...)``."""
        ny, nx = self.shape
        return (self.origin[0], self.origin[0] + nx * self.cell, self.origin[1], self.origin[1] + ny * self.cell)


def unit_substeps(poses: np.ndarray, *, width: float, max_step: float) -> np.ndarray:
    """Endpoints of the cleaning unit along a trajectory, densified.

    Parameters
    ----------
    poses : ndarray, shape (N, 3)
        Trajectory ``(x, y, theta)``, metres and radians (CCW from ``+x``).
    width : float
        Width of the cleaning unit in metres.
    max_step : float
        Largest allowed displacement of either unit end between sub-steps (m).

    Returns
    -------
    ndarray, shape (M, 4)
        ``(ax, ay, bx, by)`` per sub-step: the unit's left end ``a`` and right
        end ``b``. Sub-steps in which the unit does not move are dropped, so a
        robot standing still does not split a pass in two.
    """
    p = np.asarray(poses, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"poses must have shape (N, 3), got {p.shape}")
    if len(p) == 0:
        return np.zeros((0, 4))
    half = 0.5 * width
    dxy = np.diff(p[:, :2], axis=0)
    dth = wrap_angle(np.diff(p[:, 2]))
    # an end of the unit moves at most |dxy| + half * |dtheta|
    n_sub = np.maximum(1, np.ceil((np.hypot(dxy[:, 0], dxy[:, 1]) + half * np.abs(dth)) / max_step)).astype(int)
    # fractional positions: pose k + t for t in (0, 1] in n_sub[k] steps
    seg = np.repeat(np.arange(len(dxy)), n_sub)
    frac = (np.arange(n_sub.sum()) - np.repeat(np.cumsum(n_sub) - n_sub, n_sub) + 1) / np.repeat(n_sub, n_sub)
    x = np.concatenate([p[:1, 0], p[seg, 0] + frac * dxy[seg, 0]])
    y = np.concatenate([p[:1, 1], p[seg, 1] + frac * dxy[seg, 1]])
    th = np.concatenate([p[:1, 2], p[seg, 2] + frac * dth[seg]])
    nx, ny = -np.sin(th) * half, np.cos(th) * half
    ends = np.stack([x + nx, y + ny, x - nx, y - ny], axis=1)
    moved = np.ones(len(ends), dtype=bool)
    moved[1:] = np.any(np.abs(np.diff(ends, axis=0)) > _EPS, axis=1)
    return ends[moved]


@njit(cache=True)
def _in_triangle(px, py, x1, y1, x2, y2, x3, y3):
    d1 = (px - x2) * (y1 - y2) - (x1 - x2) * (py - y2)
    d2 = (px - x3) * (y2 - y3) - (x2 - x3) * (py - y3)
    d3 = (px - x1) * (y3 - y1) - (x3 - x1) * (py - y1)
    has_neg = (d1 < -1e-12) or (d2 < -1e-12) or (d3 < -1e-12)
    has_pos = (d1 > 1e-12) or (d2 > 1e-12) or (d3 > 1e-12)
    return not (has_neg and has_pos)


@njit(cache=True)
def _in_hull4(px, py, q):
    # the convex hull of four points is the union of the four triangles they span
    return (_in_triangle(px, py, q[0], q[1], q[2], q[3], q[4], q[5])
            or _in_triangle(px, py, q[0], q[1], q[2], q[3], q[6], q[7])
            or _in_triangle(px, py, q[0], q[1], q[4], q[5], q[6], q[7])
            or _in_triangle(px, py, q[2], q[3], q[4], q[5], q[6], q[7]))


@njit(cache=True)
def _sweep_kernel(ends, x0, y0, cell, ny, nx):
    counts = np.zeros((ny, nx), dtype=np.int32)
    last = np.full((ny, nx), -2, dtype=np.int64)
    q = np.empty(8)
    for k in range(ends.shape[0] - 1):
        q[0] = ends[k, 0]
        q[1] = ends[k, 1]
        q[2] = ends[k, 2]
        q[3] = ends[k, 3]
        q[4] = ends[k + 1, 0]
        q[5] = ends[k + 1, 1]
        q[6] = ends[k + 1, 2]
        q[7] = ends[k + 1, 3]
        xmin = min(min(q[0], q[2]), min(q[4], q[6]))
        xmax = max(max(q[0], q[2]), max(q[4], q[6]))
        ymin = min(min(q[1], q[3]), min(q[5], q[7]))
        ymax = max(max(q[1], q[3]), max(q[5], q[7]))
        j0 = max(0, int(np.floor((xmin - x0) / cell - 0.5)))
        j1 = min(nx - 1, int(np.ceil((xmax - x0) / cell - 0.5)))
        i0 = max(0, int(np.floor((ymin - y0) / cell - 0.5)))
        i1 = min(ny - 1, int(np.ceil((ymax - y0) / cell - 0.5)))
        for i in range(i0, i1 + 1):
            py = y0 + (i + 0.5) * cell
            for j in range(j0, j1 + 1):
                px = x0 + (j + 0.5) * cell
                if _in_hull4(px, py, q):
                    if last[i, j] < k - 1:
                        counts[i, j] += 1
                    last[i, j] = k
    return counts


def sweep_counts(poses: np.ndarray, raster: Raster, *, width: float = 0.30, max_step: float | None = None) -> np.ndarray:
    """Number of passes of the cleaning unit over every raster cell.

    Parameters
    ----------
    poses : ndarray, shape (N, 3)
        Trajectory ``(x, y, theta)`` in the raster's frame (metres, radians CCW).
    raster : Raster
        The floor raster.
    width : float
        Width of the cleaning unit in metres (0.30 m in the thesis).
    max_step : float, optional
        Densification step for the unit's ends (metres); defaults to one cell.

    Returns
    -------
    ndarray of int32, shape (ny, nx)
        Passes per cell (row 0 at the bottom, see :class:`Raster`).
    """
    ends = unit_substeps(poses, width=width, max_step=raster.cell if max_step is None else max_step)
    ny, nx = raster.shape
    return _sweep_kernel(np.ascontiguousarray(ends), raster.origin[0], raster.origin[1], raster.cell, ny, nx)


def sweep_counts_reference(poses: np.ndarray, raster: Raster, *, width: float = 0.30,
                           max_step: float | None = None) -> np.ndarray:
    """Plain numpy reference of :func:`sweep_counts` (same result, slower; for tests)."""
    ends = unit_substeps(poses, width=width, max_step=raster.cell if max_step is None else max_step)
    xc, yc = raster.centres()
    px, py = np.meshgrid(xc, yc)
    counts = np.zeros(raster.shape, dtype=np.int32)
    covered_prev = np.zeros(raster.shape, dtype=bool)

    def tri(a, b, c):
        d1 = (px - b[0]) * (a[1] - b[1]) - (a[0] - b[0]) * (py - b[1])
        d2 = (px - c[0]) * (b[1] - c[1]) - (b[0] - c[0]) * (py - c[1])
        d3 = (px - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (py - a[1])
        neg = (d1 < -1e-12) | (d2 < -1e-12) | (d3 < -1e-12)
        pos = (d1 > 1e-12) | (d2 > 1e-12) | (d3 > 1e-12)
        return ~(neg & pos)

    for k in range(len(ends) - 1):
        pts = [ends[k, 0:2], ends[k, 2:4], ends[k + 1, 0:2], ends[k + 1, 2:4]]
        cov = tri(pts[0], pts[1], pts[2]) | tri(pts[0], pts[1], pts[3]) | tri(pts[0], pts[2], pts[3]) | tri(
            pts[1], pts[2], pts[3])
        counts += (cov & ~covered_prev).astype(np.int32)
        covered_prev = cov
    return counts


def coverage_fractions(counts: np.ndarray, target: np.ndarray) -> dict[str, float]:
    """Cleaned-once, overlap and uncovered fractions of a target area.

    Parameters
    ----------
    counts : ndarray of int, shape (ny, nx)
        Passes per cell (:func:`sweep_counts`).
    target : ndarray of bool, shape (ny, nx)
        The cells of the target area.

    Returns
    -------
    dict
        ``coverage`` (cleaned exactly once), ``overlap`` (cleaned two or more
        times) and ``uncovered`` (never cleaned), fractions of the target cells
        that sum to 1; ``cleaned_area_m2`` is not included (see callers).
    """
    target = np.asarray(target, dtype=bool)
    n = int(target.sum())
    if n == 0:
        raise ValueError("the target area contains no raster cell")
    c = np.asarray(counts)[target]
    return {
        "coverage": float(np.count_nonzero(c == 1) / n),
        "overlap": float(np.count_nonzero(c >= 2) / n),
        "uncovered": float(np.count_nonzero(c == 0) / n),
    }
