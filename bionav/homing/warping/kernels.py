"""Numba search kernels of min-warping and 2D-warping.

They read the column distances in the layout of
:func:`~bionav.homing.warping.distance.diagonal_distances`,
``E[k, d, i % step, i // step]`` with ``d = (j - i) mod W`` (snapshot column
``i``, current column ``j``). For a template entry ``(u, v)`` (see
:mod:`~bionav.homing.warping.templates`) with movement direction ``a`` alpha
steps (``a * step`` columns) and rotation ``p`` columns,

    i = u + a * step,    j = v - p + a * step,    d = v - u - p,

so ``d`` does not depend on ``a`` and the distances of all alpha steps of one
template entry are ``n_alpha`` consecutive floats: the kernels vectorise over
alpha. Consecutive ``v`` are consecutive ``d`` as well, so min-warping reads
the minimum over a run of allowed current columns from sliding minima over
``d`` (:func:`fill_window_minima`). The plain, loop-by-loop equivalents are in
:mod:`~bionav.homing.warping.reference`.
"""

from __future__ import annotations

import threading

import numpy as np
from numba import njit, prange

#: Serialises launches of the parallel kernels. Callers on several Python
#: threads (the grid runner's workers) would otherwise start one team of
#: numba threads each, which oversubscribes the cores and aborts with numba's
#: ``workqueue`` threading layer (the only one available where neither OpenMP
#: nor TBB is installed). The kernels themselves use every core.
PARALLEL_LOCK = threading.Lock()


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


@njit(parallel=True, fastmath=True, cache=True)
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
    levels : ndarray, shape (J + 1, K, W, step, 2 * W // step), float32
        ``levels[0]`` filled; levels ``1 .. J`` are overwritten.
    """
    n_levels, n_planes, width, step, m2 = levels.shape
    for j in range(1, n_levels):
        h = 1 << (j - 1)
        for t in prange(n_planes * width):
            k = t // width
            d = t - k * width
            d2 = _wrap(d + h, width)
            for rr in range(step):
                a = levels[j - 1, k, d, rr]
                b = levels[j - 1, k, d2, rr]
                o = levels[j, k, d, rr]
                for m in range(m2):
                    o[m] = min(a[m], b[m])


@njit(parallel=True, fastmath=True, cache=True)
def minwarp_scores(levels, n_alpha, p_cols, start, w_plane, w_level, w_v, n_chunks):
    """Min-warping match values for every alpha step and the given rotations.

    Parameters
    ----------
    levels : ndarray, shape (J + 1, K, W, step, 2 * W // step), float32
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
    n_chunks : int
        Number of independent partial sums (one per thread).

    Returns
    -------
    ndarray, shape (P, n_alpha), float32
        ``sum_u min_{v, k allowed} dist`` for each (psi, alpha); lower is better.
    """
    _, n_planes, width, step, _ = levels.shape
    n_p = p_cols.shape[0]
    partial = np.zeros((n_chunks, n_p, n_alpha), dtype=np.float32)
    for c in prange(n_chunks):
        best = np.empty(n_alpha, dtype=np.float32)
        for u in range(c, width, n_chunks):
            m0 = u // step
            rr = u - m0 * step
            for ip in range(n_p):
                for a in range(n_alpha):
                    best[a] = np.inf
                pc = p_cols[ip]
                for e in range(start[u], start[u + 1]):
                    d = _wrap(w_v[e] - u - pc, width)
                    row = levels[w_level[e], w_plane[e], d, rr, m0:m0 + n_alpha]
                    for a in range(n_alpha):
                        best[a] = min(best[a], row[a])
                for a in range(n_alpha):
                    partial[c, ip, a] += best[a]
    out = np.zeros((n_p, n_alpha), dtype=np.float32)
    for c in range(n_chunks):
        out += partial[c]
    return out


@njit(fastmath=True, cache=True)
def minwarp_scores_at(dist, a_cols, p_cols, vlo, vhi, klo, khi):
    """Min-warping match values at single (alpha, psi) pairs given in columns.

    Parameters
    ----------
    dist : ndarray, shape (K, W, step, 2 * W // step), float32
    a_cols, p_cols : ndarray, shape (N,), int64
        Movement direction and rotation of each pair, in columns.
    vlo, vhi, klo, khi : ndarray
        Min-warping template.

    Returns
    -------
    ndarray, shape (N,), float64
    """
    n_planes, width, step, _ = dist.shape
    out = np.zeros(a_cols.shape[0])
    for t in range(a_cols.shape[0]):
        ac = a_cols[t] % width
        pc = p_cols[t]
        total = 0.0
        for u in range(width):
            i = u + ac
            if i >= width:
                i -= width
            m = i // step
            rr = i - m * step
            best = np.inf
            for v in range(vlo[u], vhi[u] + 1):
                d = _wrap(v - u - pc, width)
                for k in range(klo[u, v], khi[u, v] + 1):
                    x = dist[k, d, rr, m]
                    if x < best:
                        best = x
            total += best
        out[t] = total
    return out


@njit(parallel=True, fastmath=True, cache=True)
def warp2d_scores(dist, n_alpha, p_cols, v_tab, k_tab):
    """2D-warping match values for every (rho, psi, alpha step).

    Parameters
    ----------
    dist : ndarray, shape (K, W, step, 2 * W // step), float32
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
    col_m = np.arange(width) // step
    col_r = np.arange(width) - col_m * step
    for t in prange(n_rho * n_p):
        ir = t // n_p
        ip = t - ir * n_p
        pc = p_cols[ip]
        acc = np.zeros(n_alpha, dtype=np.float32)
        for u in range(width):
            m0 = col_m[u]
            rr = col_r[u]
            d = _wrap(v_tab[ir, u] - u - pc, width)
            row = dist[k_tab[ir, u], d, rr, m0:m0 + n_alpha]
            for a in range(n_alpha):
                acc[a] += row[a]
        out[ir, ip] = acc
    return out


@njit(fastmath=True, cache=True)
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


@njit(fastmath=True, cache=True)
def compass_measure(dist, p_cols):
    """Visual-compass distance of each rotation: ``sum_i min_k dist[k, i, i - p]``.

    The distance between the snapshot and the current view rotated back by
    ``p`` columns, column by column, taking for each column the best scale
    plane (so that landmarks that came closer or receded still match); small
    values mark plausible rotations.

    Returns
    -------
    ndarray, shape (P,), float64
    """
    n_planes, width, step, m2 = dist.shape
    n = width // step
    out = np.zeros(p_cols.shape[0])
    for ip in range(p_cols.shape[0]):
        d = (-p_cols[ip]) % width
        total = 0.0
        for rr in range(step):
            for m in range(n):
                best = dist[0, d, rr, m]
                for k in range(1, n_planes):
                    x = dist[k, d, rr, m]
                    if x < best:
                        best = x
                total += best
        out[ip] = total
    return out
