"""Bootstrap confidence intervals and the paired comparison of two methods.

Thesis 3.3.2 (Efron 1979, 1987; Efron & Tibshirani 1993, *An Introduction to
the Bootstrap*, ch. 14 for BCa intervals): two homing methods evaluated at the
same snapshot positions are compared by bootstrapping the difference of their
averaged measures (eqs. 3.9, 3.10) with B = 2000 resamples and bias-corrected
and accelerated (BCa) intervals. The resampling is done by
:func:`scipy.stats.bootstrap`; the BCa interval is evaluated here from the stored
bootstrap distribution, so that intervals at any level and an achieved
significance level come from one set of resamples (identical to scipy's BCa
interval at the level scipy was asked for).
"""

from __future__ import annotations

import inspect
from dataclasses import dataclass, field

import numpy as np
from scipy import stats
from scipy.special import ndtr, ndtri

#: Significance levels of the thesis' tables (5 %, 1 %, 0.1 %) and their marks.
SIGNIFICANCE_LEVELS = (0.05, 0.01, 0.001)


def stars(p_or_level: float | None) -> str:
    """Significance mark of the thesis' tables: ``***`` 0.1 %, ``**`` 1 %, ``*`` 5 %, ``""`` otherwise.

    Parameters
    ----------
    p_or_level : float or None
        A p-value, or the smallest level at which a difference is significant
        (``None`` or NaN for not significant).
    """
    if p_or_level is None or not np.isfinite(p_or_level):
        return ""
    for level, mark in zip(sorted(SIGNIFICANCE_LEVELS), ("***", "**", "*")):
        if p_or_level <= level:
            return mark
    return ""


@dataclass(frozen=True)
class Interval:
    """A confidence interval ``[low, high]`` with the bootstrap standard error."""

    low: float
    high: float
    standard_error: float
    confidence_level: float


def _accepts_axis(statistic) -> bool:
    try:
        return "axis" in inspect.signature(statistic).parameters
    except (TypeError, ValueError):  # numpy ufunc-likes without a signature
        return False


def bootstrap_interval(
    sample,
    *,
    statistic=np.mean,
    confidence_level: float = 0.95,
    n_resamples: int = 2000,
    method: str = "BCa",
    rng: np.random.Generator,
) -> Interval:
    """Bootstrap confidence interval of a one-sample statistic.

    A thin wrapper of :func:`scipy.stats.bootstrap`.

    Parameters
    ----------
    sample : array_like, shape (n,)
        Observations.
    statistic : callable, optional
        ``statistic(x, axis=-1)`` (vectorised) or ``statistic(x)``; default mean.
    confidence_level : float, optional
        Two-sided coverage, e.g. 0.95.
    n_resamples : int, optional
        Bootstrap resamples B (the thesis uses 2000 for homing measures).
    method : {"BCa", "percentile", "basic"}, optional
        Interval type.
    rng : numpy.random.Generator
        Source of randomness.

    Returns
    -------
    Interval
    """
    x = np.asarray(sample, dtype=float)
    vec = _accepts_axis(statistic)
    res = stats.bootstrap(
        (x,),
        statistic,
        n_resamples=n_resamples,
        confidence_level=confidence_level,
        method=method,
        vectorized=vec,
        rng=rng,
    )
    ci = res.confidence_interval
    return Interval(float(ci.low), float(ci.high), float(res.standard_error), confidence_level)


@dataclass(frozen=True)
class BootstrapDifference:
    """Bootstrap distribution of ``statistic(a) - statistic(b)`` over paired observations.

    Attributes
    ----------
    estimate : float
        ``statistic(a) - statistic(b)`` on the full data (eqs. 3.9, 3.10).
    distribution : ndarray, shape (B,)
        The statistic's difference on each paired resample.
    bias_correction : float
        BCa ``z0``.
    acceleration : float
        BCa ``a`` from the jackknife over pairs.
    standard_error : float
        Standard deviation of the bootstrap distribution.
    levels : tuple of float
        Significance levels reported by :attr:`significance` (5, 1, 0.1 %).
    """

    estimate: float
    distribution: np.ndarray
    bias_correction: float
    acceleration: float
    standard_error: float
    levels: tuple = field(default=SIGNIFICANCE_LEVELS)

    @property
    def degenerate(self) -> bool:
        """True when every resample gave the same value (e.g. identical methods)."""
        return bool(np.ptp(self.distribution) == 0)

    def ci(self, level: float = 0.95) -> tuple[float, float]:
        """Two-sided BCa confidence interval ``(low, high)`` with coverage ``level``."""
        if not 0 < level < 1:
            raise ValueError(f"confidence level must be in (0, 1), got {level}")
        if self.degenerate:
            v = float(self.distribution[0])
            return v, v
        alpha = (1 - level) / 2
        z0, a = self.bias_correction, self.acceleration
        q = []
        for z in (ndtri(alpha), -ndtri(alpha)):
            q.append(ndtr(z0 + (z0 + z) / (1 - a * (z0 + z))))
        lo, hi = np.quantile(self.distribution, q)
        return float(lo), float(hi)

    def significant(self, alpha: float) -> bool:
        """True when the ``1 - alpha`` BCa interval excludes zero."""
        lo, hi = self.ci(1 - alpha)
        return bool(lo > 0 or hi < 0)

    @property
    def significance(self) -> dict:
        """``{alpha: significant(alpha)}`` for the levels 0.05, 0.01, 0.001."""
        return {alpha: self.significant(alpha) for alpha in self.levels}

    @property
    def stars(self) -> str:
        """``***``/``**``/``*``/``""`` from the smallest level at which the interval excludes zero."""
        hits = [alpha for alpha in self.levels if self.significant(alpha)]
        return stars(min(hits)) if hits else ""

    @property
    def p_value(self) -> float:
        """Two-sided achieved significance level of a zero difference (BCa-consistent).

        The ``alpha`` at which one end of the ``1 - alpha`` BCa interval sits at
        zero (Efron & Tibshirani 1993, ch. 15-16). 0.0 means no resample crossed
        zero (p below about ``1/B``); 1.0 for a degenerate zero difference.
        """
        if self.degenerate:
            return 1.0 if self.distribution[0] == 0 else 0.0
        d = self.distribution
        p0 = (np.count_nonzero(d < 0) + np.count_nonzero(d <= 0)) / (2 * d.size)
        if p0 <= 0 or p0 >= 1:
            return 0.0
        z0, a = self.bias_correction, self.acceleration
        dz = ndtri(p0) - z0
        v = dz / (1 + a * dz)
        one_sided = ndtr(v - z0)
        return float(min(1.0, 2 * min(one_sided, 1 - one_sided)))


def paired_bootstrap_difference(
    a,
    b,
    *,
    statistic=np.mean,
    n_resamples: int = 2000,
    rng: np.random.Generator,
) -> BootstrapDifference:
    """Paired bootstrap of the difference of a statistic between two methods.

    Thesis 3.3.2, eqs. 3.9/3.10: ``theta = stat(method 1) - stat(method 2)``
    where both methods were evaluated at the same n positions (e.g. AAE_s or
    RR_s per snapshot position); resampling draws positions with replacement
    and keeps the pairs together.

    Parameters
    ----------
    a, b : array_like, shape (n,)
        Paired observations of method 1 and method 2 (same order).
    statistic : callable, optional
        ``statistic(x, axis=-1)`` or ``statistic(x)``; default :func:`numpy.mean`.
    n_resamples : int, optional
        B; the thesis uses 2000.
    rng : numpy.random.Generator
        Source of randomness.

    Returns
    -------
    BootstrapDifference
        ``.estimate``, ``.ci(level)`` (BCa), ``.significance`` (``{0.05: bool,
        0.01: bool, 0.001: bool}``), ``.stars``, ``.p_value``.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> res = paired_bootstrap_difference(aae_sift, aae_warping, rng=rng)  # doctest: +SKIP
    >>> res.estimate, res.ci(0.95), res.stars                             # doctest: +SKIP
    """
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    if a.shape != b.shape or a.ndim != 1:
        raise ValueError(f"a and b must be 1-D and paired, got shapes {a.shape} and {b.shape}")
    if a.size < 2:
        raise ValueError("the paired bootstrap needs at least two paired observations")
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        raise ValueError("a and b must be finite (drop positions where either method has no value)")
    vec = _accepts_axis(statistic)
    if vec:
        def diff(x, y, axis=-1):
            return statistic(x, axis=axis) - statistic(y, axis=axis)
    else:
        def diff(x, y):
            return statistic(x) - statistic(y)

    res = stats.bootstrap(
        (a, b),
        diff,
        n_resamples=n_resamples,
        paired=True,
        vectorized=vec,
        method="percentile",
        rng=rng,
    )
    dist = np.asarray(res.bootstrap_distribution, dtype=float)
    theta = float(statistic(a) - statistic(b))
    # BCa constants (Efron & Tibshirani 1993, eqs. 14.14 and 14.15)
    p = (np.count_nonzero(dist < theta) + np.count_nonzero(dist <= theta)) / (2 * dist.size)
    z0 = float(ndtri(p)) if 0 < p < 1 else 0.0
    n = a.size
    keep = ~np.eye(n, dtype=bool)
    if vec:
        loo = diff(np.broadcast_to(a, (n, n))[keep].reshape(n, n - 1),
                   np.broadcast_to(b, (n, n))[keep].reshape(n, n - 1), axis=-1)
    else:
        loo = np.array([diff(a[keep[i]], b[keep[i]]) for i in range(n)])
    u = (n - 1) * (loo.mean() - loo)
    den = np.sum(u**2)
    acc = float(np.sum(u**3) / (6 * den**1.5)) if den > 0 else 0.0
    return BootstrapDifference(theta, dist, z0, acc, float(np.std(dist, ddof=1)))
