"""Compiled kernels of SIFT homing: neighbourhood matching through a column index (thesis eqs. 5.1-5.3).

Keypoints of each image are sorted by column once; for a group of eight
neighbouring current keypoints only the snapshot keypoints whose columns lie
within the search radius of the group (two contiguous index ranges at most on
the circular panorama) are visited, and the exact neighbourhood test decides
(skipped in the "core" columns, where every keypoint is inside for sure).
Descriptor distances are exact: OpenCV SIFT descriptors are integers in
0..255, and float32 products and sums of such integers stay exact (every
partial sum is below 2**24), so ``|d_s|^2 - 2 d_c . d_s`` is an exact
integer. Ties in the distance go to the snapshot keypoint with the lowest
original index (as ``numpy.argmin`` over the original order does).

The public functions are in :mod:`bionav.homing.sift_homing`; nothing here is
meant to be called directly.
"""

from __future__ import annotations

import numba as nb
import numpy as np

#: keys pack (distance, original index) into one int64: distance * 2**32 + index
_SHIFT = np.int64(1) << np.int64(32)
_NONE = np.iinfo(np.int64).max
_TWO_SHIFT = np.int64(2) * _SHIFT
#: pixels kept between the radius and the core, where the neighbourhood test is skipped (far above rounding)
_CORE_MARGIN = 1e-6
#: current keypoints handled together (their descriptors stay in registers)
GROUP = 8


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
def _dot8(da, g0, db, j):
    """Dot products of descriptor ``j`` of b with descriptors ``g0 .. g0 + 7`` of a.

    float32 sums of integer products in any order are exact while every
    partial sum stays below 2**24 (SIFT: at most 128 * 255**2 < 2**23), so
    reassociation (vectorisation) changes nothing.
    """
    a0 = a1 = a2 = a3 = a4 = a5 = a6 = a7 = np.float32(0.0)
    for k in range(da.shape[1]):
        bk = db[j, k]
        a0 += da[g0, k] * bk
        a1 += da[g0 + 1, k] * bk
        a2 += da[g0 + 2, k] * bk
        a3 += da[g0 + 3, k] * bk
        a4 += da[g0 + 4, k] * bk
        a5 += da[g0 + 5, k] * bk
        a6 += da[g0 + 6, k] * bk
        a7 += da[g0 + 7, k] * bk
    return (np.int32(a0), np.int32(a1), np.int32(a2), np.int32(a3), np.int32(a4), np.int32(a5), np.int32(a6),
            np.int32(a7))


@nb.njit(nogil=True, cache=True, fastmath={"reassoc", "contract"})
def _dot8x2(da, g0, db, j):
    """:func:`_dot8` for b descriptors ``j`` and ``j + 1`` (first the 8 products with ``j``), exact likewise."""
    a0 = a1 = a2 = a3 = a4 = a5 = a6 = a7 = np.float32(0.0)
    c0 = c1 = c2 = c3 = c4 = c5 = c6 = c7 = np.float32(0.0)
    for k in range(da.shape[1]):
        bk = db[j, k]
        ck = db[j + 1, k]
        x0 = da[g0, k]
        x1 = da[g0 + 1, k]
        x2 = da[g0 + 2, k]
        x3 = da[g0 + 3, k]
        x4 = da[g0 + 4, k]
        x5 = da[g0 + 5, k]
        x6 = da[g0 + 6, k]
        x7 = da[g0 + 7, k]
        a0 += x0 * bk
        a1 += x1 * bk
        a2 += x2 * bk
        a3 += x3 * bk
        a4 += x4 * bk
        a5 += x5 * bk
        a6 += x6 * bk
        a7 += x7 * bk
        c0 += x0 * ck
        c1 += x1 * ck
        c2 += x2 * ck
        c3 += x3 * ck
        c4 += x4 * ck
        c5 += x5 * ck
        c6 += x6 * ck
        c7 += x7 * ck
    return (np.int32(a0), np.int32(a1), np.int32(a2), np.int32(a3), np.int32(a4), np.int32(a5), np.int32(a6),
            np.int32(a7), np.int32(c0), np.int32(c1), np.int32(c2), np.int32(c3), np.int32(c4), np.int32(c5),
            np.int32(c6), np.int32(c7))


@nb.njit(nogil=True, cache=True, fastmath={"reassoc", "contract"})
def _dot4x4(da, g0, db, j):
    """Products of a-descriptors ``g0 .. g0 + 3`` with b-descriptors ``j .. j + 3`` (b-major), exact likewise."""
    a0 = a1 = a2 = a3 = b0 = b1 = b2 = b3 = np.float32(0.0)
    c0 = c1 = c2 = c3 = d0 = d1 = d2 = d3 = np.float32(0.0)
    for k in range(da.shape[1]):
        x0 = da[g0, k]
        x1 = da[g0 + 1, k]
        x2 = da[g0 + 2, k]
        x3 = da[g0 + 3, k]
        p = db[j, k]
        q = db[j + 1, k]
        r = db[j + 2, k]
        s = db[j + 3, k]
        a0 += x0 * p
        a1 += x1 * p
        a2 += x2 * p
        a3 += x3 * p
        b0 += x0 * q
        b1 += x1 * q
        b2 += x2 * q
        b3 += x3 * q
        c0 += x0 * r
        c1 += x1 * r
        c2 += x2 * r
        c3 += x3 * r
        d0 += x0 * s
        d1 += x1 * s
        d2 += x2 * s
        d3 += x3 * s
    return (np.int32(a0), np.int32(a1), np.int32(a2), np.int32(a3), np.int32(b0), np.int32(b1), np.int32(b2),
            np.int32(b3), np.int32(c0), np.int32(c1), np.int32(c2), np.int32(c3), np.int32(d0), np.int32(d1),
            np.int32(d2), np.int32(d3))


@nb.njit(nogil=True, cache=True)
def _inside(x, width):
    """Whether every column ``x`` lies in ``[0, width)``."""
    for i in range(x.shape[0]):
        if not (0.0 <= x[i] < width):
            return False
    return True


@nb.njit(nogil=True, cache=True)
def _core_pieces(xi, yi, y_lo, y_hi, r2, xb, width, start, stop):
    """Bounds ``c0 <= ... <= c5`` of the pieces of ``[start, stop)`` for one a-keypoint.

    The core holds the b-keypoints closer in column than ``h``, where every row of b
    (``y_lo..y_hi``) is inside the radius for sure: x in ``[xi - h, xi + h]`` and,
    across the border, ``x <= xi + h - W`` or ``x >= xi - h + W``. Pieces ``[c0, c1)``,
    ``[c2, c3)``, ``[c4, c5)`` are core, ``[c1, c2)`` and ``[c3, c4)`` edge; no core
    gives ``c0 = ... = c5 = start``.
    """
    dy_max = max(abs(yi - y_lo), abs(yi - y_hi))
    h = np.sqrt(max(r2 - dy_max * dy_max, 0.0)) - _CORE_MARGIN
    if h <= 0.0:
        return start, start, start, start, start, start
    c1 = max(start, min(stop, np.searchsorted(xb, xi + h - width, side="right")))
    c2 = max(c1, min(stop, np.searchsorted(xb, xi - h)))
    c3 = max(c2, min(stop, np.searchsorted(xb, xi + h, side="right")))
    c4 = max(c3, min(stop, np.searchsorted(xb, xi - h + width)))
    return start, c1, c2, c3, c4, stop


@nb.njit(nogil=True, cache=True)
def match_sorted(xa, ya, da, na, ra, xb, yb, db, nbs, rb, radius, width, key_a, key_b, symmetric):
    """Best neighbourhood matches between two column-sorted keypoint sets.

    For each group of 8 sorted a-keypoints the dot products with every
    b-keypoint in the group's column window are computed (into a buffer),
    then each a-keypoint's row of the buffer is scanned with the exact
    neighbourhood test (vectorised passes).

    Parameters
    ----------
    xa, ya : float64 (NA,)
        Columns (sorted ascending) and rows of image a's keypoints.
    da : float32 (ceil(NA / 8) * 8, 128)
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
    inside_image = _inside(xa, width) and _inside(xb, width)
    y_lo = np.min(yb)
    y_hi = np.max(yb)
    base_b = np.empty(n_b, np.int64)
    for j in range(n_b):
        base_b[j] = nbs[j] * _SHIFT + rb[j]
    buf = np.empty((GROUP, n_b), np.int32)
    # key_b's running minima over the rows of a group: row by row into the
    # other of two buffers (an in-place minimum of int64 compiles to masked
    # stores on AVX2), copied in and out once per segment
    kb_cur = np.empty(n_b, np.int64)
    kb_nxt = np.empty(n_b, np.int64)
    for g0 in range(0, n_a, GROUP):
        g1 = min(g0 + GROUP, n_a)
        if inside_image:
            s0, e0, s1, e1 = _segments(xa[g0] - radius - 1.0, xa[g1 - 1] + radius + 1.0, xb, width)
        else:
            s0, e0, s1, e1 = 0, n_b, 0, 0
        for seg in range(2):
            start = s0 if seg == 0 else s1
            stop = e0 if seg == 0 else e1
            j = start
            while j + 3 < stop:  # 4 x 4 tiles: each row load serves four products
                for h in range(0, GROUP, 4):
                    t16 = _dot4x4(da, g0 + h, db, j)
                    for u in range(4):
                        for t in range(4):
                            buf[h + t, j + u] = t16[4 * u + t]
                j += 4
            while j + 1 < stop:
                t16 = _dot8x2(da, g0, db, j)
                for t in range(GROUP):
                    buf[t, j] = t16[t]
                    buf[t, j + 1] = t16[GROUP + t]
                j += 2
            if j < stop:
                t8 = _dot8(da, g0, db, j)
                for t in range(GROUP):
                    buf[t, j] = t8[t]
            if symmetric:
                kb_cur[start:stop] = key_b[start:stop]
            for t in range(g1 - g0):
                i = g0 + t
                xi = xa[i]
                yi = ya[i]
                if inside_image:
                    c0, c1, c2, c3, c4, c5 = _core_pieces(xi, yi, y_lo, y_hi, r2, xb, width, start, stop)
                else:
                    c0 = c1 = c2 = c3 = c4 = c5 = start
                best = key_a[i]
                base_a = na[i] * _SHIFT + ra[i]
                row = buf[t]
                # pieces [c0, c1) core, [c1, c2) edge, [c2, c3) core, [c3, c4) edge, [c4, c5) core
                # the pieces partition [start, stop): every entry of kb_nxt there is written once
                best = _scan_core(row, base_b, base_a, kb_cur, kb_nxt, symmetric, c0, c1, best)
                best = _scan_edge(row, base_b, base_a, kb_cur, kb_nxt, symmetric, c1, c2, best, xi, yi, xb, yb,
                                  width, r2)
                best = _scan_core(row, base_b, base_a, kb_cur, kb_nxt, symmetric, c2, c3, best)
                best = _scan_edge(row, base_b, base_a, kb_cur, kb_nxt, symmetric, c3, c4, best, xi, yi, xb, yb,
                                  width, r2)
                best = _scan_core(row, base_b, base_a, kb_cur, kb_nxt, symmetric, c4, c5, best)
                if c5 == start:  # no core: the whole range with the test
                    best = _scan_edge(row, base_b, base_a, kb_cur, kb_nxt, symmetric, start, stop, best, xi, yi,
                                      xb, yb, width, r2)
                key_a[i] = best
                kb_cur, kb_nxt = kb_nxt, kb_cur
            if symmetric:
                key_b[start:stop] = kb_cur[start:stop]


@nb.njit(nogil=True, cache=True)
def _scan_core(row, base_b, base_a, kb_in, kb_out, symmetric, start, stop, best):
    """Keys of candidates ``start .. stop - 1``, all inside the radius; returns the row's best key.

    With ``symmetric``, ``kb_out[j] = min(kb_in[j], key of this row)`` for
    ``j`` in ``start .. stop - 1`` (two buffers: no in-place stores).
    """
    # slices and loops from 0: indices the compiler knows are non-negative vectorise without gathers
    dots = row[start:stop]
    bb = base_b[start:stop]
    if symmetric:
        ki = kb_in[start:stop]
        ko = kb_out[start:stop]
        for j in range(dots.shape[0]):
            d = np.int64(dots[j]) * _TWO_SHIFT
            best = min(best, bb[j] - d)
            ko[j] = min(ki[j], base_a - d)
    else:
        for j in range(dots.shape[0]):
            best = min(best, bb[j] - np.int64(dots[j]) * _TWO_SHIFT)
    return best


@nb.njit(nogil=True, cache=True)
def _scan_edge(row, base_b, base_a, kb_in, kb_out, symmetric, start, stop, best, xi, yi, xb, yb, width, r2):
    """Keys of candidates ``start .. stop - 1`` with the exact neighbourhood test (eq. 5.3); ``kb_out`` as in
    :func:`_scan_core`."""
    dots = row[start:stop]
    bb = base_b[start:stop]
    xs = xb[start:stop]
    ys = yb[start:stop]
    ki = kb_in[start:stop] if symmetric else kb_in[:0]
    ko = kb_out[start:stop] if symmetric else kb_out[:0]
    for j in range(dots.shape[0]):
        dx = abs(xi - xs[j])
        dx = min(dx, width - dx)
        dy = yi - ys[j]
        inside = dx * dx + dy * dy < r2
        d = np.int64(dots[j]) * _TWO_SHIFT
        best = min(best, bb[j] - d if inside else _NONE)
        if symmetric:
            ko[j] = min(ki[j], base_a - d if inside else _NONE)
    return best


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


@nb.njit(nogil=True, cache=True)
def row_home_angles(a, others, wanted, x, y, desc, norms, rank, where, kp_off, desc_off, radius, width,
                    rad_per_column, horizon_row, rad_per_row, min_elevation, combine_max, n_bins, window,
                    angles, used):
    """Home angles between image ``a`` and each image of ``others``, both directions where ``wanted``.

    All images' column-sorted keypoints are concatenated (``kp_off``,
    ``desc_off``: start of each image, length N + 1). ``angles[s, c]`` and
    ``used[s, c]`` are written for snapshot ``s`` and current view ``c``
    when ``wanted[s]``; one distance pass serves both directions.
    """
    a0, a1 = kp_off[a], kp_off[a + 1]
    da = desc[desc_off[a]:desc_off[a + 1]]
    key_a = np.empty(a1 - a0, np.int64)
    for b in others:
        if not (wanted[a] or wanted[b]):
            continue
        b0, b1 = kp_off[b], kp_off[b + 1]
        key_b = np.empty(b1 - b0, np.int64)
        match_sorted(x[a0:a1], y[a0:a1], da, norms[a0:a1], rank[a0:a1], x[b0:b1], y[b0:b1],
                     desc[desc_off[b]:desc_off[b + 1]], norms[b0:b1], rank[b0:b1], radius, width, key_a, key_b,
                     wanted[a])
        if wanted[b]:  # a is the current view, b the snapshot
            angle, n = home_angle_from_keys(key_a, x[a0:a1], y[a0:a1], where[a0:a1], x[b0:b1], y[b0:b1],
                                            where[b0:b1], rad_per_column, horizon_row, rad_per_row, min_elevation,
                                            combine_max, n_bins, window)
            angles[b, a] = angle
            used[b, a] = n
        if wanted[a]:
            angle, n = home_angle_from_keys(key_b, x[b0:b1], y[b0:b1], where[b0:b1], x[a0:a1], y[a0:a1],
                                            where[a0:a1], rad_per_column, horizon_row, rad_per_row, min_elevation,
                                            combine_max, n_bins, window)
            angles[a, b] = angle
            used[a, b] = n
