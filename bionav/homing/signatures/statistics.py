"""Ring-wise intensity statistics [mean] [std] [skew] [kurt] (thesis eqs. 3.49-3.52).

All four are rotation invariant: a rotation of the robot about its vertical
axis rolls the columns of the unfolded panorama, which leaves every ring's
set of pixel values unchanged.
"""

from __future__ import annotations

import numpy as np

from bionav.homing.signatures.rings import ring_edges, ring_index


def _ring_moments(image: np.ndarray, rings: int, order: int):
    img = np.asarray(image, dtype=np.float64)
    if img.ndim != 2:
        raise ValueError(f"expected a 2-D (H, W) panorama, got shape {img.shape}")
    h, w = img.shape
    edges = ring_edges(h, rings)
    counts = np.diff(edges) * w
    mean = np.add.reduceat(img.sum(axis=1), edges[:-1]) / counts
    if order == 1:
        return mean, None, None
    dev = img - mean[ring_index(h, rings)][:, None]
    powers = [dev * dev]
    if order >= 3:
        powers.append(powers[0] * dev)
    if order >= 4:
        powers.append(powers[0] * powers[0])
    central = [np.add.reduceat(pw.sum(axis=1), edges[:-1]) / counts for pw in powers]
    return mean, np.sqrt(central[0]), central


def ring_mean(image: np.ndarray, *, rings: int = 1) -> np.ndarray:
    """Average intensity of each ring, [mean] (thesis eq. 3.49).

    Parameters
    ----------
    image : ndarray, shape (H, W)
        Unfolded panorama.
    rings : int
        Number of rings ``R`` (equal row bands, :func:`~bionav.homing.signatures.rings.ring_edges`).

    Returns
    -------
    ndarray, shape (R,), float64
        ``mu_k = mean of the pixels of ring k``.
    """
    return _ring_moments(image, rings, 1)[0]


def ring_std(image: np.ndarray, *, rings: int = 1) -> np.ndarray:
    """Population standard deviation of each ring, [std] (thesis eq. 3.50).

    Parameters
    ----------
    image : ndarray, shape (H, W)
    rings : int

    Returns
    -------
    ndarray, shape (R,), float64
        ``sigma_k = sqrt(mean((I - mu_k)**2))`` over ring ``k`` (divisor ``n``, not ``n - 1``).
    """
    return _ring_moments(image, rings, 2)[1]


def ring_skewness(image: np.ndarray, *, rings: int = 1) -> np.ndarray:
    """Skewness of each ring, [skew] (thesis eq. 3.51): ``mu_3 / sigma**3``.

    A ring of constant intensity (``sigma = 0``) has skewness 0.

    Returns
    -------
    ndarray, shape (R,), float64
    """
    _, sigma, central = _ring_moments(image, rings, 3)
    return np.divide(central[1], sigma**3, out=np.zeros_like(sigma), where=sigma > 0)


def ring_kurtosis(image: np.ndarray, *, rings: int = 1) -> np.ndarray:
    """Excess kurtosis of each ring, [kurt] (thesis eq. 3.52): ``mu_4 / sigma**4 - 3``.

    A ring of constant intensity (``sigma = 0``) has kurtosis 0 (by convention).

    Returns
    -------
    ndarray, shape (R,), float64
    """
    _, sigma, central = _ring_moments(image, rings, 4)
    return np.divide(central[2], sigma**4, out=np.full_like(sigma, 3.0), where=sigma > 0) - 3.0
