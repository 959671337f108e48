"""Min-warping of one pair in one compiled call (quantised distances, 32 to 1023 columns).

:func:`minwarp_pair_u8` runs the whole per-pair path of
:func:`~bionav.homing.warping.search.minwarping` for 8-bit distances with 16-bit
sums: both stacks quantised, the column distances, the window table, the compass
selection of rotations, the search (and the swapped pair's for the double
search), the best grid point and the fine search. The kernels are the ones the
Python path calls, in the same order and with the same tie rules (first minimum
in (rotation, direction) order on the grid, (direction, rotation) order in the
fine search, the compass ranking stable), so the result is the same, bit for bit;
what it saves is the Python between the kernels (dispatches, temporary arrays,
the selection and the argmin), about a tenth of a home vector at 288 x 50.
Layouts and conventions are those of :mod:`~bionav.homing.warping.kernels`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from bionav.homing.warping.distance import _quantisation_scale, _quantise, distance_quantum
from bionav.homing.warping.kernels import compass_measure, fill_window_minima, minwarp_scores_runs, swap_roles
from bionav.homing.warping.vkernels import diagonal_distances_u8, minwarp_search_u8, padded_lanes


@njit(nogil=True, cache=True)
def _table_u8(snap, cur, scale, step, quantum, sq, sn, cq2, cn2, dacc, levels):
    """Quantise both stacks, fill ``levels[0]`` with the 8-bit distances and the window levels."""
    _quantise(snap, scale, sq, sn)
    _quantise(cur, scale, cq2, cn2)
    diagonal_distances_u8(sq, cq2, sn, cn2, step, quantum, levels[0], dacc)
    if levels.shape[0] > 1:
        fill_window_minima(levels)


@njit(nogil=True, cache=True)
def _search_u8(flat, levels, n_a, p_cols, start, w_plane, w_level, w_v, scratch):
    _, n_planes, width, step, _ = levels.shape
    acc = np.empty((p_cols.shape[0], padded_lanes(n_a)), np.uint16)
    return minwarp_search_u8(flat, n_planes, width, step, n_a, p_cols, start, w_plane, w_level, w_v, acc, scratch)


@njit(nogil=True, cache=True)
def _best_on_grid(acc, acc2, p_cols, a_idx, step, width, double):
    """First minimum over (rotation, direction) of ``acc[ip, a]`` (plus the swapped pair's value of the
    corresponding hypothesis ``(a + W/2 - p, -p)``), ``a`` the directions ``a_idx`` in alpha steps."""
    best = np.int64(-1)
    bp = 0
    ba = 0
    for ip in range(p_cols.shape[0]):
        p = p_cols[ip]
        for ia in range(a_idx.shape[0]):
            a = a_idx[ia]
            v = np.int64(acc[ip, a])
            if double:
                v += np.int64(acc2[ip, ((a * step + width // 2 - p) % width) // step])
            if best < 0 or v < best:
                best = v
                bp = ip
                ba = ia
    return ba, bp, best


@njit(nogil=True, cache=True)
def _fine_u8(levels, levels2, start, w_plane, w_level, w_v, best_a, best_p, best, ra, rp, double):
    """The fine search around the grid's best (``search._fine_minwarp``): runs of ``2 ra + 1``
    directions for ``2 rp + 1`` rotations; the first minimum in (direction, rotation) order wins if
    it is below ``best``."""
    width = levels.shape[2]
    pc = (best_p + np.arange(-rp, rp + 1)) % width
    a_first = np.full(pc.shape[0], (best_a - ra) % width, np.int64)
    vals = minwarp_scores_runs(levels, a_first, 2 * ra + 1, pc, start, w_plane, w_level, w_v)
    if double:
        vals = vals + minwarp_scores_runs(levels2, (a_first + width // 2 - pc) % width, 2 * ra + 1,
                                          (-pc) % width, start, w_plane, w_level, w_v)
    bt = np.inf
    ba = 0
    bp = 0
    for ia in range(2 * ra + 1):
        for ip in range(pc.shape[0]):
            if vals[ip, ia] < bt:
                bt = vals[ip, ia]
                ba = ia
                bp = ip
    if bt < best:
        return (best_a - ra + ba) % width, pc[bp], bt
    return best_a, best_p, best


@njit(nogil=True, cache=True)
def minwarp_pair_u8(stacks, scales, step, quantum, a_cols, p_all, n_sel, windows, double, symmetric, fine,
                    ra, rp, buffers):
    """Min-warping's best hypothesis for one pair, quantised distances (one compiled call).

    Parameters
    ----------
    stacks : tuple of 4 ndarray, shape (K, R, W), float32
        The snapshot's snapshot-role planes, the current view's current-role planes, and the
        swapped pair's (the current view's snapshot-role planes, the snapshot's current-role
        ones; read only for a double search with asymmetric scales).
    scales : tuple of 2 float32
        Quantisation scales of the pair and of the swapped pair.
    step, quantum : int
        Alpha step in columns (``W // step`` alpha steps) and the distances' quantum ``q``.
    a_cols : ndarray, shape (n_alpha,), int64
        The grid's directions in columns (multiples of ``step``).
    p_all : ndarray, shape (n_psi,), int64
        The grid's rotations in columns.
    n_sel : int
        Rotations to search: all (``n_psi``) or the ``n_sel`` of lowest compass measure.
    windows : tuple
        ``(start, w_plane, w_level, w_v)`` of :func:`~bionav.homing.warping.templates.minwarp_windows`.
    double, symmetric, fine : bool
        Double search; inversion-symmetric scales (the swapped pair's table is the pair's,
        transposed); fine search.
    ra, rp : int
        The fine search's half widths in columns.
    buffers : tuple
        ``(sq, sn, cq2, cn2, dacc, levels, flat, levels2, flat2, scratch)``: the quantised stacks
        and norms, the distances' work space, the two window tables (views of padded 1-D
        buffers ``flat``, ``flat2``) and the search's scratch.

    Returns
    -------
    best_a, best_p : int
        Movement direction and rotation in columns.
    best : float
        Match value in distance quanta (both searches summed for a double search).
    n_psi_searched : int
    """
    snap, cur, snap_b, cur_b = stacks
    sq, sn, cq2, cn2, dacc, levels, flat, levels2, flat2, scratch = buffers
    start, w_plane, w_level, w_v = windows
    width = levels.shape[2]
    n_a = width // step
    a_idx = a_cols // step
    _table_u8(snap, cur, scales[0], step, quantum, sq, sn, cq2, cn2, dacc, levels)
    p_cols = p_all
    if n_sel < p_all.shape[0]:
        keep = np.sort(np.argsort(compass_measure(levels[0], p_all), kind="mergesort")[:n_sel])
        p_cols = p_all[keep]
    acc = _search_u8(flat, levels, n_a, p_cols, start, w_plane, w_level, w_v, scratch)
    acc2 = acc
    if double:
        if symmetric:
            swap_roles(levels[0], levels2[0])
            if levels2.shape[0] > 1:
                fill_window_minima(levels2)
        else:
            _table_u8(snap_b, cur_b, scales[1], step, quantum, sq, sn, cq2, cn2, dacc, levels2)
        acc2 = _search_u8(flat2, levels2, n_a, (-p_cols) % width, start, w_plane, w_level, w_v, scratch)
    ba, bp, best = _best_on_grid(acc, acc2, p_cols, a_idx, step, width, double)
    best_a = a_cols[ba]
    best_p = p_cols[bp]
    score = np.float64(best)
    if fine:
        best_a, best_p, score = _fine_u8(levels, levels2, start, w_plane, w_level, w_v, best_a, best_p,
                                         score, ra, rp, double)
    return best_a, best_p, score, p_cols.shape[0]


def n_selected(n_psi, compass_fraction):
    """Rotations the compass acceleration keeps (all without it)."""
    if compass_fraction is None or compass_fraction >= 1.0:
        return n_psi
    if not (0.0 < compass_fraction <= 1.0):
        raise ValueError(f"compass_fraction must lie in (0, 1], got {compass_fraction}")
    return max(1, int(np.ceil(compass_fraction * n_psi)))


def pair_inputs(snapshot, current, step, asymmetric_double):
    """The stacks, the quantisation scales and the step and quantum of :func:`minwarp_pair_u8`."""
    snap = np.ascontiguousarray(snapshot["snap"], dtype=np.float32)
    cur = np.ascontiguousarray(current["cur"], dtype=np.float32)
    n_rows, width = snap.shape[1:]
    scale = _quantisation_scale(snapshot, current, n_rows)
    stacks, scales = (snap, cur, snap, cur), (scale, scale)
    if asymmetric_double:  # the swapped pair: the current view in the snapshot's role
        stacks = (snap, cur, np.ascontiguousarray(current["snap"], dtype=np.float32),
                  np.ascontiguousarray(snapshot["cur"], dtype=np.float32))
        scales = (scale, _quantisation_scale(current, snapshot, n_rows))
    return stacks, scales, int(step), distance_quantum(width)[0]
