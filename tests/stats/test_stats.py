"""Tests of bionav.stats against closed forms and constructed cases."""

import numpy as np
import pytest
from scipy import stats as sps

from bionav.stats import (
    bootstrap_interval,
    bootstrap_lda,
    fisher_criterion,
    fisher_lda,
    jackknife,
    min_error_threshold,
    min_errors,
    otsu_threshold,
    paired_bootstrap_difference,
    pairwise_significance,
    stars,
)


def _exact_moments(rng, n, mean, cov):
    """n samples whose sample mean and 1/n covariance are exactly ``mean`` and ``cov``."""
    z = rng.standard_normal((n, len(mean)))
    z -= z.mean(axis=0)
    c = z.T @ z / n
    z = z @ np.linalg.inv(np.linalg.cholesky(c)).T  # now exact identity covariance
    return z @ np.linalg.cholesky(cov).T + mean


def test_lda_recovers_known_direction_and_criterion():
    rng = np.random.default_rng(1)
    cov1 = np.array([[4.0, 1.0], [1.0, 2.0]])
    cov0 = np.array([[1.0, -0.3], [-0.3, 3.0]])
    m1, m0 = np.array([3.0, 1.0]), np.array([0.0, 2.0])
    x = np.vstack([_exact_moments(rng, 400, m1, cov1), _exact_moments(rng, 300, m0, cov0)])
    labels = np.r_[np.ones(400, bool), np.zeros(300, bool)]
    sw = cov1 + cov0
    w_true = np.linalg.solve(sw, m1 - m0)
    j_true = (m1 - m0) @ w_true
    lda = fisher_lda(x, labels)
    assert lda.criterion == pytest.approx(j_true, rel=1e-10)
    np.testing.assert_allclose(lda.direction, w_true / np.linalg.norm(w_true), atol=1e-10)
    # the criterion of the returned direction is the maximum: any other direction is worse
    angles = np.linspace(0, np.pi, 181)
    ws = np.c_[np.cos(angles), np.sin(angles)]
    assert fisher_criterion(ws, x, labels).max() <= j_true + 1e-9
    assert fisher_criterion(lda.direction, x, labels) == pytest.approx(j_true)
    # class 1 projects higher
    assert lda.project(m1[None])[0] > lda.project(m0[None])[0]


def test_lda_population_gaussian_case():
    """Large two-class Gaussian sample: direction and J approach the population optimum."""
    rng = np.random.default_rng(2)
    cov = np.array([[1.0, 0.8], [0.8, 1.0]])
    m1, m0 = np.array([1.0, 0.0]), np.array([0.0, 0.0])
    n = 40000
    x = np.vstack([rng.multivariate_normal(m1, cov, n), rng.multivariate_normal(m0, cov, n)])
    labels = np.r_[np.ones(n, bool), np.zeros(n, bool)]
    w_true = np.linalg.solve(2 * cov, m1 - m0)
    j_true = (m1 - m0) @ w_true  # = 1/(2*0.36) = 1.3889
    lda = fisher_lda(x, labels)
    assert lda.criterion == pytest.approx(j_true, rel=0.03)
    assert abs(np.dot(lda.direction, w_true / np.linalg.norm(w_true))) > 0.999
    # Bayes error of equal-covariance Gaussians: Phi(-Delta/2), Delta^2 = 2 J
    bayes = sps.norm.cdf(-np.sqrt(2 * j_true) / 2)
    assert lda.error_fraction == pytest.approx(bayes, abs=0.01)


def test_j_sigma_closed_form_and_limit():
    rng = np.random.default_rng(3)
    x = np.r_[rng.normal(100, 20, 50), rng.normal(0, 30, 60)]
    labels = np.r_[np.ones(50, bool), np.zeros(60, bool)]
    x1, x0 = x[:50], x[50:]
    dm2 = (x1.mean() - x0.mean()) ** 2
    for sigma in (0.0, 5.0, 30.0):
        expected = dm2 / (x1.var() + x0.var() + 2 * sigma**2)
        assert fisher_lda(x, labels, sigma=sigma).criterion == pytest.approx(expected)
    x2 = np.c_[x, 0.5 * x + rng.normal(0, 1, x.size)]  # nearly collinear 2-D features
    j = fisher_lda(x2, labels).criterion
    sigmas = [30.0, 3.0, 0.3, 0.03, 0.003, 0.0]
    js = [fisher_lda(x2, labels, sigma=s).criterion for s in sigmas]
    assert all(a < b for a, b in zip(js[:-1], js[1:]))
    assert js[-2] == pytest.approx(j, rel=1e-4)
    assert js[-1] == j


def test_threshold_constructed_case():
    y = np.array([0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0])
    lab = np.array([0, 0, 1, 0, 1, 1, 1], bool)
    thr = min_error_threshold(y, lab)
    # 1 error is the optimum (between 1|2 or 3|4); the tie-break picks the one
    # closer to the class-mean midpoint (1.333 + 4.25)/2 = 2.79 -> 3.5
    assert thr.n_errors == 1
    assert thr.threshold == pytest.approx(3.5)
    assert thr.error_fraction == pytest.approx(1 / 7)
    # perfectly separable
    thr = min_error_threshold([5, 6, 1, 2], [1, 1, 0, 0])
    assert thr.n_errors == 0 and 2 < thr.threshold < 5
    # ties are never split: equal values with different labels cost one error
    thr = min_error_threshold([1.0, 1.0, 2.0], [0, 1, 1])
    assert thr.n_errors == 1


def _brute_force_errors(y, lab):
    cands = np.r_[y.min() - 1, np.unique(y)]
    return min(np.count_nonzero(lab & (y <= t)) + np.count_nonzero(~lab & (y > t)) for t in cands)


def test_threshold_minimises_errors_vs_brute_force():
    rng = np.random.default_rng(4)
    ys = rng.integers(0, 8, size=(50, 30)).astype(float)  # many ties
    labs = rng.random((50, 30)) < 0.5 + 0.05 * (ys - 4)
    batched = min_errors(ys, labs)
    for y, lab, b in zip(ys, labs, batched):
        ref = _brute_force_errors(y, lab)
        assert b == ref
        thr = min_error_threshold(y, lab)
        assert thr.n_errors == ref
        pred = y > thr.threshold
        assert np.count_nonzero(pred != lab) == ref



def _brute_force_otsu(y):
    """Between-class variance of every split between distinct values, by definition (a plain loop)."""
    best, best_t = -1.0, None
    values = np.unique(y)
    for lo, hi in zip(values[:-1], values[1:]):
        t = 0.5 * (lo + hi)
        a, b = y[y <= t], y[y > t]
        between = len(a) / len(y) * len(b) / len(y) * (a.mean() - b.mean()) ** 2
        if between > best + 1e-12:
            best, best_t = between, t
    return best_t


def test_otsu_threshold_matches_the_definition_and_splits_two_groups():
    rng = np.random.default_rng(7)
    for _ in range(40):
        y = rng.integers(0, 12, size=int(rng.integers(2, 60))).astype(float)  # many ties
        if np.ptp(y) == 0:
            continue
        assert otsu_threshold(y) == pytest.approx(_brute_force_otsu(y))
    # two well separated groups of unequal size: the border lies in the gap, exactly midway between the edges
    y = np.r_[rng.normal(0.0, 1.0, 300).clip(-3, 3), rng.normal(20.0, 1.0, 40).clip(17, 23)]
    t = otsu_threshold(y)
    assert y[y < 10].max() < t < y[y > 10].min()
    assert t == pytest.approx(0.5 * (y[y < 10].max() + y[y > 10].min()))
    # equivariant under a positive affine map, whatever the array shape
    assert otsu_threshold(3.0 * y.reshape(20, 17) - 5.0) == pytest.approx(3.0 * t - 5.0)
    for bad in ([1.0], [2.0, 2.0, 2.0], [0.0, np.nan, 1.0], [0.0, np.inf]):
        with pytest.raises(ValueError):
            otsu_threshold(bad)

def test_jackknife_of_mean_is_standard_error():
    rng = np.random.default_rng(5)
    x = rng.normal(3, 2, 37)
    res = jackknife(x, np.mean)
    assert res.estimate == pytest.approx(x.mean())
    np.testing.assert_allclose(res.pseudo_values, x)  # pseudo-values of the mean are the data
    assert res.standard_error == pytest.approx(x.std(ddof=1) / np.sqrt(x.size))
    # paired rows: difference of means
    pairs = np.c_[x, x - 1.0]
    res = jackknife(pairs, lambda p: p[:, 0].mean() - p[:, 1].mean())
    assert res.estimate == pytest.approx(1.0) and res.standard_error == pytest.approx(0.0, abs=1e-12)


def test_bootstrap_interval_matches_t_interval():
    rng = np.random.default_rng(6)
    x = rng.normal(10.0, 3.0, 400)
    t_lo, t_hi = sps.t.interval(0.95, x.size - 1, loc=x.mean(), scale=sps.sem(x))
    iv = bootstrap_interval(x, confidence_level=0.95, n_resamples=4000, rng=np.random.default_rng(7))
    width = t_hi - t_lo
    assert iv.low == pytest.approx(t_lo, abs=0.08 * width)
    assert iv.high == pytest.approx(t_hi, abs=0.08 * width)
    assert iv.standard_error == pytest.approx(sps.sem(x), rel=0.08)


def test_paired_bootstrap_matches_scipy_bca_and_t_interval():
    rng = np.random.default_rng(8)
    b = rng.normal(1.0, 0.5, 60)
    a = b + 0.3 + rng.normal(0, 0.2, 60)  # true mean difference 0.3
    res = paired_bootstrap_difference(a, b, n_resamples=2000, rng=np.random.default_rng(9))
    assert res.estimate == pytest.approx(np.mean(a - b))
    ref = sps.bootstrap((a, b), lambda x, y, axis=-1: x.mean(axis) - y.mean(axis), paired=True,
                        method="BCa", n_resamples=2000, rng=np.random.default_rng(9))
    lo, hi = res.ci(0.95)
    assert lo == pytest.approx(ref.confidence_interval.low, rel=1e-10)
    assert hi == pytest.approx(ref.confidence_interval.high, rel=1e-10)
    # the mean of paired differences: BCa ~ t-interval
    d = a - b
    t_lo, t_hi = sps.t.interval(0.95, d.size - 1, loc=d.mean(), scale=sps.sem(d))
    assert lo == pytest.approx(t_lo, abs=0.1 * (t_hi - t_lo))
    assert hi == pytest.approx(t_hi, abs=0.1 * (t_hi - t_lo))
    assert res.significance == {0.05: True, 0.01: True, 0.001: True}
    assert res.stars == "***" and res.p_value < 0.001


def test_paired_bootstrap_p_value_agrees_with_intervals():
    rng = np.random.default_rng(10)
    for shift in (0.0, 0.05, 0.1, 0.15, 0.2):
        b = rng.normal(0, 0.3, 40)
        a = b + shift + rng.normal(0, 0.3, 40)
        res = paired_bootstrap_difference(a, b, n_resamples=2000, rng=rng)
        for alpha in (0.05, 0.01):
            if abs(res.p_value - alpha) > 0.005:  # away from the boundary they must agree
                assert res.significant(alpha) == (res.p_value < alpha)
        assert res.ci(0.99)[0] <= res.ci(0.95)[0] <= res.estimate <= res.ci(0.95)[1] <= res.ci(0.99)[1]


def test_paired_bootstrap_identical_methods_is_degenerate_not_significant():
    a = np.linspace(0, 1, 10)
    res = paired_bootstrap_difference(a, a.copy(), rng=np.random.default_rng(0))
    assert res.estimate == 0 and res.ci(0.95) == (0.0, 0.0)
    assert not any(res.significance.values()) and res.p_value == 1.0 and res.stars == ""


def test_paired_bootstrap_median_and_errors():
    rng = np.random.default_rng(11)
    a, b = rng.normal(1, 1, 30), rng.normal(0, 1, 30)
    res = paired_bootstrap_difference(a, b, statistic=np.median, n_resamples=500, rng=rng)
    assert res.estimate == pytest.approx(np.median(a) - np.median(b))
    with pytest.raises(ValueError):
        paired_bootstrap_difference(a, b[:-1], rng=rng)
    with pytest.raises(ValueError):
        paired_bootstrap_difference(np.r_[a[:-1], np.nan], b, rng=rng)


def test_stars():
    assert [stars(p) for p in (0.0005, 0.001, 0.005, 0.03, 0.2, None)] == ["***", "***", "**", "*", "", ""]


def test_pairwise_significance_constructed():
    rng = np.random.default_rng(12)
    base = rng.normal(0, 1, 5000)
    dist = np.c_[base, base + 10.0, base + rng.normal(0, 1, 5000), base + 0.05 + rng.normal(0, 0.02, 5000)]
    sig = pairwise_significance(dist)
    assert sig[0, 1] == 0.001 and sig[1, 0] == 0.001
    assert np.isnan(sig[0, 2])
    assert sig[0, 3] == 0.05  # mean 0.05, sd 0.02: 2.5 sd -> 5 % but not 1 %
    assert np.all(np.isnan(np.diag(sig)))


def test_bootstrap_lda_equals_direct_lda_on_the_same_resample():
    rng = np.random.default_rng(13)
    x = np.r_[rng.normal([2, 0, 1], [1, 2, 1], (30, 3)), rng.normal([0, 1, 0], [1, 1, 2], (25, 3))]
    lab = np.r_[np.ones(30, bool), np.zeros(25, bool)]
    subsets = [(0,), (1, 2), (0, 1, 2)]
    boot = bootstrap_lda(x, lab, subsets, sigma=0.7, n_resamples=3, rng=np.random.default_rng(14), chunk=1)
    replay = np.random.default_rng(14)
    for b in range(3):
        i1 = replay.integers(0, 30, size=(1, 30))[0]
        i0 = replay.integers(0, 25, size=(1, 25))[0]
        xr = np.r_[x[:30][i1], x[30:][i0]]
        for k, s in enumerate(subsets):
            direct = fisher_lda(xr[:, s], lab)
            assert boot.J[b, k] == pytest.approx(direct.criterion)
            assert boot.J_sigma[b, k] == pytest.approx(fisher_lda(xr[:, s], lab, sigma=0.7).criterion)
            assert boot.n_f[b, k] == pytest.approx(direct.error_fraction)
