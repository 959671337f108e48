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
from numba import njit


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


def minwarp_windows(template, *, max_level: int = 4):
    """Cover the min-warping template with power-of-two windows of current columns.

    For each snapshot column ``u`` and plane ``k`` the allowed current columns
    ``v`` form runs; the minimum over a run of length ``L`` is the minimum over
    a few windows of ``2**j`` columns, read from the sliding minima of
    :func:`~bionav.homing.warping.kernels.fill_window_minima`: two overlapping
    windows of level ``floor(log2 L)`` (one if ``L`` is a power of two) for
    ``L <= 2**(max_level + 1)``, else ``ceil(L / 2**max_level)`` windows of
    level ``max_level``, the last one overlapping.

    Parameters
    ----------
    template : tuple
        ``(vlo, vhi, klo, khi)`` of :func:`minwarp_template`.
    max_level : int
        Largest window level ``J`` (windows of up to ``2**J`` columns); the
        search needs ``J + 1`` copies of the column distances.

    Returns
    -------
    start : ndarray, shape (W + 1,), int64
        Windows of snapshot column ``u`` are entries ``start[u] .. start[u + 1] - 1``.
    plane, level, v : ndarray, shape (N,), int64
        Plane, level and first current column (relative to ``alpha``) of each window.
    """
    if max_level < 0:
        raise ValueError(f"max_level must be >= 0, got {max_level}")
    vlo, vhi, klo, khi = (np.ascontiguousarray(t, dtype=np.int64) for t in template)
    n_planes = int(max(khi.max(initial=-1), klo.max(initial=-1))) + 1
    bound = int(np.maximum(khi - klo + 1, 0).sum())
    start = np.zeros(vlo.size + 1, np.int64)
    out = np.empty((3, bound), np.int64)
    n = _fill_windows(vlo, vhi, klo, khi, n_planes, int(max_level), start, out)
    return start, out[0, :n].copy(), out[1, :n].copy(), out[2, :n].copy()


@njit(cache=True)
def _fill_windows(vlo, vhi, klo, khi, n_planes, max_level, start, out):
    block = 1 << max_level
    n = 0
    for u in range(vlo.size):
        for k in range(n_planes):
            v = vlo[u]
            while v <= vhi[u]:
                if not (klo[u, v] <= k <= khi[u, v]):
                    v += 1
                    continue
                v0 = v
                while v <= vhi[u] and klo[u, v] <= k <= khi[u, v]:
                    v += 1
                length = v - v0
                if length <= 2 * block:
                    j = 0
                    while (2 << j) <= length and j < max_level:
                        j += 1
                    w = 1 << j
                    out[0, n], out[1, n], out[2, n] = k, j, v0
                    n += 1
                    if length > w:
                        out[0, n], out[1, n], out[2, n] = k, j, v0 + length - w
                        n += 1
                else:
                    off = 0
                    while off < length - block:
                        out[0, n], out[1, n], out[2, n] = k, max_level, v0 + off
                        n += 1
                        off += block
                    out[0, n], out[1, n], out[2, n] = k, max_level, v0 + length - block
                    n += 1
        start[u + 1] = n
    return n


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
