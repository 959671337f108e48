"""The all-pairs home vectors of :func:`bionav.evaluation.pairs.home_vector_matrix` on the GPU (``device=cuda``).

The per-image work is the CPU's (the plugin's ``prepare``); the pairs go to the GPU in batches and
the home angles and compass values come back in the CPU path's conventions (radians, grid frame:
the current view's heading added; NaN where snapshot and current view share a position).
"""

from __future__ import annotations

from typing import Any, Callable, Sequence

import numpy as np

from bionav.geometry import wrap_angle


def _pairs(snapshots, currents, s_idx) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Row, snapshot and current-view index of every pair to compute (other position)."""
    rows, ps, pc = [], [], []
    for k, si in enumerate(s_idx):
        other = np.flatnonzero(~np.all(currents.positions == snapshots.positions[si], axis=1))
        rows.append(np.full(other.size, k))
        ps.append(np.full(other.size, si))
        pc.append(other)
    cat = (lambda xs: np.concatenate(xs).astype(np.int64) if xs else np.zeros(0, np.int64))
    return cat(rows), cat(ps), cat(pc)


def _angles_of(method, snap_prep, cur_prep, ps, pc) -> tuple[np.ndarray, np.ndarray]:
    """Home angle (current view's frame) and compass psi (NaN: none) of the pairs, radians."""
    from bionav.gpu import check_method

    name = getattr(method, "name", type(method).__name__)
    check_method(name)
    if name == "sift":
        from bionav.gpu.sift import sift_pairs

        return sift_pairs(method, cur_prep, snap_prep, ps, pc), np.full(len(ps), np.nan)
    from bionav.homing.warping.search import _result

    if name == "minwarping":
        from bionav.gpu.minwarp import MinWarpGPU

        gpu = MinWarpGPU(method, snap_prep, cur_prep)
    else:
        from bionav.gpu.warp2d import Warp2dGPU

        gpu = Warp2dGPU(method, snap_prep, cur_prep)
    width = int(np.shape(snap_prep[0]["snap"])[-1])
    home, psi = np.empty(len(ps)), np.empty(len(ps))
    step = gpu.batch_size()
    for b0 in range(0, len(ps), step):
        best_a, best_p = gpu.best(ps[b0:b0 + step], pc[b0:b0 + step])
        for t, (a, p) in enumerate(zip(best_a, best_p)):
            r = _result(int(a), int(p), np.nan, 0.0, width)
            home[b0 + t], psi[b0 + t] = r.home_angle, r.psi
    return home, psi


def gpu_matrix(method, snapshots, currents, s_idx, snap_prep: Sequence[Any], cur_prep: Sequence[Any],
               on_row: Callable[[int, np.ndarray, np.ndarray], None] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Angles and compass errors ``(len(s_idx), len(currents))`` of every pair, computed on the GPU."""
    rows, ps, pc = _pairs(snapshots, currents, np.asarray(s_idx, np.int64))
    angles = np.full((len(s_idx), len(currents)), np.nan)
    compass = np.full((len(s_idx), len(currents)), np.nan)
    home, psi = _angles_of(method, snap_prep, cur_prep, ps, pc)
    angles[rows, pc] = home + currents.headings[pc]
    compass[rows, pc] = psi - (currents.headings[pc] - snapshots.headings[ps])
    angles, compass = wrap_angle(angles), wrap_angle(compass)
    if on_row is not None:
        for k, si in enumerate(s_idx):
            on_row(int(si), angles[k], compass[k])
    return angles, compass
