"""Compiled kernels of SIFT homing: neighbourhood matching through a column index (thesis eqs. 5.1-5.3).

Keypoints of each image are sorted by column once; for a group of four
neighbouring current keypoints only the snapshot keypoints whose columns lie
within the search radius of the group (two contiguous index ranges at most on
the circular panorama) are visited, and the exact neighbourhood test decides.
Descriptor distances are exact integers: OpenCV SIFT descriptors are integers
in 0..255, so ``|d_c|^2 + |d_s|^2 - 2 d_c . d_s`` is computed
(float32 products and sums of such integers stay exact) without rounding. Ties in the distance go to the snapshot keypoint with the
lowest original index (as ``numpy.argmin`` over the original order does).

The public functions are in :mod:`bionav.homing.sift_homing`; nothing here is
meant to be called directly.
"""

from __future__ import annotations

import numba as nb
import numpy as np

#: keys pack (distance, original index) into one int64: distance * 2**32 + index
_SHIFT = np.int64(1) << np.int64(32)
_NONE = np.iinfo(np.int64).max
#: current keypoints handled together (their descriptors stay in registers)
GROUP = 4


@nb.njit(nogil=True, cache=True)
def _segments(lo: float, hi: float, x: np.ndarray, width: float):
    """Index ranges ``[s0, e0), [s1, e1)`` of sorted ``x`` with column in ``[lo, hi]`` modulo ``width``."""
    n = x.shape[0]
    if hi - lo >= width:
        return 0, n, 0, 0
    if lo < 0.0:
        return np.searchsorted(x, lo + width), n, 0, np.searchsorted(x, hi, side="right")
    if hi >= width:
        return np.searchsorted(x, lo), n, 0, np.searchsorted(x, hi - width, side="right")
    return np.searchsorted(x, lo), np.searchsorted(x, hi, side="right"), 0, 0


@nb.njit(nogil=True, cache=True, fastmath={"reassoc", "contract"})
def _dot4(da, g0, db, j):
    """Dot products of descriptor ``j`` of b with descriptors ``g0 .. g0 + 3`` of a.

    float32 sums of integer products in any order are exact while every
    partial sum stays below 2**24 (SIFT: at most 128 * 255**2 < 2**23), so
    reassociation (vectorisation) changes nothing.
    """
    acc0 = np.float32(0.0)
    acc1 = np.float32(0.0)
    acc2 = np.float32(0.0)
    acc3 = np.float32(0.0)
    for k in range(da.shape[1]):
        bk = db[j, k]
        acc0 += da[g0, k] * bk
        acc1 += da[g0 + 1, k] * bk
        acc2 += da[g0 + 2, k] * bk
        acc3 += da[g0 + 3, k] * bk
    return np.int64(acc0), np.int64(acc1), np.int64(acc2), np.int64(acc3)


@nb.njit(nogil=True, cache=True)
def match_sorted(xa, ya, da, na, ra, xb, yb, db, nbs, rb, radius, width, key_a, key_b, symmetric):
    """Best neighbourhood matches between two column-sorted keypoint sets.

    Parameters
    ----------
    xa, ya : float64 (NA,)
        Columns (sorted ascending) and rows of image a's keypoints.
    da : float32 (ceil(NA / 4) * 4, 128)
        Their descriptors, integers in [-255, 255] (rows beyond NA are zero padding).
    na : int64 (NA,)
        Squared descriptor norms.
    ra : int64 (NA,)
        Original index of each sorted keypoint.
    xb, yb, db, nbs, rb
        The same for image b (``db`` needs no padding).
    radius, width : float
        Neighbourhood radius and panorama width, pixels.
    key_a : int64 (NA,)
        Output: for a as current view and b as snapshot, ``distance * 2**32 +
        original index in b`` of the best b keypoint (``_NONE``: no candidate);
        the distance is ``|d_b|^2 - 2 d_a . d_b`` (the current norm is common).
    key_b : int64 (NB,)
        Output for b as current view and a as snapshot (only if ``symmetric``).
    symmetric : bool
        Whether ``key_b`` is computed too (one distance serves both directions).
    """
    n_a = xa.shape[0]
    n_b = xb.shape[0]
    r2 = radius * radius
    key_a[:] = _NONE
    if symmetric:
        key_b[:] = _NONE
    if n_a == 0 or n_b == 0:
        return
    inside = True
    for i in range(n_a):
        if not (0.0 <= xa[i] < width):
            inside = False
    for j in range(n_b):
        if not (0.0 <= xb[j] < width):
            inside = False
    dots = np.zeros(GROUP, np.int64)
    for g0 in range(0, n_a, GROUP):
        g1 = min(g0 + GROUP, n_a)
        if inside:
            s0, e0, s1, e1 = _segments(xa[g0] - radius - 1.0, xa[g1 - 1] + radius + 1.0, xb, width)
        else:
            s0, e0, s1, e1 = 0, n_b, 0, 0
        for seg in range(2):
            start = s0 if seg == 0 else s1
            stop = e0 if seg == 0 else e1
            for j in range(start, stop):
                acc0, acc1, acc2, acc3 = _dot4(da, g0, db, j)
                dots[0] = acc0
                dots[1] = acc1
                dots[2] = acc2
                dots[3] = acc3
                for t in range(g1 - g0):
                    i = g0 + t
                    dx = abs(xa[i] - xb[j])
                    dx = min(dx, width - dx)
                    dy = ya[i] - yb[j]
                    if dx * dx + dy * dy < r2:
                        k_ab = (nbs[j] - 2 * dots[t]) * _SHIFT + rb[j]
                        if k_ab < key_a[i]:
                            key_a[i] = k_ab
                        if symmetric:
                            k_ba = (na[i] - 2 * dots[t]) * _SHIFT + ra[i]
                            if k_ba < key_b[j]:
                                key_b[j] = k_ba


@nb.njit(nogil=True, cache=True)
def matches_from_keys(keys, rank, n):
    """``(current_idx, snapshot_idx)`` in original indices, ascending current index, from ``match_sorted`` keys."""
    best = np.full(n, -1, np.int64)
    for i in range(keys.shape[0]):
        if keys[i] != _NONE:
            value = keys[i] >> np.int64(32)
            best[rank[i]] = keys[i] - value * _SHIFT
    count = 0
    for i in range(n):
        if best[i] >= 0:
            count += 1
    ci = np.empty(count, np.int64)
    si = np.empty(count, np.int64)
    m = 0
    for i in range(n):
        if best[i] >= 0:
            ci[m] = i
            si[m] = best[i]
            m += 1
    return ci, si


_TWO_PI = 2.0 * np.pi


@nb.njit(nogil=True, cache=True)
def home_angle_from_keys(keys, cur_x, cur_y, cur_where, snap_x, snap_y, snap_where, rad_per_column, horizon_row,
                         rad_per_row, min_elevation, combine_max, n_bins, window):
    """Home angle of one pair from ``match_sorted`` keys (eqs. 5.4-5.15), as ``sift_home_vector`` computes it.

    Matches are visited in ascending original current index; per match the
    home angle of :func:`bionav.homing.sift_homing.correspondence_home_angles`,
    then the histogram combination of
    :func:`bionav.homing.sift_homing.combine_home_angles` (``combine_max``:
    best window of ``window`` bins, else the histogram-weighted average).

    Returns
    -------
    angle : float
        Radians in ``[-pi, pi)``, NaN without usable correspondences.
    n_used : int
        Correspondences with a finite home angle.
    """
    n = cur_where.shape[0]
    betas = np.empty(n, np.float64)
    bins = np.empty(n, np.int64)
    hist = np.zeros(n_bins, np.int64)
    m = 0
    for i in range(n):
        p = cur_where[i]
        key = keys[p]
        if key == _NONE:
            continue
        value = key >> np.int64(32)
        q = snap_where[key - value * _SHIFT]
        theta_c = cur_x[p] * rad_per_column
        theta_s = snap_x[q] * rad_per_column
        eps_c = (horizon_row - cur_y[p]) * rad_per_row
        eps_s = (horizon_row - snap_y[q]) * rad_per_row
        r = np.tan(eps_c) / np.tan(eps_s)
        if abs(eps_s) <= min_elevation or not np.isfinite(r) or r <= 0.0:
            continue
        beta = np.arctan2(np.sin(theta_c) - r * np.sin(theta_s), np.cos(theta_c) - r * np.cos(theta_s))
        if not np.isfinite(beta):
            continue
        b = np.int64(np.floor((beta % _TWO_PI) / _TWO_PI * n_bins)) % n_bins
        betas[m] = beta
        bins[m] = b
        hist[b] += 1
        m += 1
    if m == 0:
        return np.nan, 0
    if combine_max:
        best = -1
        start = 0
        for s in range(n_bins):
            total = 0
            for k in range(window):
                total += hist[(s + k) % n_bins]
            if total > best:
                best = total
                start = s
        angle = (start + window / 2.0) / n_bins * _TWO_PI
    else:
        vx = 0.0
        vy = 0.0
        for k in range(m):
            w = float(hist[bins[k]])
            vx += w * np.cos(betas[k])
            vy += w * np.sin(betas[k])
        if vx == 0.0 and vy == 0.0:
            return np.nan, m
        angle = np.arctan2(vy, vx)
    return (angle + np.pi) % _TWO_PI - np.pi, m
