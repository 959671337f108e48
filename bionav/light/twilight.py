"""Twilight: how bright the sky is for a sun near or below the horizon, and what stays polarized.

Model: single scattering in a spherical, exponential Rayleigh atmosphere with the Earth's shadow.
The radiance seen looking at the zenith, per unit extraterrestrial solar irradiance and phase
function, is

    L(h) = integral_0^top  beta(z) T_sun(z, h) T_view(z) dz,

* ``beta(z) = (tau_0 / H) exp(-z / H)``: scattering coefficient (vertical optical depth ``tau_0``,
  scale height ``H``);
* ``T_view(z) = exp(-tau_0 (1 - exp(-z / H)))``: the way down to the observer;
* ``T_sun(z, h) = exp(-integral_0^inf beta(r(t) - R) dt)`` along the sun's ray to the point at
  altitude ``z`` above the observer, ``r(t)^2 = (R + z)^2 + t^2 + 2 t (R + z) sin h`` (``h`` the
  sun's elevation, negative below the horizon); zero where the ray meets the ground (the point lies
  in the Earth's shadow, ``(R + z) cos h < R`` for ``h < 0``).

High sun: the plane-parallel closed form ``exp(-tau_0) (1 - exp(-tau_0 (m - 1))) / (m - 1)`` with
``m = 1 / sin h``. Below the horizon only the column above the shadow height
``z_s = R (1 / cos h - 1)`` (plus the screening layer where the grazing ray's optical depth
``tau_0 sqrt(2 pi R / H) exp(-z_t / H)`` exceeds one) is lit, and ``L`` falls about as
``exp(-z_s / H)``: orders of magnitude within a few degrees of depression. Real skies are brighter
in deep twilight than single scattering says (multiple scattering and the lit horizon), so the
sun elevation below which this model predicts a signal under a sensor's noise floor is a
*conservative* limit (a real sky may still give a little light there); refraction and ozone
absorption are not modelled.

Polarization: single scattering makes every e-vector perpendicular to the plane through the
observer's line of sight and the sun, wherever the sun is, so the pattern of a sun below the
horizon is :func:`bionav.light.rayleigh.rayleigh_polarization` with the sun's true (negative)
elevation. The zenith then lies about 90 degrees from the sun, where the degree is largest: the
zenith stays highly polarized in twilight (measured: Cronin, Warrant & Greiner 2006, Appl. Opt.
45:5582, doi:10.1364/AO.45.005582). What fails at dusk is the light, not the pattern.

Units: angles in radians (elevation above the horizon), lengths in km; radiances relative (per unit
extraterrestrial irradiance and phase function).
"""

from __future__ import annotations

import numpy as np

EARTH_RADIUS_KM = 6371.0
RAYLEIGH_SCALE_HEIGHT_KM = 8.0


def shadow_height_km(sun_elevation, *, earth_radius_km: float = EARTH_RADIUS_KM):
    """Height of the Earth's shadow above the observer's zenith, km (0 for a sun above the horizon).

    ``z_s = R (1 / cos h - 1)`` for ``h < 0`` (geometric, no refraction).
    """
    h = np.asarray(sun_elevation, float)
    return np.where(h < 0.0, earth_radius_km * (1.0 / np.cos(h) - 1.0), 0.0)


def twilight_zenith_radiance(sun_elevation, *, optical_depth: float = 0.25,
                             scale_height_km: float = RAYLEIGH_SCALE_HEIGHT_KM,
                             earth_radius_km: float = EARTH_RADIUS_KM, top_km: float = 150.0,
                             n_heights: int = 600, n_path: int = 3000):
    """Single-scattered zenith radiance for any sun elevation, the Earth's shadow included.

    Parameters
    ----------
    sun_elevation : float or ndarray, shape ``(S,)``
        Sun elevation above the horizon, radians (negative: below it).
    optical_depth : float
        Vertical optical depth ``tau_0`` of the scattering atmosphere in the sensor's band (Rayleigh:
        about 0.1 at 550 nm, 0.25 at 450 nm, 0.6 at 350 nm).
    scale_height_km : float
        Scale height ``H`` of the scatterers, km.
    earth_radius_km, top_km : float
        Earth radius and the top of the integration, km.
    n_heights, n_path : int
        Quadrature points along the line of sight and along each sun ray.

    Returns
    -------
    ndarray, shape like ``sun_elevation``
        ``L(h)`` (module docstring), relative radiance per unit extraterrestrial irradiance.

    Notes
    -----
    The trapezoid rule on ``n_heights`` altitudes (uniform to ``top_km``) and ``n_path`` points along
    each sun ray (uniform to the far side of the atmosphere).
    """
    h = np.atleast_1d(np.asarray(sun_elevation, float))
    tau0, H, R = float(optical_depth), float(scale_height_km), float(earth_radius_km)
    if not (tau0 > 0 and H > 0 and R > 0 and top_km > 0):
        raise ValueError("optical_depth, scale_height_km, earth_radius_km and top_km must be positive")
    z = np.linspace(0.0, float(top_km), int(n_heights))
    beta = tau0 / H * np.exp(-z / H)
    t_view = np.exp(-tau0 * (1.0 - np.exp(-z / H)))
    reach = 2.0 * np.sqrt(2.0 * R * top_km) + 2.0 * top_km  # longest way through the atmosphere
    t = np.linspace(0.0, reach, int(n_path))
    out = np.empty(h.shape)
    for i, hi in enumerate(h):
        rp = R + z[:, None]
        r = np.sqrt(rp**2 + t[None, :] ** 2 + 2.0 * t[None, :] * rp * np.sin(hi))
        alt = r - R
        tau = np.trapezoid(tau0 / H * np.exp(-np.clip(alt, 0.0, None) / H), t, axis=1)
        shadow = (rp[:, 0] * np.cos(hi) < R) & (hi < 0.0)
        t_sun = np.where(shadow, 0.0, np.exp(-tau))
        out[i] = np.trapezoid(beta * t_sun * t_view, z)
    return out.reshape(np.shape(sun_elevation)) if np.ndim(sun_elevation) else float(out[0])


def plane_parallel_zenith_radiance(sun_elevation, *, optical_depth: float = 0.25):
    """The high-sun limit of :func:`twilight_zenith_radiance` in closed form (flat, exponential atmosphere).

    ``exp(-tau_0) (1 - exp(-tau_0 (m - 1))) / (m - 1)`` with the air mass ``m = 1 / sin h``
    (``tau_0 exp(-tau_0)`` for the sun at the zenith). Radians; only for ``h > 0``.
    """
    h = np.asarray(sun_elevation, float)
    tau0 = float(optical_depth)
    m1 = 1.0 / np.sin(h) - 1.0
    safe = np.where(np.abs(m1) > 1e-9, m1, 1.0)
    return np.exp(-tau0) * np.where(np.abs(m1) > 1e-9, -np.expm1(-tau0 * safe) / safe, tau0)
