"""Min-warping's two hot stages written with explicit vectors (:mod:`bionav.homing.warping.simd`).

* :func:`minwarp_search_u8`: the search over (psi, alpha) on 8-bit distances
  with 16-bit sums. Two rotations at a time (up to 96 alpha steps): per
  snapshot column the minima of both over the column's windows stay in six
  vector registers (96 alpha lanes each) while the windows are visited (a
  window's offsets read once for both), and are added once per column to sums
  kept in registers over all columns; the offsets of the table rows are looked
  up, not recomputed. It replaces
  :func:`~bionav.homing.warping.kernels.minwarp_scores` for quantised
  distances, whose loop per (window, rotation) re-entered a vectorised loop of
  96 bytes (set-up, alias checks and a remainder each time) and went through
  memory for every minimum.
* :func:`diagonal_distances_u8`: the 8-bit NSAD of all column pairs. The
  16-bit sums of absolute differences of a block of 32 snapshot columns and
  four diagonals stay in registers over all rows (one store per block instead
  of one load and store per row), summed as ``2 max(a, b) - a - b`` (two
  instructions per term); the snapshot row is loaded once for the four
  diagonals, and a block of columns meets all diagonals while its rows are in
  L1 cache. The normalisation is :mod:`~bionav.homing.warping.normalise`'s.

Both give the same numbers as the kernels they replace, bit for bit
(``tests/homing/test_vector_kernels.py`` compares them with the previous
kernels, kept as the plain reference, on random inputs of many sizes).
Layouts and conventions are those of :mod:`~bionav.homing.warping.kernels`
and :mod:`~bionav.homing.warping.distance`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from bionav.homing.warping.normalise import _normalise_plane
from bionav.homing.warping.simd import (
    LANES,
    add_i16,
    add_max_i16,
    add_widened_u8,
    load_i16,
    load_u8,
    min_u8,
    splat_u8,
    store_i16,
    store_u8,
    sub_i16,
    zero_i16,
)

#: alpha lanes the search keeps in registers per pass (three vectors of 32 bytes)
GROUP = 3 * LANES
#: bytes the window table must extend past its last row (a pass reads GROUP lanes of a row)
TABLE_PAD = GROUP + LANES


@njit(cache=True)
def padded_lanes(n):
    """Lanes of an accumulator row of ``n`` alpha steps: ``n`` rounded up to a multiple of 32, at
    least 96 (the sums of up to 96 alpha steps stay in three vectors)."""
    return max(GROUP, -(-n // LANES) * LANES)


def search_scratch_size(n: int) -> int:
    """Bytes of :func:`minwarp_search_u8`'s ``scratch`` for ``n`` alpha steps (four quarters: two
    rotations x two columns in flight)."""
    return 4 * (max(-(-int(n) // GROUP) * GROUP, int(n)) + int(n) + GROUP)


@njit(nogil=True, cache=True)
def _window_offsets(n_planes, width, step, n, start, w_plane, w_level, w_v):
    """Per window: the table offset of its plane, level and phase, and ``v - u + 2 W``; per
    ``x`` in ``0 .. 3 W``: the offset of row ``d = x mod W``."""
    row_stride = step * n
    plane_size = width * row_stride
    base = np.empty(w_v.shape[0], np.uint64)
    dv = np.empty(w_v.shape[0], np.uint64)
    for u in range(width):
        rr = u % step
        for e in range(start[u], start[u + 1]):
            base[e] = (w_level[e] * n_planes + w_plane[e]) * plane_size + rr * n
            dv[e] = w_v[e] - u + 2 * width
    dtab = np.empty(3 * width, np.uint64)
    for x in range(3 * width):
        dtab[x] = (x % width) * row_stride
    return base, dv, dtab


@njit(nogil=True, cache=True, inline="always")
def _column_minima(flat, base, dv, dtab, e0, e1, p, g0, scratch, sb, n):
    """Minima over the windows ``e0 .. e1 - 1`` of one snapshot column at rotation ``p``, alpha
    lanes ``g0 .. g0 + 95`` (three vectors kept in registers over the windows), stored twice in
    ``scratch`` from ``sb`` (at ``sb + g0`` and ``sb + n + g0``) so that a shifted read needs no wrap."""
    big = splat_u8(np.uint8(255))
    v0 = big
    v1 = big
    v2 = big
    ug = np.uint64(g0)
    e = e0
    while e < e1:  # unsigned indices: no wrap-around checks in the loop over windows
        o = np.intp(base[e] + dtab[dv[e] - p] + ug)
        v0 = min_u8(v0, load_u8(flat, o))
        v1 = min_u8(v1, load_u8(flat, o + LANES))
        v2 = min_u8(v2, load_u8(flat, o + 2 * LANES))
        e += np.uint64(1)
    for o in (sb + g0, sb + n + g0):
        store_u8(scratch, o, v0)
        store_u8(scratch, o + LANES, v1)
        store_u8(scratch, o + 2 * LANES, v2)


@njit(nogil=True, cache=True, inline="always")
def _column_minima2(flat, base, dv, dtab, e0, e1, pa, pb, scratch, sa, sb, n):
    """:func:`_column_minima` of two rotations ``pa``, ``pb`` at once (alpha lanes ``0 .. 95``, six
    vectors in registers): a window's offsets are read once for both; stored from ``sa`` and ``sb``."""
    big = splat_u8(np.uint8(255))
    a0 = big
    a1 = big
    a2 = big
    b0 = big
    b1 = big
    b2 = big
    e = e0
    while e < e1:
        bs = base[e]
        x = dv[e]
        oa = np.intp(bs + dtab[x - pa])
        ob = np.intp(bs + dtab[x - pb])
        a0 = min_u8(a0, load_u8(flat, oa))
        a1 = min_u8(a1, load_u8(flat, oa + LANES))
        a2 = min_u8(a2, load_u8(flat, oa + 2 * LANES))
        b0 = min_u8(b0, load_u8(flat, ob))
        b1 = min_u8(b1, load_u8(flat, ob + LANES))
        b2 = min_u8(b2, load_u8(flat, ob + 2 * LANES))
        e += np.uint64(1)
    for o in (sa, sa + n):
        store_u8(scratch, o, a0)
        store_u8(scratch, o + LANES, a1)
        store_u8(scratch, o + 2 * LANES, a2)
    for o in (sb, sb + n):
        store_u8(scratch, o, b0)
        store_u8(scratch, o + LANES, b1)
        store_u8(scratch, o + 2 * LANES, b2)


@njit(nogil=True, cache=True)
def _search_rotation_pairs(flat, base, dv, dtab, width, step, n, p_cols, start, accf, npad, scratch):
    """The search for ``n <= 96`` alpha steps, two rotations per pass (the last one alone, computed
    twice): per column the minima of both rotations, their sums in six registers over all columns."""
    q = scratch.shape[0] // 4
    n_p = p_cols.shape[0]
    for rr in range(step):
        for ip in range(0, n_p, 2):
            ipb = min(ip + 1, n_p - 1)
            pa = np.uint64(p_cols[ip])
            pb = np.uint64(p_cols[ipb])
            oa = ip * npad
            ob = ipb * npad
            ra0 = load_i16(accf, oa)
            ra1 = load_i16(accf, oa + LANES)
            ra2 = load_i16(accf, oa + 2 * LANES)
            rb0 = load_i16(accf, ob)
            rb1 = load_i16(accf, ob + LANES)
            rb2 = load_i16(accf, ob + 2 * LANES)
            pending = -1
            for u in range(rr, width + step, step):
                h = (u // step) % 2  # quarters: rotation a at h, rotation b at 2 + h; the other column at 1 - h
                if u < width:
                    _column_minima2(flat, base, dv, dtab, np.uint64(start[u]), np.uint64(start[u + 1]), pa, pb,
                                    scratch, q * h, q * (2 + h), n)
                if pending >= 0:
                    so = q * (1 - h) + pending
                    ra0 = add_widened_u8(ra0, load_u8(scratch, so))
                    ra1 = add_widened_u8(ra1, load_u8(scratch, so + LANES))
                    ra2 = add_widened_u8(ra2, load_u8(scratch, so + 2 * LANES))
                    so = q * (3 - h) + pending
                    rb0 = add_widened_u8(rb0, load_u8(scratch, so))
                    rb1 = add_widened_u8(rb1, load_u8(scratch, so + LANES))
                    rb2 = add_widened_u8(rb2, load_u8(scratch, so + 2 * LANES))
                pending = u // step
            store_i16(accf, oa, ra0)
            store_i16(accf, oa + LANES, ra1)
            store_i16(accf, oa + 2 * LANES, ra2)
            store_i16(accf, ob, rb0)
            store_i16(accf, ob + LANES, rb1)
            store_i16(accf, ob + 2 * LANES, rb2)


@njit(nogil=True, cache=True)
def minwarp_search_u8(flat, n_planes, width, step, n, p_cols, start, w_plane, w_level, w_v, acc, scratch):
    """Min-warping match values of every alpha step for the rotations ``p_cols`` (8-bit distances).

    Parameters
    ----------
    flat : ndarray, shape (M,), uint8
        The window table of :func:`~bionav.homing.warping.kernels.fill_window_minima`
        (``levels.reshape(-1)``, shape (J + 1, K, W, step, n)) followed by at least
        :data:`TABLE_PAD` more bytes (read, never used).
    n_planes, width, step, n : int
        ``K``, ``W``, the alpha step in columns and ``n = W // step``.
    p_cols : ndarray, shape (P,), int64
        Rotations in columns (``0 <= p < W``).
    start, w_plane, w_level, w_v : ndarray, int64
        Min-warping windows (:func:`~bionav.homing.warping.templates.minwarp_windows`).
    acc : ndarray, shape (P, padded_lanes(n)), uint16
        Overwritten with the match values (lanes ``n ..`` are padding);
        ``acc[ip, a]`` equals ``minwarp_scores(...)[ip, a]``.
    scratch : ndarray, shape (search_scratch_size(n),), uint8
        Work space.
    """
    npad = acc.shape[1]
    accf = acc.reshape(-1)
    accf[:] = 0
    base, dv, dtab = _window_offsets(n_planes, width, step, n, start, w_plane, w_level, w_v)
    if n <= GROUP:  # two rotations per pass, all sums in registers
        _search_rotation_pairs(flat, base, dv, dtab, width, step, n, p_cols, start, accf, npad, scratch)
        return acc
    half = scratch.shape[0] // 2
    # more alpha steps: phase by phase (a third of the table at step 3 stays in cache), then rotation
    # by rotation; per snapshot column u the minima over its windows of all alpha steps, 96 at a time
    # (per absolute column i // step), added to the sums shifted by u // step one column later (by then
    # the minima's stores have reached the cache: an earlier shifted read of them would stall)
    for rr in range(step):
        for ip in range(p_cols.shape[0]):
            p = np.uint64(p_cols[ip])
            arow = ip * npad
            pending = -1
            for u in range(rr, width + step, step):
                sb = half * ((u // step) % 2)
                if u < width:
                    e0 = np.uint64(start[u])
                    e1 = np.uint64(start[u + 1])
                    for g0 in range(0, n, GROUP):
                        _column_minima(flat, base, dv, dtab, e0, e1, p, g0, scratch, sb, n)
                    # the last group's first copy ran into the second copy's start
                    for a in range(n, -(-n // GROUP) * GROUP):
                        scratch[sb + a] = scratch[sb + a - n]
                if pending >= 0:
                    so = (half - sb) + pending
                    for c in range(0, npad, LANES):
                        store_i16(accf, arow + c, add_widened_u8(load_i16(accf, arow + c), load_u8(scratch, so + c)))
                pending = u // step
    return acc


@njit(nogil=True, cache=True, inline="always")
def _column_sums(src, base, n_rows, n_cols, out):
    """``out[j] = sum_r src[base + r * n_cols + j]`` in wrapping 16-bit arithmetic (``n_cols >= 32``)."""
    last = n_cols - LANES
    for j0 in range(0, n_cols, LANES):
        j = min(j0, last)
        s = zero_i16()
        o = base + j
        for _ in range(n_rows):
            s = add_i16(s, load_i16(src, o))
            o += n_cols
        store_i16(out, j, s)


@njit(nogil=True, fastmath=True, cache=True)
def diagonal_distances_u8(sq, cq2, sn, cn2, step, quantum, out, acc):
    """8-bit NSAD in diagonal layout from 16-bit stacks (same result as
    :func:`~bionav.homing.warping.distance._diagonal_distances_q`).

    Parameters
    ----------
    sq : ndarray, shape (K, R, W), int16
        Quantised snapshot planes (``W >= 32``; ``|a - b| <= 32767`` for any two values, as
        :func:`~bionav.homing.warping.distance._image_quantum` ensures).
    cq2 : ndarray, shape (K, R, 2 W + 4), int16
        The current view's, repeated side by side (column ``j`` is column ``j mod W``).
    sn, cn2 : ndarray, shape (K, W) and (K, 2 W + 4), int32
        Column norms (the current view's repeated likewise).
    step, quantum : int
        Alpha step and the quantum ``q`` of the 8-bit distances.
    out : ndarray, shape (K, W, step, W // step), uint8
    acc : ndarray, shape (W + 4, W), uint16
        Work space (the sums of one plane).

    Notes
    -----
    ``|a - b| = 2 max(a, b) - a - b``: the kernel sums the maxima (two instructions per term
    instead of three) and subtracts the two columns' sums once per block; all of it in wrapping
    16-bit arithmetic, which is exact modulo 2^16, and the true sum lies in ``0 .. 65535``, so the
    sums equal the previous kernel's ``sum |a - b|`` bit for bit. The blocks of 32 columns are the
    outer loop and the diagonals the inner one, so that a block's rows stay in L1 cache (with the
    diagonals outside, every diagonal streamed both stacks, 87 KB per plane, from L2). The
    normalisation is :func:`~bionav.homing.warping.normalise._normalise_plane`, unchanged: its
    fast-math division (a compiled reciprocal estimate) decides the last bit of a distance.
    """
    n_planes, n_rows, width = sq.shape
    w2 = cq2.shape[2]
    sqf = sq.reshape(-1)
    cqf = cq2.reshape(-1)
    accf = acc.reshape(-1)
    t = np.zeros(width, np.uint8)
    ssum = np.empty(width, np.uint16)  # the columns' sums (wrapping 16 bits)
    csum = np.empty(w2, np.uint16)
    qf = np.float32(quantum)
    last = width - LANES
    for k in range(n_planes):
        sbase = k * n_rows * width
        cbase = k * n_rows * w2
        _column_sums(sqf, sbase, n_rows, width, ssum)
        _column_sums(cqf, cbase, n_rows, w2, csum)
        # column block by column block, all diagonals: the block's 49 snapshot rows (3 KB) and the current
        # view's rows it meets (about 10 KB) stay in L1 cache while the diagonals walk along them
        i0 = 0
        while i0 < width:
            i = min(i0, last)  # the last block overlaps the one before (same sums)
            xs = load_i16(ssum, i)
            for d in range(0, width, 4):
                s0 = zero_i16()
                s1 = zero_i16()
                s2 = zero_i16()
                s3 = zero_i16()
                xo = sbase + i  # running offsets of the two rows (no multiplication per row)
                cb = cbase + d + i
                for _ in range(n_rows):
                    x = load_i16(sqf, xo)
                    s0 = add_max_i16(s0, x, load_i16(cqf, cb))
                    s1 = add_max_i16(s1, x, load_i16(cqf, cb + 1))
                    s2 = add_max_i16(s2, x, load_i16(cqf, cb + 2))
                    s3 = add_max_i16(s3, x, load_i16(cqf, cb + 3))
                    xo += width
                    cb += w2
                # sum |a - b| = 2 sum max(a, b) - sum a - sum b (wrapping 16 bits, exact modulo 2^16)
                cs = d + i
                ab = d * width + i
                store_i16(accf, ab, sub_i16(sub_i16(add_i16(s0, s0), xs), load_i16(csum, cs)))
                store_i16(accf, ab + width, sub_i16(sub_i16(add_i16(s1, s1), xs), load_i16(csum, cs + 1)))
                store_i16(accf, ab + 2 * width, sub_i16(sub_i16(add_i16(s2, s2), xs), load_i16(csum, cs + 2)))
                store_i16(accf, ab + 3 * width, sub_i16(sub_i16(add_i16(s3, s3), xs), load_i16(csum, cs + 3)))
            i0 += LANES
        _normalise_plane(acc, sn[k], cn2[k], qf, t, out[k], step)
