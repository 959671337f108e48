"""Sky polarization with the four neutral points (Berry, Dennis & Lee 2004).

Berry M V, Dennis M R, Lee R L Jr (2004), *Polarization singularities in the
clear sky*, New J. Phys. 6:162, doi:10.1088/1367-2630/6/1/162.

Multiple scattering splits each of the Rayleigh model's two index-+1
singularities (sun, anti-sun) into two index-+1/2 neutral points on the solar
meridian: Babinet (above the sun) and Brewster (below the sun), Arago and the
fourth point at their antipodes. In the stereographic projection of the sky
``zeta = tan(theta / 2) exp(i phi)`` (``theta`` zenith angle, ``phi`` azimuth)
the pattern is the quartic

    w(zeta) = -4 (zeta - z+)(zeta - z-)(zeta + 1/conj(z+))(zeta + 1/conj(z-))
              / ((1 + |zeta|^2)^2 |z+ + 1/conj(z+)| |z- + 1/conj(z-)|)

with the neutral points ``z± = tan((theta_sun ± delta/2) / 2) exp(i phi_sun)``
(angular separation ``delta``). In the sun-aligned projection (sun on the
positive real axis) the e-vector makes the angle ``arg(w) / 2`` with the real
axis (the projection is conformal, so this is also its angle to the local
meridian plus the point's azimuth), and the degree of polarization is
``|w| / (2 - |w|)``; for
``delta = 0`` is exactly the Rayleigh ``sin²γ / (1 + cos²γ)`` (tested).
Berry et al. additionally model the depolarization near the horizon; that
factor is not included here, the degree is scaled by ``max_degree`` as in the
Rayleigh model.
"""

from __future__ import annotations

import numpy as np

from bionav.light.rayleigh import local_frame


def berry_polarization(view, sun, *, neutral_point_separation: float, max_degree: float = 1.0):
    """Degree and e-vector of skylight with four neutral points.

    Parameters
    ----------
    view : ndarray, shape ``(..., 3)``
        Unit viewing directions in the sky frame (east-north-up), upper
        hemisphere.
    sun : ndarray, shape ``(3,)``
        Unit vector towards the sun.
    neutral_point_separation : float
        Angular distance ``delta`` between the two neutral points near the sun
        (Babinet-Brewster), radians; typically 0.3-0.6 rad (Berry et al. fit
        about 25-35 degrees). ``0`` reproduces the Rayleigh model.
    max_degree : float, optional
        Scale of the degree of polarization.

    Returns
    -------
    degree : ndarray, shape ``(...)``
    evector : ndarray, shape ``(..., 3)``
        Unit e-vectors tangent to the sky at ``view`` (axial).
    """
    view = np.asarray(view, float)
    sun = np.asarray(sun, float)
    phi_s = np.arctan2(sun[1], sun[0])
    theta_s = np.arccos(np.clip(sun[2], -1.0, 1.0))
    phi = np.arctan2(view[..., 1], view[..., 0])
    theta = np.arccos(np.clip(view[..., 2], -1.0, 1.0))
    # Sun-aligned stereographic coordinate (sun on the positive real axis).
    zeta = np.tan(theta / 2.0) * np.exp(1j * (phi - phi_s))
    half = neutral_point_separation / 2.0
    z_plus = np.tan((theta_s + half) / 2.0)  # Brewster point (below the sun)
    z_minus = np.tan((theta_s - half) / 2.0)  # Babinet point (above the sun)
    numerator = -4.0 * (zeta - z_plus) * (zeta - z_minus) * (zeta + 1.0 / z_plus) * (zeta + 1.0 / z_minus)
    denominator = (1.0 + np.abs(zeta) ** 2) ** 2 * abs(z_plus + 1.0 / z_plus) * abs(z_minus + 1.0 / z_minus)
    w = numerator / denominator
    modulus = np.clip(np.abs(w), 0.0, 1.0)
    degree = max_degree * modulus / (2.0 - modulus)
    # Angle of the polarization line in the sun-aligned projection plane,
    # then relative to the local meridian of each point (conformal map).
    chi = 0.5 * np.angle(w)
    beta = chi - (phi - phi_s)
    e_theta, e_phi = local_frame(view)
    evector = np.cos(beta)[..., None] * e_theta + np.sin(beta)[..., None] * e_phi
    return degree, evector
