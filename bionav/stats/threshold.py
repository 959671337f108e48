"""Decision thresholds on a 1-D projection.

* Supervised (:func:`min_error_threshold`, batched :func:`min_errors`), thesis 6.2.2
  (table 6.2, ``n_f``): after Fisher's LDA has projected both classes onto one
  axis, the class border is the threshold that misclassifies the fewest labelled
  samples; ``n_f`` is the fraction misclassified.
* Unsupervised (:func:`otsu_threshold`): the split of unlabelled samples into two
  groups with the largest between-group variance (Otsu 1979), for a threshold
  adapted to each image ("local" sky/object separation, Differt & Moeller 2016).

Convention: class 1 (``labels == True``) is expected *above* the threshold, i.e.
a sample is predicted as class 1 when ``projection > threshold``. Orient the
projection (e.g. with :func:`bionav.stats.fisher_lda`, whose direction points
from class 0 to class 1) before calling.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Threshold:
    """A class border on a 1-D projection.

    Attributes
    ----------
    threshold : float
        Predict class 1 where ``projection > threshold``.
    n_errors : int
        Misclassified samples at this threshold.
    n_samples : int
        Number of samples the threshold was chosen on.
    """

    threshold: float
    n_errors: int
    n_samples: int

    @property
    def error_fraction(self) -> float:
        """``n_errors / n_samples`` (the thesis' ``n_f`` as a fraction, not per mille)."""
        return self.n_errors / self.n_samples if self.n_samples else float("nan")


def _check(projection, labels):
    y = np.asarray(projection, dtype=float)
    lab = np.asarray(labels)
    if lab.dtype != bool:
        lab = lab.astype(bool)
    if y.shape != lab.shape:
        raise ValueError(f"projection shape {y.shape} != labels shape {lab.shape}")
    if not np.all(np.isfinite(y)):
        raise ValueError("projection contains NaN or infinite values")
    return y, lab


def min_error_threshold(projection, labels) -> Threshold:
    """Threshold on a 1-D projection that minimises the number of misclassified samples.

    Parameters
    ----------
    projection : array_like, shape (N,)
        Projected samples (e.g. ``x @ w``), any unit.
    labels : array_like of bool, shape (N,)
        True for class 1, which is predicted where ``projection > threshold``.

    Returns
    -------
    Threshold
        Among all thresholds with the minimum number of errors (the candidates
        are the midpoints between consecutive distinct projected values, plus one
        value below and one above all samples), the one closest to the midpoint
        of the two class means. Equal projected values are never split.

    Notes
    -----
    Errors at threshold ``t`` are ``#{class 1, y <= t} + #{class 0, y > t}``.
    O(N log N) by sorting and cumulative counts.
    """
    y, lab = _check(projection, labels)
    n = y.size
    if n == 0:
        raise ValueError("min_error_threshold needs at least one sample")
    order = np.argsort(y, kind="stable")
    ys, ls = y[order], lab[order]
    n0 = int(np.count_nonzero(~ls))
    # errors when the first k sorted samples are called class 0 (k = 0..N)
    c1 = np.concatenate([[0], np.cumsum(ls)])
    k = np.arange(n + 1)
    errors = c1 + (n0 - (k - c1))
    valid = np.ones(n + 1, dtype=bool)
    valid[1:n] = ys[1:] > ys[:-1]
    span = ys[-1] - ys[0]
    pad = 0.5 * span if span > 0 else 0.5
    cand = np.empty(n + 1)
    cand[0] = ys[0] - pad
    cand[n] = ys[-1] + pad
    cand[1:n] = 0.5 * (ys[1:] + ys[:-1])
    err_valid = np.where(valid, errors, np.iinfo(np.int64).max)
    best = err_valid.min()
    ties = np.flatnonzero(err_valid == best)
    if np.any(lab) and np.any(~lab):
        centre = 0.5 * (y[lab].mean() + y[~lab].mean())
    else:
        centre = 0.5 * (ys[0] + ys[-1])
    pick = ties[np.argmin(np.abs(cand[ties] - centre))]
    return Threshold(float(cand[pick]), int(best), int(n))


def min_errors(projections, labels) -> np.ndarray:
    """Minimum number of misclassifications over all thresholds, batched.

    The vectorised counterpart of :func:`min_error_threshold` for bootstrap
    loops: only the error count is returned, no threshold.

    Parameters
    ----------
    projections : array_like, shape (..., N)
        Projected samples; the last axis holds the samples of one problem.
    labels : array_like of bool, broadcastable to ``projections``
        True for class 1 (predicted above the threshold).

    Returns
    -------
    ndarray of int, shape (...)
        Minimum error count per problem; ties in the projection are never split.
    """
    y = np.asarray(projections, dtype=float)
    lab = np.broadcast_to(np.asarray(labels, dtype=bool), y.shape)
    n = y.shape[-1]
    order = np.argsort(y, axis=-1, kind="stable")
    ys = np.take_along_axis(y, order, axis=-1)
    ls = np.take_along_axis(lab, order, axis=-1)
    n0 = np.count_nonzero(~ls, axis=-1)[..., None]
    zeros = np.zeros(y.shape[:-1] + (1,), dtype=np.int64)
    c1 = np.concatenate([zeros, np.cumsum(ls, axis=-1, dtype=np.int64)], axis=-1)
    k = np.arange(n + 1)
    errors = 2 * c1 + n0 - k
    valid = np.ones(y.shape[:-1] + (n + 1,), dtype=bool)
    valid[..., 1:n] = ys[..., 1:] > ys[..., :-1]
    return np.where(valid, errors, np.iinfo(np.int64).max).min(axis=-1)


def otsu_threshold(projection) -> float:
    """Unsupervised two-group threshold of 1-D samples: Otsu's maximum between-class variance.

    Otsu, N. (1979), A threshold selection method from gray-level histograms,
    IEEE Trans. Syst. Man Cybern. 9(1), 62-66, doi:10.1109/TSMC.1979.4310076,
    evaluated exactly on the sorted samples (no histogram bins).

    Parameters
    ----------
    projection : array_like, shape (N,) or any shape (flattened)
        Unlabelled projected samples (e.g. the pixels of one image projected on
        a discriminant direction), any unit; finite values only.

    Returns
    -------
    float
        The midpoint between the two consecutive distinct values at which the
        split into ``{y <= t}`` and ``{y > t}`` maximises ``w0 w1 (mu0 - mu1)^2``
        (group weights ``w``, means ``mu``); the smallest such split on ties.
        Equal values are never split.

    Raises
    ------
    ValueError
        Fewer than two distinct values, or NaN / infinite values.

    Notes
    -----
    The result is the threshold that would separate two groups if the samples
    hold two; it does not test that they do (a unimodal sample is split too).
    O(N log N).
    """
    y = np.sort(np.asarray(projection, dtype=float).ravel())
    if not np.all(np.isfinite(y)):
        raise ValueError("projection contains NaN or infinite values")
    if y.size < 2 or y[-1] == y[0]:
        raise ValueError("otsu_threshold needs at least two distinct values")
    n = y.size
    k = np.arange(1, n)  # the first k sorted samples form group 0
    cs = np.cumsum(y)[:-1]
    total = cs[-1] + y[-1]
    mu0 = cs / k
    mu1 = (total - cs) / (n - k)
    between = (k / n) * (1 - k / n) * (mu0 - mu1) ** 2
    between[y[1:] == y[:-1]] = -1.0  # never split equal values
    i = int(np.argmax(between))
    return float(0.5 * (y[i] + y[i + 1]))
