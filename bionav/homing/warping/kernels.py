"""Numba search kernels of min-warping and 2D-warping (single-threaded, GIL released).

They read the column distances in the layout of
:func:`~bionav.homing.warping.distance.diagonal_distances`,
``E[k, d, i % step, i // step]`` with ``d = (j - i) mod W`` (snapshot column
``i``, current column ``j``). For a template entry ``(u, v)`` (see
:mod:`~bionav.homing.warping.templates`) with movement direction ``a`` alpha
steps (``a * step`` columns) and rotation ``p`` columns,

    i = u + a * step,    j = v - p + a * step,    d = v - u - p,

so ``d`` does not depend on ``a`` and the distances of all alpha steps of one
template entry are ``n_alpha`` consecutive values: the kernels vectorise over
alpha. Consecutive ``v`` are consecutive ``d`` as well, so min-warping reads
the minimum over a run of allowed current columns from sliding minima over
``d`` (:func:`fill_window_minima`). The plain, loop-by-loop equivalents are in
:mod:`~bionav.homing.warping.reference`.

Every kernel works on float32 distances (NSAD) and on the quantised 8-bit
distances of :func:`~bionav.homing.warping.distance.diagonal_distances`
(``quantised=True``), whose minima are taken on bytes and summed in 16 bits
(``numba.njit`` compiles one specialisation per dtype; the inner min/add loops
compile to packed byte/word instructions, see ``docs/performance.md``).

All kernels run on the calling thread and release the GIL (``nogil=True``):
callers parallelise over pairs or snapshots (the grid runner's worker threads),
which never oversubscribes the cores and never spin-waits.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(inline="always")
def _wrap(d, width):
    """``d mod width`` for ``-2 width <= d < 2 width`` without an integer division."""
    if d < 0:
        d += width
        if d < 0:
            d += width
    elif d >= width:
        d -= width
        if d >= width:
            d -= width
    return d


@njit(nogil=True, fastmath=True, cache=True)
def fill_window_minima(levels):
    """Sliding minima over ``d`` of the column distances, in place.

    ``levels[j, k, d] = min(levels[0, k, d'] for d' in d .. d + 2**j - 1)``
    (``d'`` modulo ``W``), built level by level from ``levels[0]``, the column
    distances in diagonal layout. A run of ``L`` consecutive current columns
    ``v`` (one snapshot column, one plane) is a run of ``L`` consecutive ``d``,
    so its minimum is the minimum of at most two entries of one level
    (a sparse table: Bender & Farach-Colton 2000, "The LCA problem revisited").

    Parameters
    ----------
    levels : ndarray, shape (J + 1, K, W, step, W // step), float32 or uint8
        ``levels[0]`` filled; levels ``1 .. J`` are overwritten.
    """
    n_levels, n_planes, width, step, m2 = levels.shape
    row = step * m2
    for j in range(1, n_levels):
        h = 1 << (j - 1)
        for k in range(n_planes):
            src = levels[j - 1, k].reshape((width, row))
            dst = levels[j, k].reshape((width, row))
            for d in range(width):
                d2 = _wrap(d + h, width)
                a = src[d]
                b = src[d2]
                o = dst[d]
                for m in range(row):
                    o[m] = min(a[m], b[m])


@njit(nogil=True, fastmath=True, cache=True)
def minwarp_scores(levels, n_alpha, p_cols, start, w_plane, w_level, w_v, big, out):
    """Min-warping match values for every alpha step and the given rotations.

    Parameters
    ----------
    levels : ndarray, shape (J + 1, K, W, step, W // step), float32 or uint8
        Column distances (diagonal layout) and their sliding minima
        (:func:`fill_window_minima`).
    n_alpha : int
        Number of alpha steps (``W // step``).
    p_cols : ndarray, shape (P,), int64
        Rotations ``psi`` to search, in columns (``0 <= p < W``).
    start, w_plane, w_level, w_v : ndarray
        Min-warping windows (:func:`~bionav.homing.warping.templates.minwarp_windows`):
        the entries ``start[u] .. start[u + 1] - 1`` of snapshot column ``u``
        each cover ``2**w_level`` current columns from ``w_v`` in plane ``w_plane``.
    big : scalar of the dtype of ``levels``
        Its largest value (``inf`` or 255); the minimum of a column without
        allowed entries.
    out : ndarray, shape (P, n_alpha)
        Zero-filled accumulator: float32 for float distances, uint16 (or
        uint32) for quantised ones, wide enough for ``W`` times the largest
        distance (:func:`~bionav.homing.warping.distance.distance_quantum`).

    Returns
    -------
    ndarray, shape (P, n_alpha)
        ``out``: ``sum_u min_{v, k allowed} dist`` for each (psi, alpha); lower is better.
    """
    _, n_planes, width, step, n = levels.shape
    n_p = p_cols.shape[0]
    # two buffers of running minima, used in turn: each window's minima are
    # written into the other buffer (``nxt = min(cur, x)``), never in place.
    # An in-place minimum (``if x < best: best = x``, and even
    # ``best = min(best, x)`` for 32-bit lanes) vectorises only with masked
    # stores, which AVX2 lacks for bytes (the loop then stays scalar) and runs
    # slowly for floats; a separate output compiles to plain packed
    # ``vpminub`` / ``vminps`` and stores on AVX2 and AVX-512 alike.
    cur = np.empty(n_p * n, dtype=levels.dtype)
    nxt = np.empty(n_p * n, dtype=levels.dtype)
    row_stride = step * n
    flat = levels.reshape(-1)
    plane_size = width * row_stride
    un = np.uint64(n)
    # snapshot columns in phase order (u = rr, rr + step, ...): one phase reads
    # a third of the table (step 3), which keeps the reads in cache; per window
    # all rotations at once (the window's plane and level stay fixed); the
    # first window of a column is copied, the others combined by packed
    # minima. The minima are kept over whole rows (column i // step of the
    # snapshot, any alpha) and added to the match values of alpha step
    # (i // step - u // step) mod n afterwards, so that the table holds every
    # distance once. The inner loops index flat arrays with unsigned offsets
    # (no array views per window and rotation).
    for rr in range(step):
        for u in range(rr, width, step):
            e0 = start[u]
            e1 = start[u + 1]
            off = u // step
            for e in range(e0, e1):
                pb = (w_level[e] * n_planes + w_plane[e]) * plane_size + rr * n
                v0 = w_v[e] - u
                first = e == e0
                if first:
                    for ip in range(n_p):
                        base = np.uint64(pb + _wrap(v0 - p_cols[ip], width) * row_stride)
                        bb = np.uint64(ip) * un
                        for a in range(n):
                            ua = np.uint64(a)
                            nxt[bb + ua] = flat[base + ua]
                else:
                    # two rotations per pass (a longer loop body: the
                    # compiler's vector loop fits rows of n lanes)
                    ip = 0
                    while ip + 1 < n_p:
                        base = np.uint64(pb + _wrap(v0 - p_cols[ip], width) * row_stride)
                        base1 = np.uint64(pb + _wrap(v0 - p_cols[ip + 1], width) * row_stride)
                        bb = np.uint64(ip) * un
                        bb1 = bb + un
                        for a in range(n):
                            ua = np.uint64(a)
                            nxt[bb + ua] = min(cur[bb + ua], flat[base + ua])
                            nxt[bb1 + ua] = min(cur[bb1 + ua], flat[base1 + ua])
                        ip += 2
                    if ip < n_p:
                        base = np.uint64(pb + _wrap(v0 - p_cols[ip], width) * row_stride)
                        bb = np.uint64(ip) * un
                        for a in range(n):
                            ua = np.uint64(a)
                            nxt[bb + ua] = min(cur[bb + ua], flat[base + ua])
                cur, nxt = nxt, cur
            if e1 == e0:
                cur[:] = big
            for ip in range(n_p):
                acc = out[ip]
                b = cur[ip * n:(ip + 1) * n]
                # slices: plain contiguous loops (indices ``a + off`` would
                # keep them from vectorising)
                b1 = b[off:]
                acc2 = acc[n - off:]
                for a in range(n - off):
                    acc[a] += b1[a]
                for a in range(off):
                    acc2[a] += b[a]
    return out


@njit(nogil=True, fastmath=True, cache=True)
def minwarp_scores_at(levels, a_cols, p_cols, start, w_plane, w_level, w_v):
    """Min-warping match values at single (alpha, psi) pairs given in columns.

    Reads the same windows as :func:`minwarp_scores` (used by the fine search,
    which visits hypotheses between the grid's alpha steps).

    Parameters
    ----------
    levels : ndarray, shape (J + 1, K, W, step, W // step), float32 or uint8
    a_cols, p_cols : ndarray, shape (N,), int64
        Movement direction and rotation of each pair, in columns.
    start, w_plane, w_level, w_v : ndarray
        Min-warping windows.

    Returns
    -------
    ndarray, shape (N,), float64
        In the units of ``levels``.
    """
    _, n_planes, width, step, _ = levels.shape
    n_t = a_cols.shape[0]
    total = np.zeros(n_t)
    # running minima in two buffers used in turn (no in-place or conditional
    # stores, see :func:`minwarp_scores`)
    cur = np.empty(n_t)
    nxt = np.empty(n_t)
    rr_t = np.empty(n_t, np.int64)
    m_t = np.empty(n_t, np.int64)
    p_t = np.empty(n_t, np.int64)
    for t in range(n_t):
        p_t[t] = p_cols[t] % width
    # column by column, all hypotheses at once: neighbouring hypotheses read
    # neighbouring entries of the same rows
    for u in range(width):
        for t in range(n_t):
            i = (u + a_cols[t]) % width
            m_t[t] = i // step
            rr_t[t] = i - m_t[t] * step
            cur[t] = np.inf
        for e in range(start[u], start[u + 1]):
            plane = levels[w_level[e], w_plane[e]]
            v0 = w_v[e] - u
            for t in range(n_t):
                nxt[t] = min(cur[t], np.float64(plane[_wrap(v0 - p_t[t], width), rr_t[t], m_t[t]]))
            cur, nxt = nxt, cur
        for t in range(n_t):
            total[t] += cur[t]
    return total


@njit(nogil=True, fastmath=True, cache=True)
def minwarp_scores_runs(levels, a_first, n_a, p_cols, start, w_plane, w_level, w_v):
    """Min-warping match values of runs of consecutive movement directions.

    For each rotation ``p_cols[t]`` the ``n_a`` directions ``a_first[t] ..
    a_first[t] + n_a - 1`` (columns, modulo ``W``): the fine search's block of
    hypotheses around the best grid point, for the pair and (with shifted
    directions) for the swapped pair. Reads the same windows as
    :func:`minwarp_scores`; per window and rotation one row of the table, the
    directions of a run at offsets fixed per snapshot column.

    Parameters
    ----------
    levels : ndarray, shape (J + 1, K, W, step, W // step), float32 or uint8
    a_first : ndarray, shape (P,), int64
        First movement direction of each run, in columns.
    n_a : int
        Directions per run.
    p_cols : ndarray, shape (P,), int64
        Rotation of each run, in columns.
    start, w_plane, w_level, w_v : ndarray
        Min-warping windows.

    Returns
    -------
    ndarray, shape (P, n_a), float64
        In the units of ``levels``.
    """
    n_levels, n_planes, width, step, m2 = levels.shape
    row = step * m2
    flat = levels.reshape(-1)
    n_p = p_cols.shape[0]
    total = np.zeros((n_p, n_a))
    # running minima in two buffers used in turn (no in-place or conditional
    # stores, see :func:`minwarp_scores`)
    cur = np.empty((n_p, n_a))
    nxt = np.empty((n_p, n_a))
    offs = np.empty((n_p, n_a), np.uint64)
    p_t = np.empty(n_p, np.int64)
    for t in range(n_p):
        p_t[t] = p_cols[t] % width
    for u in range(width):
        for t in range(n_p):
            # column i = u + a_first[t] + a (mod W) as (i % step, i // step),
            # advanced without dividing
            i = (u + a_first[t]) % width
            m = i // step
            r = i - m * step
            for a in range(n_a):
                offs[t, a] = np.uint64(r * m2 + m)
                cur[t, a] = np.inf
                i += 1
                r += 1
                if r == step:
                    r = 0
                    m += 1
                if i == width:
                    i = 0
                    r = 0
                    m = 0
        for e in range(start[u], start[u + 1]):
            base = (w_level[e] * n_planes + w_plane[e]) * width
            v0 = w_v[e] - u
            for t in range(n_p):
                rb = np.uint64((base + _wrap(v0 - p_t[t], width)) * row)
                bt = cur[t]
                nt = nxt[t]
                ot = offs[t]
                for a in range(n_a):
                    nt[a] = min(bt[a], np.float64(flat[rb + ot[a]]))
            cur, nxt = nxt, cur
        for t in range(n_p):
            for a in range(n_a):
                total[t, a] += cur[t, a]
    return total


@njit(nogil=True, fastmath=True, cache=True)
def warp2d_scores(dist, n_alpha, p_cols, v_tab, k_tab):
    """2D-warping match values for every (rho, psi, alpha step).

    Parameters
    ----------
    dist : ndarray, shape (K, W, step, W // step), float32
    n_alpha : int
    p_cols : ndarray, shape (P,), int64
        Rotations in columns.
    v_tab, k_tab : ndarray, shape (R, W), int32
        2D-warping template (:func:`~bionav.homing.warping.templates.warp2d_template`).

    Returns
    -------
    ndarray, shape (R, P, n_alpha), float32
        ``sum_u dist`` of the predicted column pairs; lower is better.
    """
    n_planes, width, step, _ = dist.shape
    n_rho = v_tab.shape[0]
    n_p = p_cols.shape[0]
    out = np.zeros((n_rho, n_p, n_alpha), dtype=np.float32)
    for ir in range(n_rho):
        for ip in range(n_p):
            pc = p_cols[ip]
            acc = out[ir, ip]
            for u in range(width):
                m0 = u // step
                rr = u - m0 * step
                d = _wrap(v_tab[ir, u] - u - pc, width)
                row = dist[k_tab[ir, u], d, rr]
                row1 = row[m0:]
                acc2 = acc[n_alpha - m0:]
                for a in range(n_alpha - m0):
                    acc[a] += row1[a]
                for a in range(m0):
                    acc2[a] += row[a]
    return out


@njit(nogil=True, fastmath=True, cache=True)
def warp2d_scores_at(dist, a_cols, p_cols, rho_idx, v_tab, k_tab):
    """2D-warping match values at single (alpha, psi, rho) triples (columns, columns, index)."""
    n_planes, width, step, _ = dist.shape
    out = np.zeros(a_cols.shape[0])
    for t in range(a_cols.shape[0]):
        ac = a_cols[t] % width
        pc = p_cols[t]
        ir = rho_idx[t]
        total = 0.0
        for u in range(width):
            i = u + ac
            if i >= width:
                i -= width
            m = i // step
            rr = i - m * step
            d = _wrap(v_tab[ir, u] - u - pc, width)
            total += dist[k_tab[ir, u], d, rr, m]
        out[t] = total
    return out


@njit(nogil=True, fastmath=True, cache=True)
def compass_measure(dist, p_cols):
    """Visual-compass distance of each rotation: ``sum_i min_k dist[k, i, i - p]``.

    The distance between the snapshot and the current view rotated back by
    ``p`` columns, column by column, taking for each column the best scale
    plane (so that landmarks that came closer or receded still match); small
    values mark plausible rotations.

    Parameters
    ----------
    dist : ndarray, shape (K, W, step, W // step), float32 or uint8

    Returns
    -------
    ndarray, shape (P,), float64
    """
    n_planes, width, step, m2 = dist.shape
    n = width // step
    out = np.zeros(p_cols.shape[0])
    cur = np.empty(n, dtype=dist.dtype)
    nxt = np.empty(n, dtype=dist.dtype)
    # per rotation one diagonal d: the minimum over the planes is taken on
    # whole rows (packed minima into the other of two buffers: an in-place
    # minimum of floats compiles to masked stores on AVX2), then summed
    for ip in range(p_cols.shape[0]):
        d = (-p_cols[ip]) % width
        total = 0.0
        for rr in range(step):
            row = dist[0, d, rr]
            for m in range(n):
                cur[m] = row[m]
            for k in range(1, n_planes):
                row = dist[k, d, rr]
                for m in range(n):
                    nxt[m] = min(cur[m], row[m])
                cur, nxt = nxt, cur
            s = 0.0
            for m in range(n):
                s += np.float64(cur[m])
            total += s
        out[ip] = total
    return out


@njit(nogil=True, cache=True)
def swap_roles(dist, out):
    """Column distances of the swapped pair from those of the pair (the transposed stack).

    With inversion-symmetric scale factors (``sigma_{K-1-k} = 1 / sigma_k``)
    plane ``k`` of the swapped pair (current view as snapshot) compares the
    same two images as plane ``K-1-k`` of the pair, with the roles of the
    columns exchanged: ``D'[k, j, i] = D[K-1-k, i, j]``. In diagonal layout
    ``E'[k, d, j] = E[K-1-k, -d, j + d]`` (indices modulo ``W``).

    Parameters
    ----------
    dist : ndarray, shape (K, W, step, W // step)
        Diagonal-layout distances of the pair.
    out : ndarray, same shape and dtype
        Filled with those of the swapped pair.
    """
    n_planes, width, step, m2 = dist.shape
    n = width // step
    for k in range(n_planes):
        src = dist[n_planes - 1 - k]
        for d in range(width):
            s = src[width - d if d > 0 else 0]
            o = out[k, d]
            for rj in range(step):
                # columns j = rj + step * mj map to i = j + d = ph + step * (off + mj)
                c = rj + d
                off = c // step
                ph = c - off * step
                if off >= n:
                    off -= n
                row = s[ph]
                dst = o[rj]
                row1 = row[off:]
                dst2 = dst[n - off:]
                for m in range(n - off):
                    dst[m] = row1[m]
                for m in range(off):
                    dst2[m] = row[m]
