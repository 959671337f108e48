"""Route-following measures: RIDF, perfect-memory headings, catchment width, distance from a route.

The rotational image difference function (RIDF, Zeil, Hofmann & Chahl 2003,
"Catchment areas of panoramic snapshots in outdoor scenes", J. Opt. Soc. Am.
A 20(3), 450-469, doi:10.1364/JOSAA.20.000450) of a current view ``C`` against
a snapshot ``S`` is the mean squared pixel difference of ``C`` rotated by each
whole column against ``S``. A perfect-memory route follower (Baddeley et al.
2012, PLoS Comput. Biol. 8(1), e1002336, doi:10.1371/journal.pcbi.1002336)
stores every view along the route and heads where the best-matching rotation
of its current view points.

Conventions: canonical panoramas (:mod:`bionav.geometry`); a current view
rendered at heading ``phi`` rolled by ``-c`` columns is the view at heading
``phi + 2*pi*c/W``; headings in radians CCW from world ``+x``.
"""

from __future__ import annotations

import numpy as np

from bionav.geometry import TWO_PI, wrap_angle


def _grey(images: np.ndarray, ndim: int) -> np.ndarray:
    a = np.asarray(images, np.float64)
    return a.mean(axis=-1) if a.ndim == ndim + 1 else a


def ridf(current: np.ndarray, snapshots: np.ndarray) -> np.ndarray:
    """Rotational image difference of one view against many snapshots.

    Parameters
    ----------
    current : ndarray, shape (H, W) or (H, W, C)
    snapshots : ndarray, shape (K, H, W) or (K, H, W, C)

    Returns
    -------
    ndarray, shape (K, W)
        ``D[k, c] = mean((roll(current, -c, axis=1) - snapshots[k])**2)`` over
        pixels (and channels averaged first to grey), via the FFT.
    """
    cur = _grey(current, 2)
    snaps = _grey(snapshots, 3)
    if snaps.ndim == 2:
        snaps = snaps[None]
    h, w = cur.shape
    fc = np.fft.rfft(cur, axis=1)
    fs = np.fft.rfft(snaps, axis=2)
    # corr[k, c] = sum_r sum_j cur[r, j + c] * snap[k, r, j]
    corr = np.fft.irfft((fc[None] * np.conj(fs)).sum(axis=1), n=w, axis=1)
    ss = (snaps ** 2).sum(axis=(1, 2))
    return (float((cur ** 2).sum()) + ss[:, None] - 2.0 * corr) / (h * w)


def best_match(current: np.ndarray, snapshots: np.ndarray, *, snapshot_headings: np.ndarray,
               current_heading: float = 0.0) -> tuple[float, int, float]:
    """Perfect-memory heading: the rotation of ``current`` that best matches any snapshot.

    The best (snapshot ``k``, rotation ``c``) gives the heading at which the
    current view looks like snapshot ``k``:
    ``current_heading + 2*pi*c/W``. (``snapshot_headings`` are not needed for
    the heading itself -- the snapshots were taken facing along the route --
    but fix the frame in which the views were rendered.)

    Returns
    -------
    heading : float
        Radians CCW from world ``+x``, wrapped to ``[-pi, pi)``.
    index : int
        Best-matching snapshot.
    difference : float
        Its minimum RIDF value.
    """
    d = ridf(current, snapshots)
    k, c = np.unravel_index(int(np.argmin(d)), d.shape)
    w = d.shape[1]
    return float(wrap_angle(current_heading + TWO_PI * c / w)), int(k), float(d[k, c])


def distance_to_route(points: np.ndarray, route_xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance of points to a polyline and the index of the nearest route vertex.

    Parameters
    ----------
    points : ndarray, shape (N, 2)
    route_xy : ndarray, shape (M, 2)
        Polyline vertices in metres.

    Returns
    -------
    distance : ndarray, shape (N,)
        Metres to the nearest point on any segment.
    nearest : ndarray, shape (N,), int
        Index of the nearest vertex.
    """
    p = np.asarray(points, np.float64).reshape(-1, 2)
    r = np.asarray(route_xy, np.float64).reshape(-1, 2)
    if len(r) == 1:
        d = np.linalg.norm(p - r[0], axis=1)
        return d, np.zeros(len(p), np.int64)
    a = r[:-1]
    ab = r[1:] - a
    L2 = np.maximum((ab ** 2).sum(axis=1), 1e-30)
    t = np.clip(((p[:, None, :] - a[None]) * ab[None]).sum(axis=2) / L2[None], 0.0, 1.0)
    proj = a[None] + t[..., None] * ab[None]
    dist = np.linalg.norm(p[:, None, :] - proj, axis=2)
    nearest_vertex = np.argmin(np.linalg.norm(p[:, None, :] - r[None], axis=2), axis=1)
    return dist.min(axis=1), nearest_vertex


def lateral_normals(headings: np.ndarray) -> np.ndarray:
    """Unit vectors to the left of each heading (CCW 90 degrees), shape ``(N, 2)``."""
    h = np.asarray(headings, np.float64)
    return np.column_stack([-np.sin(h), np.cos(h)])


def catchment_width(offsets: np.ndarray, errors: np.ndarray, *, threshold: float) -> np.ndarray:
    """Route catchment width per route point from heading errors at lateral offsets.

    The catchment of route point ``i`` extends to each side as far as every
    offset up to there (from 0 outwards) has a heading error below
    ``threshold``; the width is the sum of both sides' extents (BoB/navbench
    style "catchment area" of a route, here across the route).

    Parameters
    ----------
    offsets : ndarray, shape (M,)
        Signed lateral offsets in metres (must include 0; left positive).
    errors : ndarray, shape (N, M)
        Absolute heading errors in radians (NaN = failure).
    threshold : float
        Radians.

    Returns
    -------
    ndarray, shape (N,)
        Width in metres (0 when the route point itself fails).
    """
    off = np.asarray(offsets, np.float64)
    err = np.asarray(errors, np.float64)
    if not np.any(off == 0):
        raise ValueError("offsets must include 0")
    ok = np.nan_to_num(err, nan=np.inf) < threshold
    zero = int(np.flatnonzero(off == 0)[0])
    width = np.zeros(len(err))
    for side in (1, -1):
        order = np.flatnonzero(np.sign(off) == side)
        order = order[np.argsort(np.abs(off[order]))]
        ext = np.zeros(len(err))
        alive = ok[:, zero].copy()
        for j in order:
            alive &= ok[:, j]
            ext = np.where(alive, np.abs(off[j]), ext)
        width += ext
    return width
