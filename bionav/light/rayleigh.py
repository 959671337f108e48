"""Single-scattering Rayleigh model of skylight polarization.

Implements the textbook single-scattering (Rayleigh) sky used by Lambrinos et
al. (2000), *A mobile robot employing insect strategies for navigation*,
Robotics and Autonomous Systems 30:39-64, doi:10.1016/S0921-8890(99)00064-0,
and by the thesis, chapter 4:

* the e-vector (direction of oscillation of the electric field) of light
  scattered towards the observer from direction ``v`` is perpendicular to the
  scattering plane spanned by ``v`` and the sun direction ``s``,
  ``e ∝ s × v``;
* the degree of linear polarization is
  ``d = d_max * sin²γ / (1 + cos²γ)`` with the scattering angle ``γ``
  between ``v`` and ``s``: zero at the sun and anti-sun, ``d_max`` on the
  great circle 90 degrees from the sun.

Directions are unit vectors in the sky frame of :mod:`bionav.light.sun`
(east-north-up). E-vectors are axial: ``e`` and ``-e`` are the same.
"""

from __future__ import annotations

import numpy as np

# Depolarization factor of dry air at 550 nm (Young 1980, Appl. Opt. 19:3427).
AIR_DEPOLARIZATION = 0.0279


def _unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def scattering_angle(view, sun):
    """Angle between viewing directions and the sun, radians in ``[0, pi]``.

    Parameters
    ----------
    view : ndarray, shape ``(..., 3)``
        Unit viewing directions (from the observer towards the sky).
    sun : ndarray, shape ``(3,)`` or ``(..., 3)``
        Unit vector towards the sun.
    """
    c = np.sum(np.asarray(view, float) * np.asarray(sun, float), axis=-1)
    return np.arccos(np.clip(c, -1.0, 1.0))


def rayleigh_degree(gamma, *, max_degree: float = 1.0):
    """Degree of polarization ``max_degree * sin²γ / (1 + cos²γ)`` for scattering angles ``gamma`` (radians)."""
    c2 = np.cos(gamma) ** 2
    return max_degree * (1.0 - c2) / (1.0 + c2)


def max_degree_from_turbidity(turbidity: float, *, depolarization: float = AIR_DEPOLARIZATION) -> float:
    """Maximum degree of skylight polarization limited by haze.

    A first-order model: pure air scatters with maximum degree
    ``(1 - rho) / (1 + rho)`` (``rho`` the molecular depolarization factor,
    0.946 for air); with Preetham's turbidity ``T = (tau_air + tau_haze) /
    tau_air`` a fraction ``1/T`` of the scattered light comes from molecules
    and the haze part is treated as unpolarized, so ``d_max = (1 - rho) /
    ((1 + rho) T)``. ``T = 1.25`` (very clear) gives 0.76, ``T = 2`` gives 0.47,
    bracketing the 0.6-0.8 measured in clear skies (Horváth & Varjú 2004).

    Parameters
    ----------
    turbidity : float
        Preetham turbidity ``T >= 1`` (1 = pure air).
    depolarization : float, optional
        Molecular depolarization factor ``rho``.

    Returns
    -------
    float
        Maximum degree of linear polarization in ``[0, 1]``.
    """
    if turbidity < 1.0:
        raise ValueError(f"turbidity must be >= 1 (1 = pure air), got {turbidity}")
    return (1.0 - depolarization) / ((1.0 + depolarization) * turbidity)


def perpendicular(v):
    """Some unit vector perpendicular to each unit vector ``v`` (shape ``(..., 3)``)."""
    v = np.asarray(v, float)
    helper = np.where(np.abs(v[..., 2:3]) < 0.9, np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0]))
    return _unit(np.cross(helper, v))


def rayleigh_polarization(view, sun, *, max_degree: float = 1.0):
    """Degree and e-vector of single-scattered skylight.

    Parameters
    ----------
    view : ndarray, shape ``(..., 3)``
        Unit viewing directions, sky frame.
    sun : ndarray, shape ``(3,)``
        Unit vector towards the sun.
    max_degree : float, optional
        Degree at 90 degrees from the sun (see
        :func:`max_degree_from_turbidity`).

    Returns
    -------
    degree : ndarray, shape ``(...)``
        Degree of linear polarization in ``[0, max_degree]``.
    evector : ndarray, shape ``(..., 3)``
        Unit e-vectors, perpendicular to ``view`` and to the scattering plane
        (``s × v`` normalised); at the sun and anti-sun, where the degree is
        zero, an arbitrary perpendicular to ``view``.
    """
    view = np.asarray(view, float)
    sun = np.asarray(sun, float)
    e = np.cross(np.broadcast_to(sun, view.shape), view)
    norm = np.linalg.norm(e, axis=-1, keepdims=True)
    degenerate = norm < 1e-12
    e = np.where(degenerate, perpendicular(view), e / np.where(degenerate, 1.0, norm))
    degree = rayleigh_degree(scattering_angle(view, sun), max_degree=max_degree)
    return degree, e


def local_frame(view):
    """Local tangent frame of sky points: towards larger zenith angle and larger azimuth.

    Parameters
    ----------
    view : ndarray, shape ``(..., 3)``
        Unit directions, sky frame (not exactly the zenith).

    Returns
    -------
    e_theta, e_phi : ndarray, shape ``(..., 3)``
        ``e_theta`` points away from the zenith along the meridian, ``e_phi``
        along increasing (counter-clockwise) azimuth.
    """
    view = np.asarray(view, float)
    az = np.arctan2(view[..., 1], view[..., 0])
    zen = np.arccos(np.clip(view[..., 2], -1.0, 1.0))
    e_theta = np.stack([np.cos(zen) * np.cos(az), np.cos(zen) * np.sin(az), -np.sin(zen)], axis=-1)
    e_phi = np.stack([-np.sin(az), np.cos(az), np.zeros_like(az)], axis=-1)
    return e_theta, e_phi


def angle_in_frame(evector, x_axis, y_axis):
    """Axial angle of e-vectors in a plane frame, radians in ``[-pi/2, pi/2)``.

    The angle is measured from ``x_axis`` towards ``y_axis``.
    """
    a = np.arctan2(np.sum(evector * y_axis, axis=-1), np.sum(evector * x_axis, axis=-1))
    return (a + np.pi / 2.0) % np.pi - np.pi / 2.0
