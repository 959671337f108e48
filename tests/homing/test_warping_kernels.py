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
from bionav.homing.warping.distance import column_distance_matrix, diagonal_distances, distance_quantum
from bionav.homing.warping.kernels import fill_window_minima, swap_roles
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
        assert fast.shape == (len(SCALES), W, step, W // step)  # every distance once
        for i in range(W):
            for d in range(W):
                want = ref[:, i, (i + d) % W]
                np.testing.assert_allclose(fast[:, d, i % step, i // step], want, rtol=1e-5, atol=1e-6)


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
    result = minwarping(snap, cur, n_alpha=12, n_psi=12, quantised=False)
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


@pytest.mark.parametrize("scales", [SCALES, default_scales(5)])  # asymmetric: recomputed; symmetric: transposed
@pytest.mark.parametrize("quantised", [False, True])
def test_double_search_adds_the_swapped_search(scales, quantised):
    rng = np.random.default_rng(9)
    geometry = PanoramaGeometry.square_pixels(W, H)
    snap, cur = (scale_plane_stack(rng.random((H, W)).astype(np.float32), geometry=geometry, scales=scales)
                 for _ in range(2))
    a_cols, p_cols, s1 = minwarping_scores(snap, cur, n_alpha=12, n_psi=12, quantised=quantised)
    _, _, s2 = minwarping_scores(cur, snap, n_alpha=12, n_psi=12, quantised=quantised)
    col = {int(c): i for i, c in enumerate(a_cols)}
    total = np.empty_like(s1)
    for ip, pc in enumerate(p_cols):
        for ia, ac in enumerate(a_cols):
            ip2 = int(np.flatnonzero(p_cols == (-pc) % W)[0])
            total[ip, ia] = s1[ip, ia] + s2[ip2, col[int((ac + W // 2 - pc) % W)]]
    result = minwarping(snap, cur, n_alpha=12, n_psi=12, double_search=True, quantised=quantised)
    assert result.score == pytest.approx(total.min(), rel=1e-6)


def test_swap_roles_is_the_distance_stack_of_the_swapped_pair():
    rng = np.random.default_rng(5)
    geometry = PanoramaGeometry.square_pixels(W, H)
    scales = default_scales(5)
    a, b = (scale_plane_stack(rng.random((H, W)).astype(np.float32), geometry=geometry, scales=scales)
            for _ in range(2))
    for quantised in (False, True):
        for step in (1, 3):
            forward = diagonal_distances(a, b, step=step, quantised=quantised)
            swapped = np.empty_like(forward)
            swap_roles(forward, swapped)
            direct = diagonal_distances(b, a, step=step, quantised=quantised)
            if quantised:  # the same integers either way
                np.testing.assert_array_equal(swapped, direct)
            else:
                np.testing.assert_allclose(swapped, direct, rtol=1e-5, atol=1e-6)


@pytest.mark.parametrize("step", [1, 2, 3])
def test_quantised_distances_are_rounded_nsad(step):
    snap, cur = _pair(21)
    ref = column_distance_matrix(snap, cur)
    q, _ = distance_quantum(W)
    fast = diagonal_distances(snap, cur, step=step, quantised=True)
    assert fast.dtype == np.uint8 and fast.shape == (len(SCALES), W, step, W // step)
    for i in range(W):
        for d in range(W):
            want = ref[:, i, (i + d) % W] * q
            got = fast[:, d, i % step, i // step].astype(np.float64)
            # rounding (0.5) plus the 16-bit quantisation of the edge images
            assert np.abs(got - want).max() <= 0.5 + 0.02 * q, (i, d)


def test_distance_quantum_keeps_sums_in_16_bits():
    for width in (24, 288, 346, 1000):
        q, dtype = distance_quantum(width)
        assert dtype == np.uint16 and width * q <= 65535 and (q == 255 or width * (q + 1) > 65535)
    assert distance_quantum(4000) == (255, np.dtype(np.uint32))


@pytest.mark.parametrize("thresholds", THRESHOLD_SETS)
def test_quantised_scores_are_close_to_the_reference(thresholds):
    snap, cur = _pair(31)
    a_cols, p_cols, fast = minwarping_scores(snap, cur, n_alpha=12, n_psi=6, thresholds=thresholds,
                                             quantised=True)
    tau = default_thresholds(SCALES) if thresholds is None else thresholds
    ref = minwarping_scores_reference(snap, cur, a_cols=a_cols, p_cols=p_cols, thresholds=tau)
    q, _ = distance_quantum(W)
    # every column's minimum is off by at most the error of one distance
    assert np.abs(fast - ref).max() <= W * (0.5 + 0.02 * q) / q
    assert np.abs(fast - ref).max() > 0  # quantised: not the float values


def _circ_steps(x, y, width, n_steps):
    return abs((x - y + width / 2) % width - width / 2) * n_steps / width


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("options", [{}, {"double_search": True, "fine_search": True},
                                     {"compass_fraction": 0.3}])
def test_quantised_search_agrees_with_float_on_random_panoramas(seed, options):
    # a random panorama seen again rotated and with noise: the rotation is
    # determined, the movement direction is not (no translation), so the
    # quantised search must find the rotation and a hypothesis whose float
    # match value is as good as the float optimum up to the quantisation error
    rng = np.random.default_rng(seed)
    w, h = 96, 20
    geometry = PanoramaGeometry.square_pixels(w, h)
    scales = default_scales(9)
    base = rng.random((h, w)).astype(np.float32)
    other = np.roll(base, -int(rng.integers(w)), axis=1) + 0.2 * rng.random((h, w)).astype(np.float32)
    snap = scale_plane_stack(base, geometry=geometry, scales=scales)
    cur = scale_plane_stack(other, geometry=geometry, scales=scales)
    f = minwarping(snap, cur, n_alpha=32, n_psi=32, quantised=False, **options)
    q = minwarping(snap, cur, n_alpha=32, n_psi=32, quantised=True, **options)
    assert _circ_steps(q.psi * w / (2 * np.pi), f.psi * w / (2 * np.pi), w, 32) <= 1.0
    a_cols, p_cols, table = minwarping_scores(snap, cur, n_alpha=32, n_psi=32, quantised=False)
    if not options:
        ia = int(np.flatnonzero(a_cols == round(q.alpha * w / (2 * np.pi)) % w)[0])
        ip = int(np.flatnonzero(p_cols == round(q.psi * w / (2 * np.pi)) % w)[0])
        quantum, _ = distance_quantum(w)
        assert table[ip, ia] <= table.min() + 2 * w * (0.5 + 0.02 * quantum) / quantum


@pytest.mark.parametrize("step", [1, 3])
def test_single_hypothesis_scores_equal_the_reference(step):
    # the fine search's kernel: any (alpha, psi) in columns, also off the alpha grid
    from bionav.homing.warping.kernels import minwarp_scores_at
    from bionav.homing.warping.search import _window_minima

    snap, cur = _pair(41)
    tau = default_thresholds(SCALES)
    windows = minwarp_windows(minwarp_template(W, SCALES, tau))
    levels = _window_minima(snap, cur, step, windows, False).copy()
    rng = np.random.default_rng(2)
    a_cols, p_cols = rng.integers(0, W, 12), rng.integers(0, W, 12)
    fast = minwarp_scores_at(levels, a_cols, p_cols, *windows)
    for t in range(12):
        ref = minwarping_scores_reference(snap, cur, a_cols=[a_cols[t]], p_cols=[p_cols[t]], thresholds=tau)
        assert fast[t] == pytest.approx(ref[0, 0], rel=1e-5)


# the code generation of these kernels (packed instructions, no masked stores, for AVX2 and AVX-512
# targets whatever the host) is checked in test_kernel_codegen.py


@pytest.mark.parametrize("step", [1, 3])
@pytest.mark.parametrize("quantised", [False, True])
def test_runs_of_directions_equal_single_hypotheses(step, quantised):
    # the fine search's block kernel: runs of consecutive directions (any start,
    # wrapping past column W - 1) per rotation, against the reference loops
    from bionav.homing.warping.kernels import minwarp_scores_at, minwarp_scores_runs
    from bionav.homing.warping.search import _window_minima

    snap, cur = _pair(43)
    tau = default_thresholds(SCALES)
    windows = minwarp_windows(minwarp_template(W, SCALES, tau), max_level=2)
    levels = _window_minima(snap, cur, step, windows, quantised).copy()
    a_first = np.array([0, W - 2, 5, 17], np.int64)
    p_cols = np.array([3, 0, W - 1, 40], np.int64)  # 40: taken modulo W
    runs = minwarp_scores_runs(levels, a_first, 5, p_cols, *windows)
    assert runs.shape == (4, 5)
    a_all = ((a_first[:, None] + np.arange(5)) % W).ravel()
    p_all = np.repeat(p_cols, 5)
    np.testing.assert_array_equal(runs.ravel(), minwarp_scores_at(levels, a_all, p_all, *windows))
    if not quantised:
        for t in (0, 7, 19):
            ref = minwarping_scores_reference(snap, cur, a_cols=[a_all[t]], p_cols=[p_all[t] % W], thresholds=tau)
            assert runs.ravel()[t] == pytest.approx(ref[0, 0], rel=1e-5)


@pytest.mark.parametrize("step", [1, 2, 3])
def test_compass_measure_is_the_best_plane_distance_along_each_rotation(step):
    from bionav.homing.warping.kernels import compass_measure

    snap, cur = _pair(44)
    p_cols = np.array([0, 1, 5, W - 1], np.int64)
    ref_d = column_distance_matrix(snap, cur)  # (K, i, j)
    want = [sum(ref_d[:, i, (i - p) % W].min() for i in range(W)) for p in p_cols]
    got = compass_measure(diagonal_distances(snap, cur, step=step), p_cols)
    np.testing.assert_allclose(got, want, rtol=1e-5)
    q, _ = distance_quantum(W)
    dq = diagonal_distances(snap, cur, step=step, quantised=True)
    want_q = [sum(int(min(dq[k, (-p) % W, i % step, i // step] for k in range(len(SCALES)))) for i in range(W))
              for p in p_cols]
    np.testing.assert_array_equal(compass_measure(dq, p_cols), want_q)
    assert np.abs(compass_measure(dq, p_cols) / q - want).max() <= W * (0.5 + 0.02 * q) / q


@pytest.mark.parametrize("width, step", [(25, 1), (25, 5), (21, 3)])
def test_quantised_distances_of_odd_widths(width, step):
    # two diagonals per pass: an odd width ends with a half pair
    rng = np.random.default_rng(width)
    geometry = PanoramaGeometry.square_pixels(width, H)
    snap, cur = (scale_plane_stack(rng.random((H, width)).astype(np.float32), geometry=geometry, scales=SCALES)
                 for _ in range(2))
    ref = column_distance_matrix(snap, cur)
    q, _ = distance_quantum(width)
    fast = diagonal_distances(snap, cur, step=step, quantised=True)
    for i in range(width):
        for d in range(width):
            got = fast[:, d, i % step, i // step].astype(np.float64)
            assert np.abs(got - ref[:, i, (i + d) % width] * q).max() <= 0.5 + 0.02 * q, (i, d)


@pytest.mark.parametrize("thresholds", THRESHOLD_SETS)
@pytest.mark.parametrize("step", [1, 3])
@pytest.mark.parametrize("quantised", [True, False])
def test_match_values_are_sums_of_template_minima(thresholds, step, quantised):
    # minwarp_scores (sliding minima, windows, two buffers of running minima)
    # against plain loops over the template on the distances: exact for 8-bit
    # distances (integer sums), float32 sums in another order otherwise
    from bionav.homing.warping.kernels import minwarp_scores
    from bionav.homing.warping.search import _window_minima

    snap, cur = _pair(51)
    tau = default_thresholds(SCALES) if thresholds is None else thresholds
    tmpl = minwarp_template(W, SCALES, tau)
    windows = minwarp_windows(tmpl, max_level=2)
    levels = _window_minima(snap, cur, step, windows, quantised).copy()
    n = W // step
    p_cols = np.array([0, 1, 5, W - 1, 7], np.int64)  # an odd count: rotations are taken two at a time
    big = np.uint8(255) if quantised else np.float32(np.inf)
    out = np.zeros((5, n), np.uint16 if quantised else np.float32)
    minwarp_scores(levels, n, p_cols, *windows, big, out)
    vlo, vhi, klo, khi = tmpl
    dist = levels[0]
    want = np.zeros((5, n))
    for ip, p in enumerate(p_cols):
        for a in range(n):
            for u in range(W):
                i = (u + a * step) % W
                vals = [dist[k, (v - u - p) % W, i % step, i // step]
                        for v in range(vlo[u], vhi[u] + 1) for k in range(klo[u, v], khi[u, v] + 1)]
                want[ip, a] += float(min(vals)) if vals else float(big)
    if quantised:
        np.testing.assert_array_equal(out, want)
    else:
        np.testing.assert_allclose(out, want, rtol=1e-6)
