"""1D warping of horizon strips (Franz, Schölkopf, Mallot & Bülthoff 1998).

Franz et al. (1998, "Where did I take that snapshot? Scene-based homing by image
matching", Biological Cybernetics 79, 191-202) assume every
landmark at the same distance ``r`` from the snapshot position. A movement of
``d = rho * r`` along ``alpha`` with a rotation ``psi`` then moves the landmark
seen at snapshot azimuth ``x`` (``theta = x - alpha`` from the movement
direction) to azimuth ``alpha + atan2(sin theta, cos theta - rho)`` in the
snapshot's frame, i.e. to that minus ``psi`` in the current view's frame. The
current strip, sampled at these positions (linear interpolation, periodic),
predicts the snapshot; the hypothesis with the smallest sum of squared
differences wins. Conventions of ``alpha``, ``psi`` and the home direction as in
:mod:`bionav.homing.warping.search`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from bionav.geometry import wrap_angle
from bionav.homing.warping.search import WarpingResult, rho_grid


@njit(nogil=True, fastmath=True, cache=True)
def _warp1d_scores(snap, cur4, alphas, psis, rhos):
    """``cur4`` is the current strip tiled four times plus one sample (no wrap needed)."""
    width = snap.shape[0]
    n_a, n_r, n_p = alphas.shape[0], rhos.shape[0], psis.shape[0]
    out = np.empty((n_a, n_r, n_p))
    scale = width / (2.0 * np.pi)
    for t in range(n_a * n_r):
        ia = t // n_r
        il = t - ia * n_r
        alpha = alphas[ia]
        rho = rhos[il]
        pos = np.empty(width)
        for i in range(width):
            theta = 2.0 * np.pi * i / width - alpha
            # in (-W/2, 3W/2) columns; shifted by 2W so that it stays positive below
            pos[i] = (np.arctan2(np.sin(theta), np.cos(theta) - rho) + alpha) * scale + 2.0 * width
        for ip in range(n_p):
            shift = (psis[ip] * scale) % width
            total = 0.0
            for i in range(width):
                x = pos[i] - shift
                j0 = int(x)
                f = x - j0
                diff = snap[i] - (cur4[j0] + f * (cur4[j0 + 1] - cur4[j0]))
                total += diff * diff
            out[ia, il, ip] = total
    return out


def warping1d_scores(snapshot, current, *, alphas, psis, rhos):
    """1D-warping match values (sum of squared differences), fast kernel.

    Parameters
    ----------
    snapshot, current : ndarray, shape (W,)
        Horizon strips (:func:`~bionav.homing.imageops.horizon_strip`).
    alphas, psis : array_like
        Movement directions and rotations to test, radians.
    rhos : array_like
        Distance ratios ``d / r`` to test.

    Returns
    -------
    ndarray, shape (len(alphas), len(rhos), len(psis)), float64
    """
    s = np.ascontiguousarray(snapshot, dtype=np.float64)
    c = np.ascontiguousarray(current, dtype=np.float64)
    if s.ndim != 1 or s.shape != c.shape:
        raise ValueError(f"need two horizon strips of equal length, got shapes {s.shape} and {c.shape}")
    return _warp1d_scores(
        s,
        np.concatenate([c, c, c, c, c[:1]]),
        np.asarray(alphas, dtype=np.float64),
        np.asarray(psis, dtype=np.float64),
        np.asarray(rhos, dtype=np.float64),
    )


def warping1d(
    snapshot,
    current,
    *,
    n_alpha: int = 36,
    n_psi: int = 36,
    n_rho: int = 36,
    rho_max: float = 0.95,
) -> WarpingResult:
    """1D-warping home direction and visual compass of two horizon strips.

    Parameters
    ----------
    snapshot, current : ndarray, shape (W,)
        Horizon strips (column ``j`` at azimuth ``2 pi j / W`` CCW).
    n_alpha, n_psi : int
        Search steps over 360 degrees (Vardy's settings: 36 each).
    n_rho : int
        Distance-ratio steps over ``[0, rho_max]``.
    rho_max : float
        Largest distance ratio (< 1; 0.95 as in Vardy's settings).

    Returns
    -------
    WarpingResult
        ``home_angle`` in the current view's frame, ``psi`` the rotation
        ``heading(current) - heading(snapshot)``.
    """
    if n_alpha < 1 or n_psi < 1:
        raise ValueError(f"n_alpha and n_psi must be >= 1, got {n_alpha} and {n_psi}")
    alphas = 2.0 * np.pi * np.arange(n_alpha) / n_alpha
    psis = 2.0 * np.pi * np.arange(n_psi) / n_psi
    rhos = rho_grid(n_rho, rho_max)
    scores = warping1d_scores(snapshot, current, alphas=alphas, psis=psis, rhos=rhos)
    ia, il, ip = np.unravel_index(int(np.argmin(scores)), scores.shape)
    alpha, psi = float(alphas[ia]), float(wrap_angle(psis[ip]))
    home = float(wrap_angle(alpha + np.pi - psi))
    return WarpingResult(home, psi, alpha, float(rhos[il]), float(scores[ia, il, ip]), {})
