"""Search templates: which current-view column and scale plane a snapshot column may map to.

Both templates are expressed relative to the movement direction ``alpha`` (the
direction from the snapshot position to the current position, in the snapshot's
frame), in column units of a panorama of width ``W``:

* ``u``: snapshot column minus the column of ``alpha``; the landmark is seen at
  ``theta = 2 pi u / W`` from the movement direction;
* ``v``: current-view column plus the rotation ``psi`` minus the column of
  ``alpha``; the landmark is seen from the current position at
  ``theta' = 2 pi v / W`` from the movement direction.

Moving along ``alpha`` makes every landmark drift away from the focus of
expansion (``theta = 0``) towards the focus of contraction (``theta = pi``):
``theta'`` lies between ``theta`` (landmark infinitely far) and ``pi``
(current position infinitely far). By the sine rule in the triangle snapshot,
current position, landmark, the distance ratio is
``sigma = r / r' = sin(theta') / sin(theta)`` (Möller, Krzykawski & Gerstmayr
2010, doi:10.1007/s10514-010-9195-y).
"""

from __future__ import annotations

import numpy as np


def plane_of_scale(sigma, thresholds):
    """Scale-plane index for scale factors ``sigma`` (``K`` where none applies).

    Plane ``k`` covers ``tau_{k-1} <= sigma < tau_k`` with ``tau_{-1} = 0``.
    """
    return np.searchsorted(np.asarray(thresholds, dtype=np.float64), sigma, side="right")


def minwarp_template(width: int, scales, thresholds):
    """Template of min-warping: reachable columns and allowed planes.

    Parameters
    ----------
    width : int
        Panorama width ``W`` (columns spanning 360 degrees).
    scales, thresholds : array_like, shape (K,)
        Scale factors ``sigma_k`` and thresholds ``tau_k``
        (see :func:`bionav.homing.warping.scaleplanes.default_thresholds`).

    Returns
    -------
    vlo, vhi : ndarray, shape (W,), int32
        For snapshot column ``u`` the current columns ``v`` in
        ``vlo[u] .. vhi[u]`` (inclusive) are reachable.
    klo, khi : ndarray, shape (W, W), int32
        Planes ``klo[u, v] .. khi[u, v]`` (inclusive) are allowed for the column
        pair; empty (``klo > khi``) when the scale ratio lies beyond the last
        threshold. For ordinary pairs one plane is allowed, the one whose
        threshold interval holds ``sin(theta') / sin(theta)``. At the focus of
        expansion (``u = 0``, ``v = 0``) the ratio is undetermined but at least
        1: every plane with ``sigma_k >= 1`` is allowed; at the focus of
        contraction (``2 u = W``) every plane with ``sigma_k <= 1``.
    """
    s = np.asarray(scales, dtype=np.float64)
    tau = np.asarray(thresholds, dtype=np.float64)
    n_planes = s.size
    w = int(width)
    u = np.arange(w)
    vlo = np.empty(w, np.int32)
    vhi = np.empty(w, np.int32)
    for uu in range(w):
        if uu == 0 or 2 * uu == w:
            vlo[uu] = vhi[uu] = uu
        elif 2 * uu < w:
            vlo[uu], vhi[uu] = uu, w // 2
        else:
            vlo[uu], vhi[uu] = (w + 1) // 2, uu
    theta = 2.0 * np.pi * u / w
    sin_t = np.sin(theta)
    with np.errstate(divide="ignore", invalid="ignore"):
        sigma = np.abs(np.sin(theta)[None, :]) / np.abs(sin_t)[:, None]
    k = plane_of_scale(sigma, tau).astype(np.int32)
    klo = k.copy()
    khi = k.copy()
    out = k >= n_planes
    klo[out] = 1
    khi[out] = 0
    # degenerate columns: focus of expansion and focus of contraction
    unit = 1e-9
    ge1 = np.flatnonzero((s >= 1.0 - unit) & (s < tau))
    le1 = np.flatnonzero(s <= 1.0 + unit)
    klo[0, 0], khi[0, 0] = (ge1[0], ge1[-1]) if ge1.size else (1, 0)
    if w % 2 == 0:
        h = w // 2
        klo[h, h], khi[h, h] = (le1[0], le1[-1]) if le1.size else (1, 0)
    # pairs outside the reachable range are never visited; mark them empty anyway
    reach = (u[None, :] >= vlo[:, None]) & (u[None, :] <= vhi[:, None])
    klo[~reach] = 1
    khi[~reach] = 0
    return vlo, vhi, klo, khi


def warp2d_template(width: int, rhos, thresholds):
    """Template of 2D-warping under the equal-distance assumption.

    Every landmark is assumed at the same distance ``r`` from the snapshot
    position; the current position lies at distance ``rho * r`` along
    ``alpha``. A landmark at ``theta`` is then seen at
    ``theta' = atan2(sin theta, cos theta - rho)`` with scale ratio
    ``sigma = 1 / sqrt(1 - 2 rho cos theta + rho^2)`` (Möller 2009,
    doi:10.1016/j.robot.2008.05.005).

    Parameters
    ----------
    width : int
        Panorama width ``W``.
    rhos : array_like, shape (R,)
        Distance ratios ``rho = d / r`` in ``[0, 1)``.
    thresholds : array_like, shape (K,)
        Scale thresholds ``tau_k``; scales beyond the last threshold use the
        last plane.

    Returns
    -------
    v : ndarray, shape (R, W), int32
        Current column (relative to ``alpha``, rounded to the nearest column)
        of each snapshot column ``u``.
    k : ndarray, shape (R, W), int32
        Scale plane of each snapshot column.
    """
    w = int(width)
    rho = np.asarray(rhos, dtype=np.float64)[:, None]
    theta = 2.0 * np.pi * np.arange(w)[None, :] / w
    theta_p = np.arctan2(np.sin(theta), np.cos(theta) - rho)
    v = np.rint(theta_p * w / (2.0 * np.pi)).astype(np.int64) % w
    sigma = 1.0 / np.sqrt(1.0 - 2.0 * rho * np.cos(theta) + rho**2)
    tau = np.asarray(thresholds, dtype=np.float64)
    k = np.minimum(plane_of_scale(sigma, tau), tau.size - 1)
    return v.astype(np.int32), k.astype(np.int32)
