"""Column distances between a snapshot and a current view for every scale plane.

The distance of two edge-filtered columns ``a`` and ``b`` (``n`` rows) is the
normalised sum of absolute differences

    NSAD(a, b) = sum_r |a_r - b_r| / (sum_r |a_r| + sum_r |b_r|),

which lies in ``[0, 1]`` (0 for identical columns; defined as 0 when both
columns are zero). Möller, Horst & Fleer (2014, "Illumination tolerance for
visual navigation with the holistic min-warping method", Robotics 3) found it
the best measure for min-warping on edge-filtered images.

The fast path (``quantised=True``) computes it as the SIMD reference
implementation of min-warping does (Möller, Horst & Fleer 2014; WarpingSIMD):
both stacks are quantised to 16-bit integers with one common scale (NSAD does
not change when both columns are scaled alike), the absolute differences are
summed in 16 bits, and the distance is stored as a byte,
``round(NSAD * q)`` with the quantum ``q`` of :func:`distance_quantum`.
"""

from __future__ import annotations

import threading

import numpy as np
from numba import njit

from bionav.homing.warping.normalise import _normalise_plane


def column_distance_matrix(snapshot, current):
    """Reference column distances, plain numpy.

    Parameters
    ----------
    snapshot, current : dict
        Scale-plane stacks of :func:`~bionav.homing.warping.scaleplanes.scale_plane_stack`
        for the snapshot and the current view.

    Returns
    -------
    ndarray, shape (K, W, W), float64
        ``D[k, i, j]``: NSAD between column ``i`` of the snapshot's plane ``k``
        (snapshot role) and column ``j`` of the current view's plane ``k``
        (current role).
    """
    a = np.asarray(snapshot["snap"], dtype=np.float64)  # (K, R, W)
    b = np.asarray(current["cur"], dtype=np.float64)
    num = np.abs(a[:, :, :, None] - b[:, :, None, :]).sum(axis=1)
    den = np.abs(a).sum(axis=1)[:, :, None] + np.abs(b).sum(axis=1)[:, None, :]
    out = np.zeros_like(num)
    np.divide(num, den, out=out, where=den > 0)
    return out


def distance_quantum(width: int):
    """Quantum of the 8-bit distances and the dtype of their sums over ``width`` columns.

    Returns
    -------
    q : int
        Quantised distances are ``round(NSAD * q)`` in ``0 .. q``;
        ``q = min(255, 65535 // width)`` so that a match value (a sum over
        ``width`` columns) fits 16 bits (227 at 288 columns, 189 at 346).
    dtype : numpy dtype
        ``uint16``, or ``uint32`` with ``q = 255`` for panoramas wider than
        1023 columns.
    """
    q = min(255, 65535 // int(width))
    if q >= 64:
        return q, np.dtype(np.uint16)
    return 255, np.dtype(np.uint32)


def _image_quantum(n_rows: int) -> int:
    """Largest |value| of the 16-bit edge images: ``2 * n_rows * q`` must fit 16 bits."""
    return max(1, min(2047, 65535 // (2 * int(n_rows))))


@njit(nogil=True, fastmath=True, cache=True)
def _quantise(planes, scale, out, norms):
    """``out[k, r, j] = round(scale * planes[k, r, j % W])`` (``j < out.shape[2]``); ``norms`` = sum_r |out|."""
    n_planes, n_rows, width = planes.shape
    n_out = out.shape[2]
    for k in range(n_planes):
        nk = norms[k]
        for j in range(n_out):
            nk[j] = 0
        for r in range(n_rows):
            src = planes[k, r]
            o = out[k, r]
            for j in range(width):
                o[j] = np.int16(np.rint(src[j] * scale))
            for j in range(width, n_out):
                o[j] = o[j - width]
            for j in range(n_out):
                nk[j] += abs(np.int32(o[j]))


@njit(nogil=True, fastmath=True, cache=True, inline="always")
def _add_row_distances(af, a0, c0, width):
    """Add one row's ``|a0[i] - c0[i + d]|`` to the diagonal sums ``af[d * W + i]`` (16-bit)."""
    uw = np.uint64(width)
    for d in range(width):
        ud = np.uint64(d)
        ab = ud * uw
        for i in range(width):
            ui = np.uint64(i)
            af[ab + ui] += np.uint16(abs(np.int16(a0[ui] - c0[ud + ui])))


@njit(nogil=True, fastmath=True, cache=True)
def _diagonal_distances_q(sq, cq2, sn, cn2, step, quantum, out):
    """8-bit NSAD in diagonal layout from 16-bit stacks.

    ``sq`` (K, R, W) and ``sn`` (K, W): quantised snapshot planes and column
    norms; ``cq2`` (K, R, >= 2 W + 1) and ``cn2`` (K, >= 2 W + 1): the current view's,
    twice side by side (and more columns), so that the columns ``i + d`` of
    all snapshot columns ``i`` are one contiguous run. The sums of a plane are kept for all diagonals
    (``W x W`` 16-bit, in L2 cache) and built eight rows at a time, so that
    those rows stay in L1 cache while every diagonal visits them; the inner
    loops run over all ``W`` columns (32 16-bit lanes). The bytes are then
    de-interleaved into ``out[k, d, i % step, i // step]``.
    """
    n_planes, n_rows, width = sq.shape
    acc = np.empty((width + 1, width), np.uint16)  # row W: scratch for odd W
    af = acc.reshape(-1)
    uw = np.uint64(width)
    t = np.zeros(width, np.uint8)
    qf = np.float32(quantum)
    for k in range(n_planes):
        acc[:] = 0
        # |a - b| of 16-bit values (|a|, |b| <= 2047: no overflow); two
        # diagonals per pass share the loads of the snapshot rows
        r = 0
        while r + 8 <= n_rows:
            a0 = sq[k, r]
            a1 = sq[k, r + 1]
            a2 = sq[k, r + 2]
            a3 = sq[k, r + 3]
            a4 = sq[k, r + 4]
            a5 = sq[k, r + 5]
            a6 = sq[k, r + 6]
            a7 = sq[k, r + 7]
            c0 = cq2[k, r]
            c1 = cq2[k, r + 1]
            c2 = cq2[k, r + 2]
            c3 = cq2[k, r + 3]
            c4 = cq2[k, r + 4]
            c5 = cq2[k, r + 5]
            c6 = cq2[k, r + 6]
            c7 = cq2[k, r + 7]
            for d in range(0, width, 2):
                # unsigned offsets into whole rows: no array views per diagonal
                ud = np.uint64(d)
                ab = ud * uw
                for i in range(width):
                    ui = np.uint64(i)
                    j = ud + ui
                    j1 = j + np.uint64(1)
                    x0 = a0[ui]
                    x1 = a1[ui]
                    x2 = a2[ui]
                    x3 = a3[ui]
                    x4 = a4[ui]
                    x5 = a5[ui]
                    x6 = a6[ui]
                    x7 = a7[ui]
                    af[ab + ui] += np.uint16(
                        abs(np.int16(x0 - c0[j])) + abs(np.int16(x1 - c1[j]))
                        + abs(np.int16(x2 - c2[j])) + abs(np.int16(x3 - c3[j]))
                        + abs(np.int16(x4 - c4[j])) + abs(np.int16(x5 - c5[j]))
                        + abs(np.int16(x6 - c6[j])) + abs(np.int16(x7 - c7[j]))
                    )
                    af[ab + uw + ui] += np.uint16(
                        abs(np.int16(x0 - c0[j1])) + abs(np.int16(x1 - c1[j1]))
                        + abs(np.int16(x2 - c2[j1])) + abs(np.int16(x3 - c3[j1]))
                        + abs(np.int16(x4 - c4[j1])) + abs(np.int16(x5 - c5[j1]))
                        + abs(np.int16(x6 - c6[j1])) + abs(np.int16(x7 - c7[j1]))
                    )
            r += 8
        while r < n_rows:
            _add_row_distances(af, sq[k, r], cq2[k, r], width)
            r += 1
        _normalise_plane(acc, sn[k], cn2[k], qf, t, out[k], step)


@njit(nogil=True, fastmath=True, cache=True)
def _diagonal_distances(snap, cur2, snap_norm, cur_norm2, step, out):
    """Fill ``out[k, d, i % step, i // step] = NSAD(snap[k, :, i], cur[k, :, (i + d) % W])``.

    ``cur2`` and ``cur_norm2`` hold the current view's planes and norms twice
    side by side (width ``2 W``) so that column ``i + d`` needs no wrap.
    ``out`` has shape ``(K, W, step, n)`` with ``n = W // step``.
    """
    n_planes, n_rows, width = snap.shape
    n = width // step
    acc = np.zeros(width, dtype=np.float32)
    for k in range(n_planes):
        for d in range(width):
            acc[:] = 0.0
            for r in range(n_rows):
                a = snap[k, r]
                b = cur2[k, r, d:d + width]
                for i in range(width):
                    acc[i] += abs(a[i] - b[i])
            na = snap_norm[k]
            nb = cur_norm2[k, d:d + width]
            # loop over (i % step, i // step) rather than dividing: an integer
            # division by a run-time step costs more than the whole row sum
            for rr in range(step):
                for m in range(n):
                    i = m * step + rr
                    den = na[i] + nb[i]
                    val = np.float32(0.0)
                    if den > 0:
                        val = acc[i] / den
                    out[k, d, rr, m] = val


_SCRATCH = threading.local()


def _scratch(name, shape, dtype):
    """A per-thread array kept between calls (contents undefined)."""
    cache = _SCRATCH.__dict__.setdefault("arrays", {})
    arr = cache.get(name)
    if arr is None or arr.shape != shape or arr.dtype != dtype:
        arr = np.empty(shape, dtype=dtype)
        cache[name] = arr
    return arr


def _absmax(stack, key):
    if f"{key}_absmax" in stack:
        return float(stack[f"{key}_absmax"])
    return float(np.abs(np.asarray(stack[key])).max(initial=0.0))


def _quantisation_scale(snapshot, current, n_rows: int):
    """The common scale of both stacks' 16-bit images (largest |value| to :func:`_image_quantum`)."""
    top = max(_absmax(snapshot, "snap"), _absmax(current, "cur"))
    return np.float32(_image_quantum(n_rows) / top if top > 0 else 0.0)


def diagonal_distances(snapshot, current, *, step: int = 1, out=None, quantised: bool = False):
    """Fast column distances in the layout the search kernels read.

    Parameters
    ----------
    snapshot, current : dict
        Scale-plane stacks (see :func:`column_distance_matrix`).
    step : int
        Alpha step in columns (``W`` must be a multiple of it).
    out : ndarray, shape (K, W, step, W // step), optional
        Array to fill (C-contiguous, float32 or uint8 for ``quantised``), e.g.
        the first level of the search's window minima; a new one by default.
    quantised : bool
        Quantise as the SIMD reference does (16-bit images, 16-bit sums, 8-bit
        distances ``round(NSAD * q)``, ``q`` of :func:`distance_quantum`);
        float32 NSAD otherwise.

    Returns
    -------
    ndarray, shape (K, W, step, W // step), float32 or uint8
        ``E[k, d, i % step, i // step]`` equals ``column_distance_matrix(snapshot, current)[k, i, (i + d) % W]``
        (times ``q`` and rounded when quantised).
    """
    snap = np.ascontiguousarray(snapshot["snap"], dtype=np.float32)
    cur = np.ascontiguousarray(current["cur"], dtype=np.float32)
    if snap.shape != cur.shape:
        raise ValueError(
            f"snapshot and current view stacks differ in shape: {snap.shape} vs {cur.shape}"
        )
    n_planes, n_rows, width = snap.shape
    if width % step:
        raise ValueError(f"width {width} is not a multiple of the alpha step {step}")
    n = width // step
    shape = (n_planes, width, step, n)
    dtype = np.uint8 if quantised else np.float32
    if out is None:
        out = np.empty(shape, dtype=dtype)
    elif out.shape != shape or out.dtype != dtype or not out.flags.c_contiguous:
        raise ValueError(f"out must be a C-contiguous {np.dtype(dtype).name} array of shape {shape}")
    if quantised:
        scale = _quantisation_scale(snapshot, current, n_rows)
        # per-thread scratch arrays: fresh ones would be new pages (page faults) on every call
        sq = _scratch("sq", (n_planes, n_rows, width), np.int16)
        sn = _scratch("sn", (n_planes, width), np.int32)
        cq2 = _scratch("cq2", (n_planes, n_rows, 2 * width + 4), np.int16)
        cn2 = _scratch("cn2", (n_planes, 2 * width + 4), np.int32)
        _quantise(snap, scale, sq, sn)
        _quantise(cur, scale, cq2, cn2)
        if width >= 32:  # the vector kernel (same result; its blocks are 32 columns wide)
            from bionav.homing.warping.vkernels import diagonal_distances_u8

            acc = _scratch("acc", (width + 4, width), np.uint16)
            diagonal_distances_u8(sq, cq2, sn, cn2, int(step), distance_quantum(width)[0], out, acc)
        else:
            _diagonal_distances_q(sq, cq2, sn, cn2, int(step), distance_quantum(width)[0], out)
        return out
    cur_norm = np.asarray(current["cur_norm"], dtype=np.float32)
    _diagonal_distances(
        snap,
        np.concatenate([cur, cur], axis=2),
        np.ascontiguousarray(snapshot["snap_norm"], dtype=np.float32),
        np.concatenate([cur_norm, cur_norm], axis=1),
        int(step),
        out,
    )
    return out
