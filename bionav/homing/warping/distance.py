"""Column distances between a snapshot and a current view for every scale plane.

The distance of two edge-filtered columns ``a`` and ``b`` (``n`` rows) is the
normalised sum of absolute differences

    NSAD(a, b) = sum_r |a_r - b_r| / (sum_r |a_r| + sum_r |b_r|),

which lies in ``[0, 1]`` (0 for identical columns; defined as 0 when both
columns are zero). Möller, Horst & Fleer (2014, "Illumination tolerance for
visual navigation with the holistic min-warping method", Robotics 3) found it
the best measure for min-warping on edge-filtered images.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from bionav.homing.warping.kernels import PARALLEL_LOCK


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


@njit(parallel=True, fastmath=True, cache=True)
def _diagonal_distances(snap, cur2, snap_norm, cur_norm2, step, out):
    """Fill ``out[k, d, i % step, i // step (+ n)] = NSAD(snap[k, :, i], cur[k, :, (i + d) % W])``.

    ``cur2`` and ``cur_norm2`` hold the current view's planes and norms twice
    side by side (width ``2 W``) so that column ``i + d`` needs no wrap.
    ``out`` has shape ``(K, W, step, 2 * n)`` with ``n = W // step``; the second
    half of the last axis repeats the first, so that ``n`` consecutive entries
    starting anywhere in the first half are a contiguous slice (the search
    kernels read the distances of all ``n`` alpha steps as one vector).
    """
    n_planes, n_rows, width = snap.shape
    n = width // step
    for t in prange(n_planes * width):
        k = t // width
        d = t - k * width
        acc = np.zeros(width, dtype=np.float32)
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
                out[k, d, rr, m + n] = val


def diagonal_distances(snapshot, current, *, step: int = 1, out=None):
    """Fast column distances in the layout the search kernels read.

    Parameters
    ----------
    snapshot, current : dict
        Scale-plane stacks (see :func:`column_distance_matrix`).
    step : int
        Alpha step in columns (``W`` must be a multiple of it).
    out : ndarray, shape (K, W, step, 2 * W // step), float32, optional
        Array to fill (C-contiguous), e.g. the first level of the search's
        window minima; a new one by default.

    Returns
    -------
    ndarray, shape (K, W, step, 2 * W // step), float32
        ``E[k, d, i % step, i // step]`` (and again at ``i // step + W // step``)
        equals ``column_distance_matrix(snapshot, current)[k, i, (i + d) % W]``.
    """
    snap = np.ascontiguousarray(snapshot["snap"], dtype=np.float32)
    cur = np.ascontiguousarray(current["cur"], dtype=np.float32)
    if snap.shape != cur.shape:
        raise ValueError(
            f"snapshot and current view stacks differ in shape: {snap.shape} vs {cur.shape}"
        )
    n_planes, _, width = snap.shape
    if width % step:
        raise ValueError(f"width {width} is not a multiple of the alpha step {step}")
    shape = (n_planes, width, step, 2 * (width // step))
    if out is None:
        out = np.empty(shape, dtype=np.float32)
    elif out.shape != shape or out.dtype != np.float32 or not out.flags.c_contiguous:
        raise ValueError(f"out must be a C-contiguous float32 array of shape {shape}")
    cur_norm = np.asarray(current["cur_norm"], dtype=np.float32)
    with PARALLEL_LOCK:
        _diagonal_distances(
            snap,
            np.concatenate([cur, cur], axis=2),
            np.ascontiguousarray(snapshot["snap_norm"], dtype=np.float32),
            np.concatenate([cur_norm, cur_norm], axis=1),
            int(step),
            out,
        )
    return out
