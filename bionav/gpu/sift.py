"""SIFT homing's matching of many pairs on the GPU; the home angles from the matches on the CPU.

One thread per (pair, current keypoint) visits every snapshot keypoint, applies the neighbourhood
test of :func:`bionav.homing.sift_homing.match_in_neighbourhood` (float64, the same expression) and
keeps the smallest key ``(|d_s|^2 - 2 d_c . d_s) * 2**32 + snapshot index`` (ties: the lowest
index). The descriptors are integers in 0..255, so the float32 dot products are exact in any order:
the matches are the CPU kernel's, bit for bit, and the home angles (computed from them by the CPU's
:func:`~bionav.homing.sift_kernels.home_angle_from_keys`) are the CPU path's.
"""

from __future__ import annotations

import numpy as np

from bionav.gpu import cuda_module

#: numba.cuda (or its simulator): module level, so that the simulator finds the kernels' ``cuda``
cuda = cuda_module()


@cuda.jit
def match(x, y, desc, base, kp_off, pa, pb, out_off, radius, width, out):
    """out[out_off[t] + i]: best key of current keypoint i of image pa[t] among image pb[t]'s keypoints."""
    t, i = cuda.grid(2)
    if t >= pa.shape[0]:
        return
    a0, b0, b1 = kp_off[pa[t]], kp_off[pb[t]], kp_off[pb[t] + 1]
    if i >= kp_off[pa[t] + 1] - a0:
        return
    r2 = radius * radius
    xi, yi = x[a0 + i], y[a0 + i]
    best = 0x7FFFFFFFFFFFFFFF
    for j in range(b0, b1):
        dx = abs(xi - x[j])
        dx = min(dx, width - dx)
        dy = yi - y[j]
        if dx * dx + dy * dy < r2:
            dot = np.float32(0.0)
            for c in range(desc.shape[1]):
                dot += desc[a0 + i, c] * desc[j, c]
            key = base[j] - np.int64(dot) * np.int64(2) * (np.int64(1) << np.int64(32))
            best = min(best, key)
    out[out_off[t] + i] = best


def _kernel():
    """The compiled kernels."""
    return match


def sift_pairs(method, cur_prep, snap_prep, ps, pc) -> np.ndarray:
    """Home angles (radians, the current view's frame; NaN without usable matches) of pairs (ps[t], pc[t])."""
    from bionav.errors import UserError
    from bionav.gpu import cuda_module
    from bionav.gpu.minwarp_kernels import grid
    from bionav.homing.sift_homing import MIN_ELEVATION, N_BINS, column_index
    from bionav.homing.sift_kernels import home_angle_from_keys

    if cur_prep is not snap_prep:
        cur_index = [column_index(f) for f in cur_prep]
        index = cur_index + [column_index(f) for f in snap_prep]
        offset = len(cur_prep)
    else:
        index, offset = [column_index(f) for f in cur_prep], 0
    if any(ix is None for ix in index):
        raise UserError("device=cuda matches SIFT descriptors that are integers (OpenCV's); use device=cpu.")
    cuda = cuda_module()
    kp_off = np.concatenate([[0], np.cumsum([len(ix.x) for ix in index])]).astype(np.int64)
    x = np.concatenate([ix.x for ix in index])
    y = np.concatenate([ix.y for ix in index])
    desc = np.concatenate([ix.descriptors[:len(ix.x)] for ix in index]).astype(np.float32)
    base = np.concatenate([ix.sq_norms * (np.int64(1) << np.int64(32)) + ix.rank for ix in index])
    pa, pb = np.asarray(pc, np.int64), np.asarray(ps, np.int64) + offset
    sizes = kp_off[pa + 1] - kp_off[pa]
    out_off = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    out = cuda.device_array(max(1, int(out_off[-1])), np.int64)
    geo, cfg = method.work_geometry, method.config
    radius = float(cfg.search_radius * geo.width)
    blocks, threads = grid((len(pa), max(1, int(sizes.max(initial=1)))), block=(4, 64))
    _kernel()[blocks, threads](*(cuda.to_device(np.ascontiguousarray(v)) for v in (x, y, desc, base, kp_off)),
                               cuda.to_device(pa), cuda.to_device(pb), cuda.to_device(out_off), radius,
                               float(geo.width), out)
    keys = out.copy_to_host()
    angles = np.empty(len(pa))
    for t, (a, b) in enumerate(zip(pa, pb)):
        ia, ib = index[a], index[b]
        angles[t], _ = home_angle_from_keys(keys[out_off[t]:out_off[t + 1]], ia.x, ia.y, ia.where, ib.x, ib.y,
                                            ib.where, geo.rad_per_column, float(geo.horizon_row),
                                            float(geo.rad_per_row), MIN_ELEVATION, cfg.combine == "max", N_BINS,
                                            int(cfg.window))
    return angles
