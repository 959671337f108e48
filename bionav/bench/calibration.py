"""``python -m bionav.bench --method calibrate``: the plan's calibration workloads, timed on this machine.

Four short workloads (about two seconds of CPU in all), each the minimum CPU time
(``time.process_time``) over 12 rounds in which every workload runs once (interleaved), so that other
processes change it little:

* ``minwarping``: min-warping home vectors of a synthetic pair at 288 x 50 (96 x 96 steps);
* ``warping2d``: 2D-warping home vectors of the same pair;
* ``sift``: neighbourhood matching of two synthetic sets of 700 keypoints (integer descriptors);
* ``python``: a loop of small NumPy operations (the start-up and bookkeeping of a run).

The plan (:mod:`bionav.thesis.calibration`) runs this command, caches its JSON line per CPU and
compares it with the reference machine's.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np


def _pair():
    """Two synthetic 288 x 50 panoramas (smooth random texture, the second one shifted and rolled)."""
    from bionav.geometry import PanoramaGeometry

    rng = np.random.default_rng(42)
    noise = rng.random((50, 288 + 16)).astype(np.float32)
    kernel = np.ones(9, np.float32) / 9.0
    smooth = np.apply_along_axis(lambda r: np.convolve(r, kernel, mode="valid"), 1, noise)[:, :288]
    snap = (smooth - smooth.min()) / np.ptp(smooth)
    cur = np.roll(snap, 17, axis=1) * 0.8 + 0.1
    return snap, cur, PanoramaGeometry.square_pixels(288, 50)


#: interleaved rounds: every round times each workload once, the minimum over the rounds is kept, so that a burst
#: of other work on the machine spoils a round of every family, not all rounds of one
ROUNDS = 12


def _interleaved_min_ms(workloads: dict, rounds: int = ROUNDS) -> dict[str, float]:
    for fn, _ in workloads.values():
        fn()  # warm-up: compilation, caches
    best = {name: float("inf") for name in workloads}
    for _ in range(rounds):
        for name, (fn, calls) in workloads.items():
            c0 = time.process_time()
            for _ in range(calls):
                fn()
            best[name] = min(best[name], (time.process_time() - c0) / calls)
    return {name: 1e3 * t for name, t in best.items()}


def _workloads():
    from bionav.homing.features import SiftFeatures
    from bionav.homing.sift_homing import column_index, match_in_neighbourhood
    from bionav.homing.warping import minwarping, scale_plane_stack, warping2d

    snap, cur, geo = _pair()
    s, c = scale_plane_stack(snap, geometry=geo), scale_plane_stack(cur, geometry=geo)
    rng = np.random.default_rng(7)

    def features(n=700):
        xy = np.column_stack([rng.random(n) * 1122, rng.random(n) * 162]).astype(np.float32)
        d = rng.integers(0, 256, (n, 128)).astype(np.float32)
        return column_index(SiftFeatures(xy, d, (d * d).sum(axis=1), width=np.asarray(1122)))

    fa, fb = features(), features()
    small = rng.random(64)

    def python_loop():
        total = 0.0
        for i in range(2000):
            total += float(np.sum(small * i)) + len(str(i))
        return total

    return {  # family: (workload, calls per round)
        "minwarping": (lambda: minwarping(s, c), 3),
        "warping2d": (lambda: warping2d(s, c), 1),
        "sift": (lambda: match_in_neighbourhood(fa, fb, radius=247.0, width=1122), 4),
        "python": (python_loop, 1),
    }


def run_calibration() -> dict[str, Any]:
    """Time the workloads on this machine: ``{family: CPU ms, ..., "machine", "cpu"}``."""
    from bionav.bench.cpu import numba_target
    from bionav.machine import cpu_model, machine_label

    out: dict[str, Any] = {f: round(ms, 4) for f, ms in _interleaved_min_ms(_workloads()).items()}
    out.update(machine=f"{cpu_model()}, {machine_label()}", cpu=numba_target()["cpu"])
    return out
