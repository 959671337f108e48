"""Min-warping of many pairs on the GPU: the steps of :func:`bionav.homing.warping.minwarping` per batch.

Per batch of pairs the GPU quantises both stacks (the CPU's common scale, rounded half to even), sums
the absolute differences of every column pair (integers), normalises them to 8 bits, builds the
window minima, and searches every (psi, alpha); the compass selection, the double search's
combination, the best hypothesis and its tie rule, and the fine search's choice are the CPU code's,
on the GPU's integer match values. So the result equals the CPU's whenever the 8-bit distances do.

Tolerance: the 8-bit distance ``uint8(float32(sum) * q / norms + 0.5)`` is computed here with IEEE
float32 division; the CPU kernel is compiled with fast-math (a refined reciprocal, 1-2 ulp), so the
two can differ by one quantum where the exact value lies on a rounding boundary (``x.5``). Otherwise,
distances, window minima, match values, compass measures and the chosen (alpha, psi) are identical
(``tests/gpu/test_gpu_simulator.py``: the distance sums, the table and every match value bit for
bit against the CPU kernels on the same inputs).
"""

from __future__ import annotations

import numpy as np

from bionav.gpu.minwarp_kernels import grid, kernels


def _stacks(preps, key):
    return np.ascontiguousarray(np.stack([np.asarray(p[key], np.float32) for p in preps]))


class MinWarpGPU:
    """The all-pairs min-warping of one plugin configuration on the GPU (device arrays kept per run)."""

    def __init__(self, method, snap_preps, cur_preps) -> None:
        from bionav.errors import UserError
        from bionav.gpu import cuda_module
        from bionav.homing.warping.distance import _image_quantum, distance_quantum
        from bionav.homing.warping.search import WINDOW_LEVEL, _column_grid, _layout_step
        from bionav.homing.warping.templates import minwarp_template, minwarp_windows

        cfg = method.config
        if not cfg.quantised:
            raise UserError("device=cuda runs min-warping's quantised search; set homing.quantised=true or use "
                            "device=cpu.")
        self.cuda, self.k, self.cfg = cuda_module(), kernels(), cfg
        n_planes, n_rows, width = np.shape(snap_preps[0]["snap"])
        scales, tau = method._scales()
        windows = minwarp_windows(minwarp_template(width, scales, tau), max_level=WINDOW_LEVEL)
        self.width, self.n_planes, self.n_rows = width, n_planes, n_rows
        self.a_cols, self.p_all = _column_grid(cfg.n_alpha, width), _column_grid(cfg.n_psi, width)
        self.step = _layout_step(width, cfg.n_alpha, self.p_all, cfg.double_search)
        self.n = width // self.step
        self.n_levels = int(windows[2].max(initial=0)) + 1
        self.q, acc = distance_quantum(width)
        if acc != np.uint16:
            raise UserError(f"device=cuda runs min-warping up to 1023 columns, not {width}; use device=cpu.")
        self.image_quantum = _image_quantum(n_rows)
        to = self.cuda.to_device
        self.windows = tuple(to(np.ascontiguousarray(w, np.int64)) for w in windows)
        self.snaps, self.curs = to(_stacks(snap_preps, "snap")), to(_stacks(cur_preps, "cur"))
        self.snap_top = np.array([float(p["snap_absmax"]) for p in snap_preps])
        self.cur_top = np.array([float(p["cur_absmax"]) for p in cur_preps])
        self.symmetric = bool(np.allclose(scales * scales[::-1], 1.0, rtol=1e-9, atol=0.0))

    def batch_size(self) -> int:
        """Pairs per batch: about 1.5 GB of window tables (two with the double search)."""
        per_pair = self.n_levels * self.n_planes * self.width * self.width * (2 if self.cfg.double_search else 1)
        return int(max(1, min(4096, 1.5e9 // per_pair)))

    def _tables(self, ps, pc):
        """The window tables of the pairs (snapshot ps[b], current view pc[b]) on the device."""
        cuda, k, w, kk = self.cuda, self.k, self.width, self.n_planes
        b = len(ps)
        top = np.maximum(self.snap_top[ps], self.cur_top[pc])
        scale = np.array([np.float32(self.image_quantum / t if t > 0 else 0.0) for t in top], np.float32)
        sq = cuda.device_array((b, kk, self.n_rows, w), np.int16)
        cq = cuda.device_array((b, kk, self.n_rows, w), np.int16)
        sn = cuda.device_array((b, kk, w), np.int32)
        cn = cuda.device_array((b, kk, w), np.int32)
        blocks, threads = grid((b, kk, w))
        k.quantise[blocks, threads](self.snaps, self.curs, cuda.to_device(ps), cuda.to_device(pc),
                                    cuda.to_device(scale), sq, sn, cq, cn)
        lev = cuda.device_array((b, self.n_levels, kk, w, self.step, self.n), np.uint8)
        blocks, threads = grid((b, kk * w, w))
        k.distances[blocks, threads](sq, cq, sn, cn, np.float32(self.q), lev)
        self._fill(lev)
        return lev

    def _fill(self, lev):
        b, kk, w = lev.shape[0], self.n_planes, self.width
        blocks, threads = grid((b, kk * w, self.step * self.n))
        for j in range(1, self.n_levels):
            self.k.window_level[blocks, threads](lev, j, 1 << (j - 1))

    def _search(self, lev, p_sel):
        b = lev.shape[0]
        out = self.cuda.device_array((b, p_sel.shape[1], self.n), np.uint16)
        blocks, threads = grid(out.shape)
        self.k.search[blocks, threads](lev, self.cuda.to_device(np.ascontiguousarray(p_sel)), *self.windows, out)
        return out.copy_to_host().astype(np.float64)

    def _select(self, lev):
        """Rotations searched per pair (compass acceleration as :func:`~bionav.homing.warping.search._select_psi`)."""
        b, cfg, p_all = lev.shape[0], self.cfg, self.p_all
        if not cfg.compass_acceleration or cfg.compass_fraction >= 1.0:
            return np.tile(p_all, (b, 1))
        measure = self.cuda.device_array((b, p_all.size), np.float64)
        blocks, threads = grid(measure.shape, block=(8, 32))
        self.k.compass[blocks, threads](lev[:, 0], self.cuda.to_device(p_all), measure)
        measure = measure.copy_to_host()
        n_sel = max(1, int(np.ceil(cfg.compass_fraction * p_all.size)))
        keep = np.sort(np.argsort(measure, axis=1, kind="stable")[:, :n_sel], axis=1)
        return p_all[keep]

    def best(self, ps, pc):
        """Per pair (snapshot ps[b], current view pc[b]) the best (alpha column, psi column)."""
        from bionav.errors import UserError

        ps, pc = np.asarray(ps, np.int64), np.asarray(pc, np.int64)
        lev = self._tables(ps, pc)
        p_sel = self._select(lev)
        scores = self._search(lev, p_sel)
        lev2 = None
        w, step = self.width, self.step
        if self.cfg.double_search:
            if not self.symmetric:
                raise UserError("device=cuda's double search needs inversion-symmetric scale factors (the "
                                "default ones); use device=cpu for these homing.scales.")
            lev2 = self.cuda.device_array_like(lev)
            blocks, threads = grid((lev.shape[0], self.n_planes * w, w))
            self.k.swap_roles[blocks, threads](lev, lev2)
            self._fill(lev2)
            scores2 = self._search(lev2, (-p_sel) % w)
            a_eff = np.arange(self.n) * step
            idx = ((a_eff[None, None, :] + w // 2 - p_sel[:, :, None]) % w) // step
            scores = scores + np.take_along_axis(scores2, idx, axis=2)
        scores = scores[:, :, self.a_cols // step]
        flat = scores.reshape(len(ps), -1)
        t = np.argmin(flat, axis=1)
        ip, ia = np.unravel_index(t, scores.shape[1:])
        best_a, best_p = self.a_cols[ia], p_sel[np.arange(len(ps)), ip]
        best = flat[np.arange(len(ps)), t]
        if self.cfg.fine_search:
            best_a, best_p = self._fine(lev, lev2, best_a, best_p, best)
        return best_a, best_p

    def _fine(self, lev, lev2, best_a, best_p, best):
        """:func:`~bionav.homing.warping.search._fine_minwarp` for every pair (same order and ties)."""
        cuda, w, cfg = self.cuda, self.width, self.cfg
        ra = max(1, int(np.ceil(w / cfg.n_alpha)) - 1)
        rp = max(1, int(np.ceil(w / cfg.n_psi)) - 1)
        pc = (best_p[:, None] + np.arange(-rp, rp + 1)[None, :]) % w
        a_first = np.broadcast_to(((best_a - ra) % w)[:, None], pc.shape).copy()

        def runs(table, a0, p):
            out = cuda.device_array((len(best_a), p.shape[1], 2 * ra + 1), np.float64)
            blocks, threads = grid(out.shape)
            self.k.runs[blocks, threads](table, cuda.to_device(np.ascontiguousarray(a0)),
                                         cuda.to_device(np.ascontiguousarray(p)), *self.windows, out)
            return out.copy_to_host()

        vals = runs(lev, a_first, pc)
        if lev2 is not None:
            vals = vals + runs(lev2, (a_first + w // 2 - pc) % w, (-pc) % w)
        vals = np.transpose(vals, (0, 2, 1)).reshape(len(best_a), -1)  # (direction, rotation) order
        t = np.argmin(vals, axis=1)
        better = vals[np.arange(len(best_a)), t] < best
        ia, ip = np.divmod(t, pc.shape[1])
        new_a = np.where(better, (best_a - ra + ia) % w, best_a)
        new_p = np.where(better, pc[np.arange(len(best_a)), ip], best_p)
        return new_a, new_p
