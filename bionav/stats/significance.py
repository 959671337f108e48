"""Pairwise significance of differences between several paired bootstrap statistics.

Thesis 6.2.3/6.3.3 (tables 6.3, 6.5): the criteria of all features are
bootstrapped on the *same* resamples; two features differ significantly at
level ``alpha`` when the percentile interval ``[alpha/2, 1 - alpha/2]`` of the
resampled difference excludes zero (Efron & Tibshirani 1993, ch. 13 and 16).
"""

from __future__ import annotations

import numpy as np

from bionav.stats.bootstrap import SIGNIFICANCE_LEVELS


def pairwise_significance(distribution, *, levels=SIGNIFICANCE_LEVELS) -> np.ndarray:
    """Smallest significance level at which each pair of statistics differs.

    Parameters
    ----------
    distribution : array_like, shape (B, K)
        Bootstrap replicates of K statistics computed on the same B resamples.
    levels : sequence of float, optional
        Levels to test (default 0.05, 0.01, 0.001).

    Returns
    -------
    ndarray, shape (K, K)
        Entry ``(i, j)`` is the smallest level in ``levels`` at which the
        two-sided percentile interval of ``stat_i - stat_j`` excludes zero, NaN
        where no level does (and on the diagonal). Symmetric.
    """
    d = np.asarray(distribution, dtype=float)
    if d.ndim != 2:
        raise ValueError(f"distribution must have shape (B, K), got {d.shape}")
    k = d.shape[1]
    out = np.full((k, k), np.nan)
    diff = d[:, :, None] - d[:, None, :]
    for alpha in sorted(levels, reverse=True):
        lo, hi = np.quantile(diff, [alpha / 2, 1 - alpha / 2], axis=0)
        sig = (lo > 0) | (hi < 0)
        out[sig] = alpha
    np.fill_diagonal(out, np.nan)
    return out
