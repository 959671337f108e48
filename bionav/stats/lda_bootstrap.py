"""Bootstrap distributions of LDA criteria for many feature subsets at once.

Thesis 6.2.3 and 6.3.3: J, J_sigma and n_f of every feature (single channels,
channel pairs, all channels) are re-estimated on 10,000 bootstrap data sets to
test whether two features differ significantly. Every feature is evaluated on
the same resamples (a paired design), so differences between features can be
read off the joint distribution (see :func:`bionav.stats.pairwise_significance`).
Resampling is stratified: each class is resampled with replacement at its own
size, so every data set has the original class sizes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.stats.lda import _check, optimal_criterion
from bionav.stats.threshold import min_errors


@dataclass(frozen=True)
class LdaBootstrap:
    """Bootstrap replicates of the LDA criteria per feature subset.

    Attributes
    ----------
    J : ndarray, shape (B, K)
        Fisher criterion (eq. 3.16) at its optimum, per resample and subset.
    J_sigma : ndarray, shape (B, K)
        Noise-regularised criterion (eq. 3.22) at its optimum.
    n_f : ndarray, shape (B, K)
        Fraction of misclassified samples with the minimum-error threshold on
        the plain-LDA projection.
    """

    J: np.ndarray
    J_sigma: np.ndarray
    n_f: np.ndarray


def bootstrap_lda(
    x,
    labels,
    subsets,
    *,
    sigma: float,
    n_resamples: int = 10_000,
    rng: np.random.Generator,
    chunk: int = 250,
) -> LdaBootstrap:
    """Stratified bootstrap of J, J_sigma and n_f for several feature subsets.

    Parameters
    ----------
    x : array_like, shape (N, d)
        Samples.
    labels : array_like of bool, shape (N,)
        True for class 1.
    subsets : sequence of sequence of int
        K feature subsets (column indices of ``x``), e.g. ``[(0,), (0, 4), (0, 1, 2, 3, 4)]``.
    sigma : float
        Receptor-noise standard deviation for J_sigma (unit of ``x``).
    n_resamples : int, optional
        Number of bootstrap data sets B (thesis: 10,000).
    rng : numpy.random.Generator
        Source of randomness.
    chunk : int, optional
        Resamples processed per vectorised batch (memory vs. speed).

    Returns
    -------
    LdaBootstrap
    """
    x, lab = _check(x, labels)
    x1, x0 = x[lab], x[~lab]
    n1, n0 = len(x1), len(x0)
    subsets = [tuple(int(i) for i in s) for s in subsets]
    k = len(subsets)
    out_j = np.empty((n_resamples, k))
    out_js = np.empty((n_resamples, k))
    out_nf = np.empty((n_resamples, k))
    lab_cat = np.concatenate([np.ones(n1, bool), np.zeros(n0, bool)])
    for start in range(0, n_resamples, chunk):
        c = min(chunk, n_resamples - start)
        r1 = x1[rng.integers(0, n1, size=(c, n1))]
        r0 = x0[rng.integers(0, n0, size=(c, n0))]
        m1, m0 = r1.mean(axis=1), r0.mean(axis=1)
        d1, d0 = r1 - m1[:, None], r0 - m0[:, None]
        sw = np.einsum("bni,bnj->bij", d1, d1) / n1 + np.einsum("bni,bnj->bij", d0, d0) / n0
        dm = m1 - m0
        both = np.concatenate([r1, r0], axis=1)
        for j, s in enumerate(subsets):
            idx = np.ix_(np.arange(c), s, s)
            crit, w = optimal_criterion(dm[:, s], sw[idx], sigma=0.0)
            crit_s, _ = optimal_criterion(dm[:, s], sw[idx], sigma=sigma)
            proj = np.einsum("bni,bi->bn", both[:, :, s], w)
            out_j[start:start + c, j] = crit
            out_js[start:start + c, j] = crit_s
            out_nf[start:start + c, j] = min_errors(proj, lab_cat) / (n1 + n0)
    return LdaBootstrap(out_j, out_js, out_nf)
