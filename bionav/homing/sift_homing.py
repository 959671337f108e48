"""SIFT homing (thesis 5.1; Vardy & Möller 2005, Schatz 2006).

Conventions: canonical panoramas (:mod:`bionav.geometry`); every angle in
radians, azimuths counter-clockwise in the image frame, elevations positive
above the horizon. Snapshot and current view are assumed aligned (same
orientation); the home angle is returned in the current view's frame.

References
----------
Vardy, A. & Möller, R. (2005). Biologically plausible visual homing methods
based on optical flow techniques. Connection Science 17(1-2), 47-89.
doi:10.1080/09540090500140958
Lowe, D. G. (2004). Distinctive image features from scale-invariant
keypoints. IJCV 60(2), 91-110. doi:10.1023/B:VISI.0000029664.99615.94
"""

from __future__ import annotations

import numpy as np

from bionav.geometry import TWO_PI, PanoramaGeometry, wrap_angle
from bionav.homing.features import SiftFeatures

#: keypoints whose snapshot elevation is at most this (radians) are ignored (thesis 5.1.2)
MIN_ELEVATION = 0.01


def match_in_neighbourhood(
    current: SiftFeatures, snapshot: SiftFeatures, *, radius: float, width: int
) -> tuple[np.ndarray, np.ndarray]:
    """Nearest-descriptor matching limited to a pixel neighbourhood (eqs. 5.1-5.3).

    For every current keypoint ``p`` the snapshot keypoint with the smallest
    descriptor distance among those closer than ``radius`` pixels is chosen.
    The column distance wraps around the panorama (width ``width``).

    Returns
    -------
    current_idx, snapshot_idx : ndarray of int
        Matched index pairs (current keypoints without any candidate are dropped).
    """
    if len(current.xy) == 0 or len(snapshot.xy) == 0:
        empty = np.zeros(0, np.int64)
        return empty, empty
    dx = current.xy[:, None, 0] - snapshot.xy[None, :, 0]
    dx = (dx + width / 2.0) % width - width / 2.0
    dy = current.xy[:, None, 1] - snapshot.xy[None, :, 1]
    near = dx * dx + dy * dy < radius * radius
    d2 = current.sq_norms[:, None] + snapshot.sq_norms[None, :] - 2.0 * (current.descriptors @ snapshot.descriptors.T)
    d2 = np.where(near, d2, np.inf)
    best = np.argmin(d2, axis=1)
    ok = np.isfinite(d2[np.arange(len(best)), best])
    return np.flatnonzero(ok), best[ok]


def correspondence_home_angles(
    theta_s: np.ndarray, eps_s: np.ndarray, theta_c: np.ndarray, eps_c: np.ndarray
) -> np.ndarray:
    """Home angle of each landmark correspondence (thesis eq. 5.12, quadrant-safe).

    A landmark seen at azimuth ``theta_s`` and elevation ``eps_s`` from the
    snapshot and at ``theta_c``, ``eps_c`` from the current view (aligned
    frames, equal camera heights) lies at horizontal distances with ratio
    ``r = d_s / d_c = tan(eps_c) / tan(eps_s)`` (eq. 5.7). From
    ``L = S + d_s u(theta_s) = C + d_c u(theta_c)`` the home direction is that
    of ``u(theta_c) - r u(theta_s)``::

        beta = atan2(sin(theta_c) - r sin(theta_s), cos(theta_c) - r cos(theta_s))

    which equals eq. 5.12, ``theta_x - arctan(sin(dx) / (r - cos(dx))) + pi``
    with ``dx = theta_c - theta_s``, wherever ``r > cos(dx)``, and keeps the
    right quadrant elsewhere.

    Parameters
    ----------
    theta_s, eps_s, theta_c, eps_c : ndarray
        Radians; azimuths CCW, elevations positive above the horizon.

    Returns
    -------
    ndarray
        Home angles in radians (current view's frame), NaN where the
        correspondence is unusable: ``|eps_s| <= 0.01`` (thesis), or a distance
        ratio that is not positive and finite.
    """
    theta_s, eps_s, theta_c, eps_c = np.broadcast_arrays(theta_s, eps_s, theta_c, eps_c)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.tan(eps_c) / np.tan(eps_s)
        beta = np.arctan2(np.sin(theta_c) - r * np.sin(theta_s), np.cos(theta_c) - r * np.cos(theta_s))
    bad = (np.abs(eps_s) <= MIN_ELEVATION) | ~np.isfinite(r) | (r <= 0)
    return np.where(bad, np.nan, beta)


def combine_home_angles(angles: np.ndarray, *, method: str = "average", n_bins: int = 360, window: int = 10) -> float:
    """Overall home direction from per-correspondence home angles (thesis 5.1.3).

    Parameters
    ----------
    angles : ndarray, shape (K,)
        Home angles in radians (NaN entries ignored).
    method : {"average", "max"}
        ``"average"``: sum of the unit vectors, each weighted by the count of
        its histogram bin (eqs. 5.14-5.15: the histogram-weighted average
        vector). ``"max"``: centre of the cyclic window of ``window`` bins with
        the largest count (Schatz 2006).
    n_bins : int
        Histogram bins over 360 degrees.
    window : int
        Window width in bins for ``"max"``.

    Returns
    -------
    float
        Angle in radians in ``[-pi, pi)``, or NaN without any usable angle.
    """
    angles = np.asarray(angles, dtype=float)
    angles = angles[np.isfinite(angles)]
    if angles.size == 0:
        return float("nan")
    bins = np.floor((angles % TWO_PI) / TWO_PI * n_bins).astype(np.int64) % n_bins
    hist = np.bincount(bins, minlength=n_bins).astype(float)
    if method == "average":
        weights = hist[bins]
        v = np.array([np.sum(weights * np.cos(angles)), np.sum(weights * np.sin(angles))])
        if not np.any(v):
            return float("nan")
        return float(wrap_angle(np.arctan2(v[1], v[0])))
    if method == "max":
        sums = np.convolve(np.concatenate([hist, hist[: window - 1]]), np.ones(window), mode="valid")[:n_bins]
        start = int(np.argmax(sums))
        centre_bin = start + window / 2.0
        return float(wrap_angle(centre_bin / n_bins * TWO_PI))
    raise ValueError(f"unknown combination method {method!r}; use 'average' or 'max'")


def sift_home_vector(
    snapshot: SiftFeatures,
    current: SiftFeatures,
    *,
    geometry: PanoramaGeometry,
    search_radius: float,
    combine: str = "average",
    window: int = 10,
) -> tuple[float, int]:
    """SIFT home vector between two aligned panoramas (thesis 5.1).

    Parameters
    ----------
    snapshot, current : SiftFeatures
        Features of the snapshot and the current view.
    geometry : PanoramaGeometry
        Pixel geometry of both images.
    search_radius : float
        Neighbourhood radius ``q`` in pixels.
    combine : {"average", "max"}
        How the per-correspondence angles are combined (:func:`combine_home_angles`).

    Returns
    -------
    angle : float
        Home direction in radians, CCW in the current view's frame (NaN if no
        usable correspondence).
    n_used : int
        Number of correspondences that contributed.
    """
    ci, si = match_in_neighbourhood(current, snapshot, radius=search_radius, width=geometry.width)
    if ci.size == 0:
        return float("nan"), 0
    az = geometry.rad_per_column
    theta_c = current.xy[ci, 0] * az
    theta_s = snapshot.xy[si, 0] * az
    eps_c = (geometry.horizon_row - current.xy[ci, 1]) * geometry.rad_per_row
    eps_s = (geometry.horizon_row - snapshot.xy[si, 1]) * geometry.rad_per_row
    beta = correspondence_home_angles(theta_s, eps_s, theta_c, eps_c)
    used = int(np.sum(np.isfinite(beta)))
    return combine_home_angles(beta, method=combine, window=window), used
