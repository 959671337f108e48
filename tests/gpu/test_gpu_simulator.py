"""The GPU backend (bionav/gpu, device=cuda) against the CPU kernels, in numba-cuda's CUDA simulator.

No GPU is needed: NUMBA_ENABLE_CUDASIM=1 runs the kernels as Python threads, so the images are
tiny (16 x 8, three scale planes, 4 x 4 or 8 x 8 search steps) and the pairs few. Integer stages are
compared bit for bit, the float ones within the tolerances bionav/gpu states.
"""

from __future__ import annotations

import os

import numpy as np
import pytest

if os.environ.get("BIONAV_GPU_DEVICE_TESTS") != "1":  # scripts/gpu-bench.sh runs them on the GPU itself
    os.environ["NUMBA_ENABLE_CUDASIM"] = "1"  # before numba.cuda is imported (numba's config is read again)
from numba.core import config as _numba_config  # noqa: E402

_numba_config.reload_config()
pytest.importorskip("numba.cuda", reason="the GPU backend's extra: pip install 'bionav[gpu]'")

from bionav.geometry import PanoramaGeometry  # noqa: E402
from bionav.plugins.homing.warping import MinWarping, Warping2D  # noqa: E402

W, H = 16, 8
SCALES = [0.5, 1.0, 2.0]
THRESHOLDS = [0.75, 1.5, 2.5]


def _images(n=3, seed=0):
    rng = np.random.default_rng(seed)
    base = rng.random((H, W + 6)).astype(np.float32)
    base = np.cumsum(base, axis=1)[:, 6:] - np.cumsum(base, axis=1)[:, :-6]  # smooth along the rows
    return [np.roll(base, 3 * k, axis=1) * (1.0 - 0.1 * k) + 0.05 * k * rng.random((H, W)).astype(np.float32)
            for k in range(n)]


def _method(cls, **options):
    cfg = cls.Config(image_size=[W, H], n_alpha=options.pop("n_alpha", 8), n_psi=options.pop("n_psi", 8),
                     scales=SCALES, thresholds=THRESHOLDS, **options)
    return cls(cfg, geometry=PanoramaGeometry.square_pixels(W, H))


PAIRS = (np.array([0, 1, 2]), np.array([1, 2, 0]))


def _assert_cpu_hypotheses(method, preps, best_a, best_p, *, abs_tol):
    """The GPU's (alpha, psi) columns give the CPU plugin's home angle and compass for every pair of PAIRS."""
    from bionav.homing.warping.search import _result

    for k, (s, c) in enumerate(zip(*PAIRS)):
        cpu = method.home_vector(preps[s], preps[c])
        gpu = _result(int(best_a[k]), int(best_p[k]), np.nan, 0.0, W)
        assert gpu.home_angle == pytest.approx(cpu.angle, abs=abs_tol)
        assert gpu.psi == pytest.approx(cpu.compass, abs=abs_tol)


@pytest.mark.parametrize("options", [{}, {"compass_acceleration": True, "compass_fraction": 0.5},
                                     {"double_search": True, "fine_search": True, "n_alpha": 4, "n_psi": 4}])
def test_gpu_minwarping_chooses_the_cpu_hypothesis(options):
    from bionav.gpu.minwarp import MinWarpGPU

    m = _method(MinWarping, **options)
    preps = [m.prepare(img) for img in _images()]
    ps, pc = PAIRS
    _assert_cpu_hypotheses(m, preps, *MinWarpGPU(m, preps, preps).best(ps, pc), abs_tol=0.0)


def test_gpu_table_and_search_equal_the_cpu_kernels():
    """The window table within one quantum of the CPU's (the division), the search on it bit for bit."""
    from bionav.gpu.minwarp import MinWarpGPU
    from bionav.homing.warping import search as S
    from bionav.homing.warping.kernels import minwarp_scores

    m = _method(MinWarping, n_alpha=4, n_psi=4)
    preps = [m.prepare(img) for img in _images()]
    gpu = MinWarpGPU(m, preps, preps)
    lev = gpu._tables(np.array([0, 2]), np.array([1, 0]))
    tables = lev.copy_to_host()
    windows = tuple(w.copy_to_host() for w in gpu.windows)
    for b, (s, c) in enumerate(((0, 1), (2, 0))):
        cpu = S._window_minima(preps[s], preps[c], gpu.step, windows, True).copy()
        diff = np.abs(cpu.astype(int) - tables[b].astype(int))
        assert diff.max() <= 1 and np.mean(diff == 0) > 0.99
    p_sel = np.tile(gpu.p_all, (2, 1))
    got = gpu._search(lev, p_sel)
    for b in range(2):
        want = np.zeros((gpu.p_all.size, gpu.n), np.uint16)
        minwarp_scores(np.ascontiguousarray(tables[b]), gpu.n, gpu.p_all, *windows, np.uint8(255), want)
        np.testing.assert_array_equal(got[b], want)


def test_gpu_warping2d_chooses_the_cpu_hypothesis():
    from bionav.gpu.warp2d import Warp2dGPU

    m = _method(Warping2D, n_rho=3)
    preps = [m.prepare(img) for img in _images()]
    ps, pc = PAIRS
    _assert_cpu_hypotheses(m, preps, *Warp2dGPU(m, preps, preps).best(ps, pc), abs_tol=1e-12)


def test_gpu_sift_matches_equal_the_cpu_all_pairs_path():
    from bionav.gpu.sift import sift_pairs
    from bionav.homing.features import SiftFeatures
    from bionav.homing.sift_homing import sift_home_angles_all_pairs
    from bionav.plugins.homing.sift import SiftConfig, SiftHoming

    width, height = 64, 16
    method = SiftHoming(SiftConfig(), geometry=PanoramaGeometry.square_pixels(width, height))
    rng = np.random.default_rng(3)
    feats = []
    for k in range(3):
        n = 12 + 3 * k
        xy = np.column_stack([rng.random(n) * width, rng.random(n) * height]).astype(np.float32)
        d = rng.integers(0, 6, (n, 128)).astype(np.float32)  # few values: ties in the distance occur
        feats.append(SiftFeatures(xy, d, (d * d).sum(axis=1), width=np.asarray(width)))
    cpu, _ = sift_home_angles_all_pairs(feats, geometry=method.work_geometry,
                                        search_radius=method.config.search_radius * width)
    ps, pc = np.array([0, 0, 1, 1, 2, 2]), np.array([1, 2, 0, 2, 0, 1])
    got = sift_pairs(method, feats, feats, ps, pc)
    np.testing.assert_array_equal(got, cpu[ps, pc])
