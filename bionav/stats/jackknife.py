"""Jackknife estimates and standard errors (thesis 3.3.1; Efron 1979, Quinn & Keough 2002)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class JackknifeResult:
    """Outcome of :func:`jackknife`.

    Attributes
    ----------
    estimate : float
        The statistic on the full sample, ``theta*``.
    jackknife_estimate : float
        Mean of the pseudo-values (the bias-corrected jackknife estimate).
    standard_error : float
        Jackknife standard error of the statistic.
    leave_one_out : ndarray, shape (n,)
        ``theta*_{-i}``: the statistic with observation ``i`` removed.
    pseudo_values : ndarray, shape (n,)
        ``n theta* - (n - 1) theta*_{-i}`` (eq. 3.7).
    """

    estimate: float
    jackknife_estimate: float
    standard_error: float
    leave_one_out: np.ndarray
    pseudo_values: np.ndarray


def jackknife(sample, statistic) -> JackknifeResult:
    """Leave-one-out jackknife of a scalar statistic.

    Parameters
    ----------
    sample : array_like, shape (n, ...)
        Observations along axis 0 (rows may be vectors, e.g. a pair
        ``(a_i, b_i)`` of two methods' results at one snapshot position).
    statistic : callable
        ``statistic(sub_sample) -> float`` for an array of shape ``(m, ...)``.

    Returns
    -------
    JackknifeResult

    Notes
    -----
    The standard error is Efron's
    ``sqrt((n - 1)/n * sum_i (theta*_{-i} - mean_j theta*_{-j})^2)``, which equals
    the standard deviation of the pseudo-values divided by ``sqrt(n)``; for the
    mean it is exactly ``s / sqrt(n)``. (Eq. 3.8 as printed in the thesis mixes
    pseudo-values with the ``(n-1)/n`` factor of the leave-one-out form; this is
    the form of Quinn & Keough and Efron & Tibshirani 1993, eq. 11.5.)
    """
    data = np.asarray(sample)
    n = data.shape[0]
    if n < 2:
        raise ValueError("the jackknife needs at least two observations")
    theta = float(statistic(data))
    keep = ~np.eye(n, dtype=bool)
    loo = np.array([float(statistic(data[keep[i]])) for i in range(n)])
    pseudo = n * theta - (n - 1) * loo
    se = float(np.sqrt((n - 1) / n * np.sum((loo - loo.mean()) ** 2)))
    return JackknifeResult(theta, float(pseudo.mean()), se, loo, pseudo)
