"""Fast warping kernels against the plain reference implementations, pair by pair."""

import numpy as np
import pytest

from bionav.geometry import PanoramaGeometry
from bionav.homing.warping import (
    minwarping,
    minwarping_scores,
    scale_plane_stack,
    warping1d_scores,
    warping2d_scores,
)
from bionav.homing.warping.distance import column_distance_matrix, diagonal_distances
from bionav.homing.warping.kernels import fill_window_minima
from bionav.homing.warping.reference import (
    minwarping_scores_reference,
    warping1d_scores_reference,
    warping2d_scores_reference,
)
from bionav.homing.warping.scaleplanes import default_scales, default_thresholds
from bionav.homing.warping.templates import minwarp_template, minwarp_windows

W, H = 24, 8
SCALES = np.array([0.5, 0.75, 1.0, 1.4, 2.0])
THRESHOLD_SETS = [None, np.array([0.6, 0.9, 1.2, 1.7, 2.5])]  # open last plane / finite last threshold


def _pair(seed):
    rng = np.random.default_rng(seed)
    geometry = PanoramaGeometry.square_pixels(W, H)
    a = rng.random((H, W)).astype(np.float32)
    b = rng.random((H, W)).astype(np.float32)
    return (
        scale_plane_stack(a, geometry=geometry, scales=SCALES),
        scale_plane_stack(b, geometry=geometry, scales=SCALES),
    )


def test_diagonal_distances_match_reference_matrix():
    snap, cur = _pair(0)
    ref = column_distance_matrix(snap, cur)
    for step in (1, 2, 3):
        fast = diagonal_distances(snap, cur, step=step)
        n = W // step
        for i in range(W):
            for d in range(W):
                want = ref[:, i, (i + d) % W]
                np.testing.assert_allclose(fast[:, d, i % step, i // step], want, rtol=1e-5, atol=1e-6)
                np.testing.assert_allclose(fast[:, d, i % step, i // step + n], want, rtol=1e-5, atol=1e-6)


def test_nsad_of_identical_and_zero_columns():
    snap, _ = _pair(1)
    d = column_distance_matrix(snap, {"cur": snap["snap"]})
    assert np.allclose(np.diagonal(d, axis1=1, axis2=2), 0.0)
    zero = {"snap": np.zeros((1, 3, 4)), "cur": np.zeros((1, 3, 4))}
    assert np.all(column_distance_matrix(zero, zero) == 0.0)


def test_window_minima_match_brute_force():
    rng = np.random.default_rng(11)
    n_levels, k, w, step, m2 = 4, 2, 10, 2, 10
    levels = np.zeros((n_levels, k, w, step, m2), np.float32)
    levels[0] = rng.random((k, w, step, m2), dtype=np.float32)
    fill_window_minima(levels)
    for j in range(n_levels):
        for d in range(w):
            window = [(d + t) % w for t in range(2**j)]
            np.testing.assert_array_equal(levels[j, :, d], levels[0][:, window].min(axis=1))


@pytest.mark.parametrize("max_level", [0, 1, 2, 4])
@pytest.mark.parametrize("width", [24, 288])
def test_minwarp_windows_cover_exactly_the_allowed_columns(max_level, width):
    scales = default_scales() if width == 288 else SCALES
    tmpl = minwarp_template(width, scales, default_thresholds(scales))
    vlo, vhi, klo, khi = tmpl
    start, plane, level, first = minwarp_windows(tmpl, max_level=max_level)
    assert level.max() <= max_level
    for u in range(width):
        covered = {}
        for e in range(start[u], start[u + 1]):
            covered.setdefault(int(plane[e]), set()).update(range(first[e], first[e] + 2 ** int(level[e])))
        allowed = {}
        for v in range(vlo[u], vhi[u] + 1):
            for k in range(klo[u, v], khi[u, v] + 1):
                allowed.setdefault(k, set()).add(v)
        assert covered == allowed, f"u={u}"


@pytest.mark.parametrize("thresholds", THRESHOLD_SETS)
@pytest.mark.parametrize("n_alpha", [12, 8, 24, 7])
@pytest.mark.parametrize("window_level", [0, 1, 4])
def test_minwarping_scores_fast_equals_reference(thresholds, n_alpha, window_level):
    snap, cur = _pair(n_alpha)
    a_cols, p_cols, fast = minwarping_scores(
        snap, cur, n_alpha=n_alpha, n_psi=6, thresholds=thresholds, window_level=window_level
    )
    tau = default_thresholds(SCALES) if thresholds is None else thresholds
    ref = minwarping_scores_reference(snap, cur, a_cols=a_cols, p_cols=p_cols, thresholds=tau)
    np.testing.assert_allclose(fast, ref, rtol=1e-5, atol=1e-5)


@pytest.mark.parametrize("thresholds", THRESHOLD_SETS)
@pytest.mark.parametrize("n_alpha", [12, 7])
def test_warping2d_scores_fast_equals_reference(thresholds, n_alpha):
    snap, cur = _pair(100 + n_alpha)
    a_cols, p_cols, rhos, fast = warping2d_scores(
        snap, cur, n_alpha=n_alpha, n_psi=8, n_rho=5, rho_max=0.9, thresholds=thresholds
    )
    tau = default_thresholds(SCALES) if thresholds is None else thresholds
    ref = warping2d_scores_reference(snap, cur, a_cols=a_cols, p_cols=p_cols, rhos=rhos, thresholds=tau)
    np.testing.assert_allclose(fast, ref, rtol=1e-5, atol=1e-5)


def test_warping1d_scores_fast_equals_reference():
    rng = np.random.default_rng(3)
    s, c = rng.random(30), rng.random(30)
    alphas, psis, rhos = np.linspace(0, 6, 7), np.linspace(-3, 3, 5), np.linspace(0, 0.9, 4)
    fast = warping1d_scores(s, c, alphas=alphas, psis=psis, rhos=rhos)
    ref = warping1d_scores_reference(s, c, alphas=alphas, psis=psis, rhos=rhos)
    np.testing.assert_allclose(fast, ref, rtol=1e-10, atol=1e-10)


def test_minwarping_picks_the_reference_minimum():
    snap, cur = _pair(7)
    result = minwarping(snap, cur, n_alpha=12, n_psi=12)
    a_cols, p_cols, _ = minwarping_scores(snap, cur, n_alpha=12, n_psi=12)
    ref = minwarping_scores_reference(
        snap, cur, a_cols=a_cols, p_cols=p_cols, thresholds=default_thresholds(SCALES)
    )
    ip, ia = np.unravel_index(np.argmin(ref), ref.shape)
    assert result.score == pytest.approx(ref[ip, ia], rel=1e-5)
    assert result.alpha == pytest.approx(2 * np.pi * a_cols[ia] / W)
    assert np.isclose(np.exp(1j * result.psi), np.exp(2j * np.pi * p_cols[ip] / W))


def test_compass_acceleration_searches_a_subset_of_the_same_scores():
    snap, cur = _pair(8)
    full = minwarping(snap, cur, n_alpha=12, n_psi=12)
    part = minwarping(snap, cur, n_alpha=12, n_psi=12, compass_fraction=0.25)
    assert part.extras["n_psi_searched"] == 3
    assert part.score >= full.score - 1e-6
    fine = minwarping(snap, cur, n_alpha=12, n_psi=12, fine_search=True)
    assert fine.score <= full.score + 1e-6


def test_double_search_adds_the_swapped_search():
    snap, cur = _pair(9)
    a_cols, p_cols, s1 = minwarping_scores(snap, cur, n_alpha=12, n_psi=12)
    _, _, s2 = minwarping_scores(cur, snap, n_alpha=12, n_psi=12)
    col = {int(c): i for i, c in enumerate(a_cols)}
    total = np.empty_like(s1)
    for ip, pc in enumerate(p_cols):
        for ia, ac in enumerate(a_cols):
            ip2 = int(np.flatnonzero(p_cols == (-pc) % W)[0])
            total[ip, ia] = s1[ip, ia] + s2[ip2, col[int((ac + W // 2 - pc) % W)]]
    result = minwarping(snap, cur, n_alpha=12, n_psi=12, double_search=True)
    assert result.score == pytest.approx(total.min(), rel=1e-5)
