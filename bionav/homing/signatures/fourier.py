"""Discrete Fourier parameters of unfolded panoramas (thesis 3.5.3, 3.5.4, appendix C).

The unfolded panorama is closed in the column direction, so the 1-D DFT is
taken along the columns (thesis eq. 3.45, the un-normalised transform of
:func:`numpy.fft.fft`)::

    F_k(I) = sum_{i=0}^{N-1} I_i exp(-1j * k * i * 2 pi / N)

either of every image row ([fc], [fc_abs], [mffc_phase], [mffc_abs]) or of a
per-column profile of the image ([mean_fft], [std_fft], [cog_fft] and their
``_abs`` versions). A column roll by ``m`` multiplies ``F_k`` by
``exp(-1j k m 2 pi / N)``, so amplitudes ``|F_k|`` are rotation invariant and
the complex coefficients are not.

Choices the thesis leaves open (documented here, following appendix C, which
sums over ``k = 0 .. K-1``):

* ``n_coeffs`` ``K`` keeps the coefficients ``k = 0, ..., K-1`` (the DC term
  included). ``K`` may go up to ``N`` (all coefficients, which makes the
  potential of [fc] ``N`` times the sum of squared pixel differences by
  Parseval's theorem).
* Complex coefficients enter a signature vector as their real parts followed
  by their imaginary parts (:func:`complex_to_real`), so that the squared
  Euclidean distance of eq. 5.17 equals ``sum |F_k(C) - F_k(S)|**2`` (eq. C.2).
"""

from __future__ import annotations

import numpy as np

from bionav.errors import UserError


def _check_k(n_coeffs: int, n: int) -> int:
    k = int(n_coeffs)
    if not 1 <= k <= n:
        raise UserError(
            f"signature.n_coeffs={n_coeffs} Fourier coefficients do not fit an image of {n} columns. "
            f"Choose signature.n_coeffs between 1 and {n}."
        )
    return k


def row_spectrum(image: np.ndarray, *, n_coeffs: int) -> np.ndarray:
    """First ``K`` DFT coefficients of every image row (thesis eqs. 3.45, 3.55, C.1).

    Parameters
    ----------
    image : ndarray, shape (H, W)
        Unfolded panorama (or any per-pixel field such as a flow-template derivative).
    n_coeffs : int
        ``K``, ``1 <= K <= W``.

    Returns
    -------
    ndarray, shape (H, K), complex128
        ``F_k(I_j)`` for rows ``j`` and ``k = 0 .. K-1``.
    """
    img = np.asarray(image, dtype=np.float64)
    if img.ndim != 2:
        raise ValueError(f"expected a 2-D (H, W) panorama, got shape {img.shape}")
    k = _check_k(n_coeffs, img.shape[1])
    return np.fft.fft(img, axis=1)[:, :k]


def profile_spectrum(profile: np.ndarray, *, n_coeffs: int) -> np.ndarray:
    """First ``K`` DFT coefficients of a per-column profile (thesis eqs. 3.56-3.58).

    Parameters
    ----------
    profile : ndarray, shape (W,)
    n_coeffs : int

    Returns
    -------
    ndarray, shape (K,), complex128
    """
    p = np.asarray(profile, dtype=np.float64)
    k = _check_k(n_coeffs, p.shape[-1])
    return np.fft.fft(p, axis=-1)[..., :k]


def column_mean(image: np.ndarray) -> np.ndarray:
    """Average of every column, ``mu_i = mean_j I_ij`` (thesis eq. 3.56); shape ``(W,)``."""
    return np.asarray(image, dtype=np.float64).mean(axis=0)


def column_std(image: np.ndarray) -> np.ndarray:
    """Population standard deviation of every column (thesis eq. 3.57); shape ``(W,)``."""
    return np.asarray(image, dtype=np.float64).std(axis=0)


def column_cog(image: np.ndarray) -> np.ndarray:
    """Centre of gravity of every column along the rows (thesis eq. 3.58).

    ``j_s_i = sum_j I_ij j / sum_j I_ij`` with row index ``j`` (0 = top row).
    A column with zero total intensity gets the middle row ``(H - 1) / 2``.

    Parameters
    ----------
    image : ndarray, shape (H, W)

    Returns
    -------
    ndarray, shape (W,), rows
    """
    img = np.asarray(image, dtype=np.float64)
    h = img.shape[0]
    mass = img.sum(axis=0)
    moment = np.arange(h) @ img
    return np.divide(moment, mass, out=np.full(img.shape[1], (h - 1) / 2.0), where=mass != 0)


def complex_to_real(z: np.ndarray) -> np.ndarray:
    """Flatten complex coefficients to ``[Re(z).ravel(), Im(z).ravel()]`` (float64)."""
    z = np.asarray(z)
    return np.concatenate([z.real.ravel(), z.imag.ravel()]).astype(np.float64)
