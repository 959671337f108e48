"""Fisher's linear discriminant analysis, with and without receptor noise.

Thesis section 3.3.3, eqs. 3.11-3.17 (Fisher's criterion ``J``; Alpaydin 2004,
*Introduction to Machine Learning*, ch. 6.8) and eqs. 3.18-3.23 (the
noise-regularised criterion ``J_sigma`` of Kollmeier 2006 / Kollmeier et al. 2007,
which adds independent Gaussian receptor noise of standard deviation ``sigma`` to
every channel of both classes).

Conventions
-----------
* ``x`` has shape ``(N, d)``: N samples of d features (d = 1 is allowed).
* ``labels`` is a boolean array of shape ``(N,)``; True marks class 1.
* Class scatter matrices use the ``1/N_i`` normalisation of eqs. 3.14/3.15
  (population covariance, not ``1/(N_i - 1)``).
* The discriminant direction is returned with unit norm and oriented so that
  class 1 projects higher than class 0 (``w @ (m1 - m0) > 0``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.stats.threshold import min_error_threshold


def _check(x, labels):
    x = np.asarray(x, dtype=float)
    if x.ndim == 1:
        x = x[:, None]
    if x.ndim != 2:
        raise ValueError(f"x must have shape (N, d), got {x.shape}")
    lab = np.asarray(labels)
    if lab.shape != (x.shape[0],):
        raise ValueError(f"labels must have shape ({x.shape[0]},), got {lab.shape}")
    lab = lab.astype(bool)
    if np.count_nonzero(lab) < 2 or np.count_nonzero(~lab) < 2:
        raise ValueError("each class needs at least two samples for a discriminant analysis")
    if not np.all(np.isfinite(x)):
        raise ValueError("x contains NaN or infinite values")
    return x, lab


def class_scatter(x, labels):
    """Class means and within-class covariance matrices (eqs. 3.14, 3.15).

    Parameters
    ----------
    x : array_like, shape (N, d) or (N,)
        Samples.
    labels : array_like of bool, shape (N,)
        True for class 1.

    Returns
    -------
    m1, m0 : ndarray, shape (d,)
        Means of class 1 and class 0.
    s1, s0 : ndarray, shape (d, d)
        Covariances ``S_i = 1/N_i sum (x - m_i)(x - m_i)^T`` of each class.
    """
    x, lab = _check(x, labels)
    x1, x0 = x[lab], x[~lab]
    m1, m0 = x1.mean(axis=0), x0.mean(axis=0)
    d1, d0 = x1 - m1, x0 - m0
    return m1, m0, d1.T @ d1 / len(x1), d0.T @ d0 / len(x0)


def fisher_criterion(w, x, labels, *, sigma: float = 0.0):
    """Fisher's criterion of one or more projection directions.

    ``J(w) = [w^T (m1 - m0)]^2 / (w^T S_W w)`` (eq. 3.16) with
    ``S_W = S_1 + S_0``; with ``sigma > 0`` the noise-regularised
    ``J_sigma(w)`` of eq. 3.22 with ``S_W + 2 sigma^2 I``.

    Parameters
    ----------
    w : array_like, shape (d,) or (K, d)
        Projection direction(s); the scale does not matter.
    x : array_like, shape (N, d)
        Samples.
    labels : array_like of bool, shape (N,)
        True for class 1.
    sigma : float, optional
        Standard deviation of the receptor noise added to every feature, in the
        unit of ``x`` (the thesis uses 30 ADC counts).

    Returns
    -------
    float or ndarray, shape (K,)
    """
    m1, m0, s1, s0 = class_scatter(x, labels)
    sw = s1 + s0 + 2.0 * sigma**2 * np.eye(len(m1))
    w = np.asarray(w, dtype=float)
    num = (w @ (m1 - m0)) ** 2
    den = np.einsum("...i,ij,...j->...", w, sw, w)
    return num / den


def optimal_criterion(delta_mean, within_scatter, *, sigma: float = 0.0):
    """Maximum of Fisher's criterion from class moments, batched.

    ``max_w J = dm^T (S_W + 2 sigma^2 I)^{-1} dm``, attained by eq. 3.17 / 3.23.
    Used by the bootstrap, which needs the criterion of many resamples at once.

    Parameters
    ----------
    delta_mean : array_like, shape (..., d)
        ``m1 - m0``.
    within_scatter : array_like, shape (..., d, d)
        ``S_W = S_1 + S_0``.
    sigma : float, optional
        Receptor-noise standard deviation (unit of the features).

    Returns
    -------
    criterion : ndarray, shape (...)
    direction : ndarray, shape (..., d)
        ``(S_W + 2 sigma^2 I)^{-1} dm`` (not normalised).
    """
    dm = np.asarray(delta_mean, dtype=float)
    sw = np.asarray(within_scatter, dtype=float) + 2.0 * sigma**2 * np.eye(dm.shape[-1])
    direction = np.linalg.solve(sw, dm[..., None])[..., 0]
    return np.einsum("...i,...i->...", dm, direction), direction


@dataclass(frozen=True)
class LinearDiscriminant:
    """A fitted two-class Fisher discriminant with its minimum-error border.

    Attributes
    ----------
    direction : ndarray, shape (d,)
        Unit discriminant vector ``w`` (eq. 3.17, or 3.23 when ``sigma > 0``),
        oriented so that class 1 projects higher than class 0.
    criterion : float
        ``J(w)`` (eq. 3.16), or ``J_sigma(w)`` (eq. 3.22) when ``sigma > 0``,
        at the optimal ``w``.
    sigma : float
        Receptor-noise standard deviation used (0 for plain LDA).
    mean1, mean0 : ndarray, shape (d,)
        Class means.
    threshold : float
        Class border on the projection ``x @ direction`` minimising the
        misclassified training samples (class 1 above).
    n_errors : int
        Misclassified training samples at that threshold.
    n_samples : int
        Number of training samples.
    """

    direction: np.ndarray
    criterion: float
    sigma: float
    mean1: np.ndarray
    mean0: np.ndarray
    threshold: float
    n_errors: int
    n_samples: int

    @property
    def error_fraction(self) -> float:
        """Fraction of misclassified training samples (``n_f`` as a fraction)."""
        return self.n_errors / self.n_samples

    def project(self, x) -> np.ndarray:
        """Project samples of shape ``(N, d)`` (or ``(N,)`` when d = 1) onto ``w``; shape ``(N,)``."""
        x = np.asarray(x, dtype=float)
        if x.ndim == 1 and len(self.direction) == 1:
            x = x[:, None]
        return x @ self.direction

    def predict(self, x) -> np.ndarray:
        """Boolean class-1 prediction ``project(x) > threshold``, shape ``(N,)``."""
        return self.project(x) > self.threshold

    def border_line(self):
        """The class border in a 2-D feature space as ``(point, tangent)``.

        The border is ``{p : w @ p = threshold}``; returns the point of it closest
        to the origin and a unit tangent. Only for d = 2.
        """
        if len(self.direction) != 2:
            raise ValueError("border_line is defined for two features only")
        w = self.direction
        return w * self.threshold, np.array([-w[1], w[0]])


def fisher_lda(x, labels, *, sigma: float = 0.0) -> LinearDiscriminant:
    """Fisher's linear discriminant of two classes, optionally with receptor noise.

    Parameters
    ----------
    x : array_like, shape (N, d) or (N,)
        Samples (e.g. log-sensor counts of d spectral channels).
    labels : array_like of bool, shape (N,)
        True for class 1 (e.g. sky), False for class 0 (e.g. objects).
    sigma : float, optional
        Standard deviation of Gaussian receptor noise added to every feature of
        both classes (eqs. 3.18-3.23); 0 gives plain Fisher LDA (eq. 3.17).

    Returns
    -------
    LinearDiscriminant
        Unit direction ``w ∝ (S_W + 2 sigma^2 I)^{-1} (m1 - m0)``, its criterion
        value, and the minimum-misclassification threshold on ``x @ w``.

    Notes
    -----
    The criterion is invariant to the scale of ``w`` (eq. 3.17, arbitrary ``c``).
    With ``sigma = 0`` and a singular within-class scatter (a constant feature)
    ``numpy.linalg.LinAlgError`` is raised; ``sigma > 0`` always regularises.
    """
    x, lab = _check(x, labels)
    m1, m0, s1, s0 = class_scatter(x, lab)
    crit, w = optimal_criterion(m1 - m0, s1 + s0, sigma=sigma)
    norm = np.linalg.norm(w)
    if not np.isfinite(norm) or norm == 0:
        raise ValueError("the class means coincide; no discriminant direction exists")
    w = w / norm
    thr = min_error_threshold(x @ w, lab)
    return LinearDiscriminant(
        direction=w,
        criterion=float(crit),
        sigma=float(sigma),
        mean1=m1,
        mean0=m0,
        threshold=thr.threshold,
        n_errors=thr.n_errors,
        n_samples=thr.n_samples,
    )
