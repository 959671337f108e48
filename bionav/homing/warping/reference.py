"""Plain reference implementations of the warping searches (slow; for tests).

Every function here loops over the hypotheses and columns one by one and
recomputes the geometry from angles, independently of the templates and the
numba kernels, so that the fast path can be checked pair by pair.
"""

from __future__ import annotations

import numpy as np

from bionav.homing.warping.distance import column_distance_matrix


def allowed_planes(u: int, v: int, width: int, scales, thresholds) -> list[int]:
    """Scale planes allowed for snapshot column ``u`` and current column ``v``.

    Both columns are relative to the movement direction (see
    :mod:`~bionav.homing.warping.templates`). The landmark seen at
    ``theta = 2 pi u / W`` from the snapshot position appears from the current
    position at ``theta'`` between ``theta`` and ``pi`` (on the same side), with
    scale ratio ``sin(theta') / sin(theta)``.
    """
    theta = 2.0 * np.pi * u / width
    theta_p = 2.0 * np.pi * v / width
    scales = np.asarray(scales, dtype=np.float64)
    tau = np.asarray(thresholds, dtype=np.float64)
    if u == 0:  # focus of expansion: the landmark stays ahead and grows
        return [k for k in range(scales.size) if scales[k] >= 1.0 - 1e-9] if v == 0 else []
    if 2 * u == width:  # focus of contraction: it stays behind and shrinks
        return [k for k in range(scales.size) if scales[k] <= 1.0 + 1e-9] if v == u else []
    if 2 * u < width:
        reachable = u <= v and 2 * v <= width
    else:
        reachable = 2 * v >= width and v <= u
    if not reachable:
        return []
    sigma = abs(np.sin(theta_p)) / abs(np.sin(theta))
    lower = 0.0
    for k in range(scales.size):
        if lower <= sigma < tau[k]:
            return [k]
        lower = tau[k]
    return []


def minwarping_scores_reference(snapshot, current, *, a_cols, p_cols, thresholds):
    """Min-warping match values, one hypothesis and one column at a time.

    Parameters
    ----------
    snapshot, current : dict
        Scale-plane stacks.
    a_cols, p_cols : sequence of int
        Movement directions and rotations (columns).
    thresholds : array_like, shape (K,)

    Returns
    -------
    ndarray, shape (len(p_cols), len(a_cols)), float64
    """
    dist = column_distance_matrix(snapshot, current)
    scales = np.asarray(snapshot["scales"], dtype=np.float64)
    width = dist.shape[1]
    planes = {}
    out = np.zeros((len(p_cols), len(a_cols)))
    for ip, pc in enumerate(p_cols):
        for ia, ac in enumerate(a_cols):
            total = 0.0
            for i in range(width):
                u = (i - ac) % width
                best = np.inf
                for j in range(width):
                    v = (j + pc - ac) % width
                    if (u, v) not in planes:
                        planes[u, v] = allowed_planes(u, v, width, scales, thresholds)
                    for k in planes[u, v]:
                        best = min(best, dist[k, i, j])
                total += best
            out[ip, ia] = total
    return out


def warping2d_scores_reference(snapshot, current, *, a_cols, p_cols, rhos, thresholds):
    """2D-warping match values, one hypothesis and one column at a time.

    Returns
    -------
    ndarray, shape (len(rhos), len(p_cols), len(a_cols)), float64
    """
    dist = column_distance_matrix(snapshot, current)
    width = dist.shape[1]
    tau = np.asarray(thresholds, dtype=np.float64)
    out = np.zeros((len(rhos), len(p_cols), len(a_cols)))
    for il, rho in enumerate(rhos):
        for ip, pc in enumerate(p_cols):
            for ia, ac in enumerate(a_cols):
                alpha = 2.0 * np.pi * ac / width
                psi = 2.0 * np.pi * pc / width
                total = 0.0
                for i in range(width):
                    theta = 2.0 * np.pi * i / width - alpha
                    # landmark at unit distance, current position rho along alpha
                    lx, ly = np.cos(theta) - rho, np.sin(theta)
                    azimuth_snapframe = np.arctan2(ly, lx) + alpha
                    j = int(np.rint((azimuth_snapframe - psi) * width / (2.0 * np.pi))) % width
                    sigma = 1.0 / np.hypot(lx, ly)
                    k = min(int(np.sum(tau <= sigma)), tau.size - 1)
                    total += dist[k, i, j]
                out[il, ip, ia] = total
    return out


def warping1d_scores_reference(snapshot, current, *, alphas, psis, rhos):
    """1D-warping match values (sum of squared differences), plain loops.

    Parameters
    ----------
    snapshot, current : ndarray, shape (W,)
        Horizon strips.
    alphas, psis, rhos : sequence of float
        Hypotheses (radians, radians, distance ratios).

    Returns
    -------
    ndarray, shape (len(alphas), len(rhos), len(psis)), float64
    """
    s = np.asarray(snapshot, dtype=np.float64)
    c = np.asarray(current, dtype=np.float64)
    width = s.size
    out = np.zeros((len(alphas), len(rhos), len(psis)))
    for ia, alpha in enumerate(alphas):
        for il, rho in enumerate(rhos):
            for ip, psi in enumerate(psis):
                total = 0.0
                for i in range(width):
                    theta = 2.0 * np.pi * i / width - alpha
                    theta_p = np.arctan2(np.sin(theta), np.cos(theta) - rho)
                    pos = ((theta_p + alpha - psi) * width / (2.0 * np.pi)) % width
                    j0 = int(np.floor(pos))
                    f = pos - j0
                    pred = (1.0 - f) * c[j0 % width] + f * c[(j0 + 1) % width]
                    total += (s[i] - pred) ** 2
                out[ia, il, ip] = total
    return out
