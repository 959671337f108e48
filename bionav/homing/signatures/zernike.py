"""Zernike moments of a panorama wrapped onto the unit disc (Sun, Yue & Mangan 2020).

Sun, X., Yue, S. & Mangan, M. (2020). A decentralised neural model explaining
optimal integration of navigational strategies in insects. *eLife* 9, e54026,
doi:10.7554/eLife.54026: the panoramic skyline is encoded by Zernike moments;
their amplitudes are invariant to rotations of the view about the vertical
axis and their phases give the rotation (the heading).

Mapping (a choice the paper makes implicitly by wrapping the panorama into a
disc): the canonical panorama (:mod:`bionav.geometry`) of shape ``(H, W)``
is read in polar coordinates, column ``j`` at polar angle
``theta_j = 2*pi*j/W`` (counter-clockwise, the panorama's azimuth) and row
``r`` at radius ``rho_r = (r + 1/2) / H`` (row 0, the top of the view, near the
centre). The moment of order ``n`` and repetition ``m`` (``0 <= m <= n``,
``n - m`` even) is the polar quadrature of the Zernike integral::

    Z_nm = (n + 1) / pi * sum_r sum_j I[r, j] R_nm(rho_r) exp(-1j m theta_j) rho_r drho dtheta

with the radial polynomial ``R_nm`` (Zernike 1934). The sum over ``j`` is the
row-wise DFT, so all moments cost one FFT per row plus a small matrix product.

Rotation: the view at heading ``phi + delta`` (the heading-``phi`` panorama
rolled by ``-delta * W / 2 pi`` columns) has moments ``Z_nm exp(1j m delta)``:
exact for whole-column rotations.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from bionav.errors import UserError
from bionav.geometry import TWO_PI, parabolic_peak_offset


def zernike_indices(order: int) -> np.ndarray:
    """``(n, m)`` pairs with ``0 <= m <= n <= order`` and ``n - m`` even, shape ``(K, 2)``."""
    order = int(order)
    if not 0 <= order <= 60:  # a Python caller's argument (signature.order is checked against its declared range)
        raise ValueError(f"order must lie in 0..60 (the paper's range is up to about 20), got {order}")
    return np.array([(n, m) for n in range(order + 1) for m in range(n % 2, n + 1, 2)], dtype=np.int64)


def radial_polynomial(n: int, m: int, rho: np.ndarray) -> np.ndarray:
    """Zernike radial polynomial ``R_nm(rho)`` (``n - m`` even, ``m >= 0``)."""
    rho = np.asarray(rho, np.float64)
    out = np.zeros_like(rho)
    for s in range((n - m) // 2 + 1):
        c = (-1) ** s * math.factorial(n - s) / (
            math.factorial(s) * math.factorial((n + m) // 2 - s) * math.factorial((n - m) // 2 - s))
        out += c * rho ** (n - 2 * s)
    return out


@lru_cache(maxsize=16)
def _basis(order: int, height: int, width: int):
    idx = zernike_indices(order)
    rho = (np.arange(height) + 0.5) / height
    drho = 1.0 / height
    dtheta = TWO_PI / width
    radial = np.stack([radial_polynomial(int(n), int(m), rho) for n, m in idx])  # (K, H)
    weight = ((idx[:, 0] + 1) / np.pi)[:, None] * radial * rho[None, :] * drho * dtheta
    return idx, weight


def zernike_moments(image: np.ndarray, *, order: int) -> tuple[np.ndarray, np.ndarray]:
    """Zernike moments of a panorama wrapped onto the unit disc.

    Parameters
    ----------
    image : ndarray, shape (H, W)
        Canonical panorama (or a binary sky mask: the skyline).
    order : int
        Highest order ``n`` (0..60).

    Returns
    -------
    moments : ndarray, shape (K,), complex128
        ``Z_nm`` for the pairs of :func:`zernike_indices`.
    indices : ndarray, shape (K, 2), int
        ``(n, m)`` of every moment.
    """
    img = np.asarray(image, np.float64)
    if img.ndim != 2:
        raise ValueError(f"expected a 2-D (H, W) panorama, got shape {img.shape}")
    h, w = img.shape
    idx, weight = _basis(int(order), h, w)
    if idx[:, 1].max(initial=0) >= w:
        raise UserError(f"signature.order={order} needs at least {idx[:, 1].max() + 1} image columns; "
                        f"the image has {w}.")
    spec = np.fft.fft(img, axis=1)  # (H, W): sum_j I[r, j] exp(-1j m theta_j) at column m
    moments = np.einsum("kr,rk->k", weight, spec[:, idx[:, 1]])
    return moments, idx


def rotation_from_moments(moments_current: np.ndarray, moments_snapshot: np.ndarray, indices: np.ndarray, *,
                          n_angles: int = 360) -> float:
    """Rotation ``delta = heading(current) - heading(snapshot)`` from the moments' phases.

    Least squares over all moments with ``m > 0``:
    ``delta = argmin sum |Z_c - Z_s exp(1j m delta)|**2``, searched on
    ``n_angles`` equally spaced angles and refined by a parabola through the
    best three.

    Returns
    -------
    float
        Radians in ``[-pi, pi)``, counter-clockwise.
    """
    m = np.asarray(indices)[:, 1]
    keep = m > 0
    zc = np.asarray(moments_current)[keep]
    zs = np.asarray(moments_snapshot)[keep]
    if zc.size == 0:
        return float("nan")
    alphas = np.arange(n_angles) * TWO_PI / n_angles
    # |Zc - Zs e^{im a}|^2 = |Zc|^2 + |Zs|^2 - 2 Re(conj(Zc) Zs e^{im a}); maximise the last sum
    score = np.real(np.exp(1j * np.outer(alphas, m[keep])) @ (np.conj(zc) * zs))
    k = int(np.argmax(score))
    frac = float(parabolic_peak_offset(score[(k - 1) % n_angles], score[k], score[(k + 1) % n_angles]))
    delta = (k + frac) * TWO_PI / n_angles
    return float((delta + np.pi) % TWO_PI - np.pi)
