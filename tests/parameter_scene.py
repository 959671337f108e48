"""A tiny analytic panoramic renderer for homing tests (smooth landmarks at known 3-D positions)."""

from __future__ import annotations

import numpy as np

from bionav.geometry import PanoramaGeometry


def render(position, landmarks, geometry: PanoramaGeometry, *, heading: float = 0.0) -> np.ndarray:
    """Canonical panorama seen from ``position = (x, y)`` (camera at z = 0) with ``heading`` (rad CCW).

    Each landmark ``(x, y, z, radius, amplitude)`` is a Gaussian blob of angular
    standard deviation ``atan(radius / distance)`` around its direction, on a
    background that is brighter towards the sky (infinitely far, no parallax).
    """
    theta = geometry.column_azimuths()[None, :] + heading
    eps = geometry.row_elevations()[:, None]
    u = np.stack(np.broadcast_arrays(np.cos(eps) * np.cos(theta), np.cos(eps) * np.sin(theta), np.sin(eps)), -1)
    img = 0.3 + 0.1 * np.sin(eps) * np.ones_like(theta)
    p = np.array([position[0], position[1], 0.0])
    for x, y, z, radius, amp in landmarks:
        d = np.array([x, y, z]) - p
        dist = np.linalg.norm(d)
        beta = np.arctan(radius / dist)
        alpha = np.arccos(np.clip(u @ (d / dist), -1.0, 1.0))
        img = img + amp * np.exp(-(alpha**2) / (2 * beta**2))
    return img


def ring_of_landmarks(n: int, *, distance: float, rng: np.random.Generator, z_range=(-1.0, 1.5)):
    """``n`` landmarks at random azimuths around the origin, horizontal distance jittered around ``distance``."""
    az = np.sort(rng.uniform(0, 2 * np.pi, n))
    dist = distance * rng.uniform(0.8, 1.25, n)
    z = rng.uniform(*z_range, n)
    radius = rng.uniform(0.3, 0.6, n)
    amp = rng.uniform(0.2, 0.6, n) * rng.choice([-1, 1], n)
    return [(d * np.cos(a), d * np.sin(a), zz, r, m) for a, d, zz, r, m in zip(az, dist, z, radius, amp)]
