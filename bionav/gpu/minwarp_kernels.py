"""CUDA kernels of min-warping (numba-cuda), one thread per output value, a batch of pairs at once.

The layouts are those of the CPU kernels (:mod:`bionav.homing.warping.kernels`): per pair ``b`` the
window table ``lev[b, j, k, d, i % step, i // step]``. Every kernel but :func:`mw_distances` is integer
arithmetic and gives the CPU kernels' values bit for bit; :func:`mw_distances` divides in IEEE float32
(the CPU kernel's compiled division may use a refined reciprocal), see :mod:`bionav.gpu.minwarp`.
Imported only when device=cuda is used (:mod:`bionav.gpu.pairs`), so bionav never needs numba-cuda otherwise.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np

from bionav.gpu import cuda_module

#: numba.cuda (or its simulator): module level, so that the simulator finds the kernels' ``cuda``
cuda = cuda_module()


@cuda.jit(device=True)
def plane_diagonal(kd, width):
    """Plane ``k`` and diagonal ``d`` of the flat thread index ``kd = k * W + d``."""
    k = kd // width
    return k, kd - k * width


@cuda.jit(device=True)
def rint32(v):
    # round half to even, as numpy.rint (v: float32, |v| < 2**23; v - floor(v) is exact)
    f = math.floor(v)
    r = v - f
    if r > 0.5 or (r == 0.5 and f % 2 != 0):
        f += 1
    return f


@cuda.jit
def mw_quantise(snaps, curs, ps, pc, scale, sq, sn, cq, cn):
    """sq/cq[b, k, r, w] = rint(scale[b] * stack[k, r, w]) (int16), sn/cn[b, k, w] their column norms."""
    b, k, w = cuda.grid(3)
    if b >= ps.shape[0] or k >= sq.shape[1] or w >= sq.shape[3]:
        return
    s = scale[b]
    ns = 0
    nc = 0
    for r in range(sq.shape[2]):
        x = int(rint32(snaps[ps[b], k, r, w] * s))
        y = int(rint32(curs[pc[b], k, r, w] * s))
        sq[b, k, r, w] = x
        cq[b, k, r, w] = y
        ns += abs(x)
        nc += abs(y)
    sn[b, k, w] = ns
    cn[b, k, w] = nc


@cuda.jit
def mw_distances(sq, cq, sn, cn, qf, lev):
    """lev[b, 0, k, d, i % step, i // step] = uint8(float32(sum_r |sq - cq|) * q / norms + 0.5)."""
    b, kd, i = cuda.grid(3)
    n_planes, width, step = sq.shape[1], sq.shape[3], lev.shape[4]
    if b >= sq.shape[0] or kd >= n_planes * width or i >= width:
        return
    k, d = plane_diagonal(kd, width)
    j = i + d
    if j >= width:
        j -= width
    ac = 0
    for r in range(sq.shape[2]):
        ac += abs(int(sq[b, k, r, i]) - int(cq[b, k, r, j]))
    den = max(sn[b, k, i] + cn[b, k, j], 1)
    # the CPU kernel's formula in IEEE float32
    val = int(np.float32(ac) * qf / np.float32(den) + np.float32(0.5))
    lev[b, 0, k, d, i % step, i // step] = val


@cuda.jit
def mw_window_level(lev, j, h):
    """lev[b, j, k, d, x] = min(lev[b, j - 1, k, d, x], lev[b, j - 1, k, (d + h) % W, x])."""
    b, kd, x = cuda.grid(3)
    n_planes, width, step, n = lev.shape[2], lev.shape[3], lev.shape[4], lev.shape[5]
    if b >= lev.shape[0] or kd >= n_planes * width or x >= step * n:
        return
    k, d = plane_diagonal(kd, width)
    d2 = (d + h) % width
    rr = x // n
    m = x - rr * n
    lev[b, j, k, d, rr, m] = min(lev[b, j - 1, k, d, rr, m], lev[b, j - 1, k, d2, rr, m])


@cuda.jit
def mw_swap_roles(lev, out):
    """The swapped pair's level 0: ``E'[k, d, j] = E[K-1-k, -d, j + d]`` (indices modulo W)."""
    b, kd, j = cuda.grid(3)
    n_planes, width, step, n = lev.shape[2], lev.shape[3], lev.shape[4], lev.shape[5]
    if b >= lev.shape[0] or kd >= n_planes * width or j >= width:
        return
    k, d = plane_diagonal(kd, width)
    i = (j + d) % width
    out[b, 0, k, d, j % step, j // step] = lev[b, 0, n_planes - 1 - k, (width - d) % width, i % step, i // step]


@cuda.jit
def plane_compass(table, p_cols, out):
    """out[b, ip] = sum over columns of the smallest plane distance along rotation p_cols[ip] (float64, summed
    per phase as :func:`~bionav.homing.warping.kernels.compass_measure`); ``table[b, k, d, rr, m]``."""
    b, ip = cuda.grid(2)
    n_planes, width, step, n = table.shape[1], table.shape[2], table.shape[3], table.shape[4]
    if b >= table.shape[0] or ip >= p_cols.shape[0]:
        return
    d = (width - p_cols[ip]) % width
    total = 0.0
    for rr in range(step):
        s = 0.0
        for m in range(n):
            best = table[b, 0, d, rr, m]
            for k in range(1, n_planes):
                best = min(best, table[b, k, d, rr, m])
            s += np.float64(best)
        total += s
    out[b, ip] = total


@cuda.jit
def mw_search(lev, p_sel, start, w_plane, w_level, w_v, out):
    """out[b, ip, a] = sum_u min over u's windows of the table at rotation p_sel[b, ip] (uint16)."""
    b, ip, a = cuda.grid(3)
    width, step, n = lev.shape[3], lev.shape[4], lev.shape[5]
    if b >= lev.shape[0] or ip >= p_sel.shape[1] or a >= n:
        return
    p = p_sel[b, ip]
    acc = 0
    for u in range(width):
        rr = u % step
        m = (a + u // step) % n
        best = 255
        for e in range(start[u], start[u + 1]):
            d = (w_v[e] - u - p) % width
            best = min(best, lev[b, w_level[e], w_plane[e], d, rr, m])
        acc += int(best)
    out[b, ip, a] = acc & 0xFFFF


@cuda.jit
def mw_runs(lev, a_first, p_cols, start, w_plane, w_level, w_v, out):
    """out[b, t, a] = sum_u min over windows at rotation p_cols[b, t], direction a_first[b, t] + a (float64)."""
    b, t, a = cuda.grid(3)
    width, step, n = lev.shape[3], lev.shape[4], lev.shape[5]
    if b >= lev.shape[0] or t >= p_cols.shape[1] or a >= out.shape[2]:
        return
    p = p_cols[b, t]
    total = 0
    for u in range(width):
        i = (u + a_first[b, t] + a) % width
        best = 255
        for e in range(start[u], start[u + 1]):
            d = (w_v[e] - u - p) % width
            best = min(best, lev[b, w_level[e], w_plane[e], d, i % step, i // step])
        total += int(best)
    out[b, t, a] = total


def kernels():
    """The compiled kernels."""
    return SimpleNamespace(quantise=mw_quantise, distances=mw_distances, window_level=mw_window_level,
                           swap_roles=mw_swap_roles, compass=plane_compass, search=mw_search, runs=mw_runs)


def grid(shape, block=(1, 8, 32)):
    """Blocks per grid for ``shape`` (up to 3-D) with threads per block ``block``."""
    block = tuple(block[len(block) - len(shape):])
    return tuple(max(1, -(-int(s) // b)) for s, b in zip(shape, block)), block
