"""2D-warping of many pairs on the GPU: the steps of :func:`bionav.homing.warping.warping2d` per batch.

The float32 column distances (NSAD), the compass measure and the match values are summed in the CPU
kernels' order (rows, then columns), so they differ from the CPU's only by the division of the
NSAD: IEEE float32 here, a refined reciprocal in the CPU kernel compiled with fast-math (a relative
difference of about 1e-7). The best hypothesis can therefore differ only where two hypotheses'
match values lie within about 1e-6 of each other (``tests/gpu/test_gpu_simulator.py`` checks the
match values within ``rtol=1e-5`` and the chosen hypotheses on its pairs).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from bionav.gpu import cuda_module
from bionav.gpu.minwarp_kernels import plane_compass, plane_diagonal

#: numba.cuda (or its simulator): module level, so that the simulator finds the kernels' ``cuda``
cuda = cuda_module()


@cuda.jit
def w2_distances(snaps, curs, snorm, cnorm, ps, pc, dist):
    """dist[b, k, d, i % step, i // step] = NSAD of snapshot column i and current column i + d (float32)."""
    b, kd, i = cuda.grid(3)
    n_planes, width, step = snaps.shape[1], snaps.shape[3], dist.shape[3]
    if b >= ps.shape[0] or kd >= n_planes * width or i >= width:
        return
    k, d = plane_diagonal(kd, width)
    j = (i + d) % width
    acc = np.float32(0.0)
    for r in range(snaps.shape[2]):
        acc += abs(snaps[ps[b], k, r, i] - curs[pc[b], k, r, j])
    den = snorm[ps[b], k, i] + cnorm[pc[b], k, j]
    dist[b, k, d, i % step, i // step] = acc / den if den > 0 else np.float32(0.0)


@cuda.jit
def w2_search(dist, p_sel, v_tab, k_tab, out):
    """out[b, il * P + ip, a]: sum over u of the predicted column pair's distance (float32, u in order)."""
    b, lp, a = cuda.grid(3)
    width, step, n = dist.shape[2], dist.shape[3], dist.shape[4]
    n_p = p_sel.shape[1]
    if b >= dist.shape[0] or lp >= v_tab.shape[0] * n_p or a >= n:
        return
    il = lp // n_p
    p = p_sel[b, lp - il * n_p]
    acc = np.float32(0.0)
    for u in range(width):
        m0 = u // step
        d = (v_tab[il, u] - u - p) % width
        acc += dist[b, k_tab[il, u], d, u - m0 * step, (a + m0) % n]
    out[b, lp, a] = acc


def _kernels():
    """The compiled kernels."""
    return SimpleNamespace(distances=w2_distances, compass=plane_compass, search=w2_search)


class Warp2dGPU:
    """The all-pairs 2D-warping of one plugin configuration on the GPU."""

    def __init__(self, method, snap_preps, cur_preps) -> None:
        from bionav.errors import UserError
        from bionav.gpu import cuda_module
        from bionav.homing.warping.search import _column_grid, _layout_step, rho_grid
        from bionav.homing.warping.templates import warp2d_template

        cfg = method.config
        if cfg.fine_search:
            raise UserError("device=cuda runs 2D-warping without homing.fine_search; set it false or use device=cpu.")
        self.cuda, self.k, self.cfg = cuda_module(), _kernels(), cfg
        self.n_planes, _, self.width = np.shape(snap_preps[0]["snap"])
        self.a_cols, self.p_all = _column_grid(cfg.n_alpha, self.width), _column_grid(cfg.n_psi, self.width)
        self.step = _layout_step(self.width, cfg.n_alpha, self.p_all, False)
        self.n = self.width // self.step
        v_tab, k_tab = warp2d_template(self.width, rho_grid(cfg.n_rho, cfg.rho_max), method._scales()[1])
        to = self.cuda.to_device
        self.v_tab, self.k_tab, self.n_rho = to(v_tab.astype(np.int64)), to(k_tab.astype(np.int64)), v_tab.shape[0]
        self.snaps = to(np.stack([np.asarray(p["snap"], np.float32) for p in snap_preps]))
        self.curs = to(np.stack([np.asarray(p["cur"], np.float32) for p in cur_preps]))
        self.snorm = to(np.stack([np.asarray(p["snap_norm"], np.float32) for p in snap_preps]))
        self.cnorm = to(np.stack([np.asarray(p["cur_norm"], np.float32) for p in cur_preps]))

    def batch_size(self) -> int:
        return int(max(1, min(4096, 1e9 // (4 * self.n_planes * self.width * self.width))))

    def best(self, ps, pc):
        from bionav.gpu.minwarp_kernels import grid

        cuda, k, cfg, w = self.cuda, self.k, self.cfg, self.width
        b = len(ps)
        dist = cuda.device_array((b, self.n_planes, w, self.step, self.n), np.float32)
        blocks, threads = grid((b, self.n_planes * w, w))
        k.distances[blocks, threads](self.snaps, self.curs, self.snorm, self.cnorm,
                                     cuda.to_device(np.asarray(ps, np.int64)), cuda.to_device(np.asarray(pc, np.int64)),
                                     dist)
        p_sel = np.tile(self.p_all, (b, 1))
        if cfg.compass_acceleration and cfg.compass_fraction < 1.0:
            measure = cuda.device_array((b, self.p_all.size), np.float64)
            blocks, threads = grid(measure.shape, block=(8, 32))
            k.compass[blocks, threads](dist, cuda.to_device(self.p_all), measure)
            n_sel = max(1, int(np.ceil(cfg.compass_fraction * self.p_all.size)))
            keep = np.sort(np.argsort(measure.copy_to_host(), axis=1, kind="stable")[:, :n_sel], axis=1)
            p_sel = self.p_all[keep]
        out = cuda.device_array((b, self.n_rho * p_sel.shape[1], self.n), np.float32)
        blocks, threads = grid(out.shape)
        k.search[blocks, threads](dist, cuda.to_device(np.ascontiguousarray(p_sel)), self.v_tab, self.k_tab, out)
        scores = out.copy_to_host().reshape(b, self.n_rho, p_sel.shape[1], self.n)[:, :, :, self.a_cols // self.step]
        t = np.argmin(scores.reshape(b, -1), axis=1)
        _, ip, ia = np.unravel_index(t, scores.shape[1:])
        return self.a_cols[ia], p_sel[np.arange(b), ip]
