"""Spectral daylight: sun, clear sky, clouds, and the irradiance they give on the ground.

A small, documented model, good enough to reproduce *why* a UV channel
separates sky from terrestrial objects (thesis ch. 6; Möller 2002) from the
clear noon sky down to the low evening sun:

* **Sun**: the measured ASTM G173-03 extraterrestrial spectrum (280-1200 nm,
  :mod:`bionav.light.measured_spectra`; a 5778 K black body scaled to the solar
  constant outside that range); direct beam attenuated by Beer-Lambert
  extinction along the relative air mass of Kasten & Young (1989).
* **Extinction**: Rayleigh optical depth of Hansen & Travis (1974),
  ``0.008569 lambda^-4 (1 + 0.0113 lambda^-2 + 0.00013 lambda^-4)`` (lambda in
  micrometres), aerosol of Angstrom turbidity ``beta`` and exponent ``alpha``
  (``beta lambda^-alpha``), and **ozone** (Bird & Riordan 1986 coefficients
  times the column ``SkyState.ozone_atm_cm``; the Huggins band below 340 nm and
  the Chappuis band around 600 nm) along the ozone-layer air mass
  ``(1 + h/R) / sqrt(sin^2 h_s + 2 h/R)`` (layer at h = 22 km). Ozone lies above
  the scattering air, so it filters the sunlight once, before it is scattered:
  at a low sun its long slant path through the Chappuis band takes orange and
  red out of the whole sky, which keeps the dusk sky blue (Hulburt 1953,
  doi:10.1364/JOSA.43.000113). Water vapour (720, 820, 940 nm) and the oxygen
  A band (760 nm) absorb in the R and IR channels (Bird & Riordan's
  transmittance laws, :func:`gas_transmittance`; precipitable water
  ``SkyState.precipitable_water_cm``).
* **Clear sky**: single scattering in two stacked plane-parallel layers viewed
  from the ground: the free troposphere and stratosphere (pure Rayleigh, the
  molecules above ``AEROSOL_LAYER_M``) over a boundary layer holding the rest of
  the molecules and all the aerosol. In each homogeneous layer (Liou 2002,
  *An Introduction to Atmospheric Radiation*, eq. 6.3.5)
  ``L = E_in P_eff(gamma) / (4 pi) * m_v / (m_v - m_s) * (exp(-tau m_s) - exp(-tau m_v))``,
  with ``E_in`` the sunlight reaching the layer top and the upper layer's light
  attenuated by the lower one on its way down; Rayleigh phase function
  ``3/4 (1 + cos^2 gamma)``, Henyey-Greenstein aerosol phase function (g = 0.7,
  single-scattering albedo 0.9). With the aerosol at the bottom, the blue and UV
  light scattered high up at a low sun is not dimmed by the long slant path
  through the hazy boundary layer, as in the real evening sky.
* **Multiple scattering**: single scattering alone loses the light that is
  scattered again on its way down, a large share of the UV and blue sky at a low
  sun. bionav closes the energy budget with Bird & Riordan's (1986) SPCTRAL2
  diffuse irradiance (half of all Rayleigh-scattered light reaches the ground,
  the forward fraction of the aerosol-scattered light, ground-sky reflections,
  their short-wave correction; :func:`diffuse_irradiance_bird`, validated there
  against rigorous radiative transfer and measurements): the irradiance the
  single-scattering sky lacks is spread over the sky in proportion to each line
  of sight's scattering depth ``1 - exp(-tau m_v)``. The sky's angular structure
  (sun aureole, horizon, colour across the sky) stays that of single scattering.
* **Clouds**: spectrally grey scatterers. A cloud of optical depth ``tau_c`` seen
  from below has radiance ``E_top mu_s T(tau_c) / pi`` with the two-stream
  diffuse transmittance ``T = 1 / (1 + 0.75 (1 - g) tau_c)``, g = 0.85; broken
  clouds add sunlit sides ``(1 - T)`` in proportion to the clear fraction;
  ``E_top`` is the sun attenuated by ozone and the air above the cloud base
  (80 % of the Rayleigh and 30 % of the aerosol optical depth), and the air
  below adds a little blue path radiance. So overcast skies are grey and dim,
  while cloud cover *flattens* the sky spectrum relative to the blue sky.
* **Spatial clouds**: a cloud layer at height ``cloud_height_m`` carrying a
  smooth random field (sum of random plane waves), thresholded to the requested
  cover fraction, drifting with the wind (see :class:`CloudLayer`). A line of
  sight whose footprint on the layer spans several clouds sees their *fraction*
  ``f`` (:func:`cloud_fraction`), each of the full optical depth: radiances and
  the direct beam are averaged over the footprint (``(1 - f) + f exp(-tau m)``),
  not computed from the footprint's mean optical depth, which would hide a low
  sun behind a 10 % cover (``1 - exp(-x)`` is concave).

Frames: directions are unit vectors in a local east-north-up frame (x east,
y north, z up). Azimuths in this module are radians counter-clockwise from
east (x), elevations radians above the horizon.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from bionav.geometry import direction_from_angles
from bionav.light.bands import WAVELENGTHS_NM, band_integrate
from bionav.light.clouds import CloudLayer
from bionav.light.materials import landscape_albedo
from bionav.light.sun import BIELEFELD_LAT_DEG, BIELEFELD_LON_DEG, parse_time, sun_position

_H = 6.62607015e-34
_C = 2.99792458e8
_KB = 1.380649e-23
_SOLID_ANGLE_FACTOR = (6.957e8 / 1.495978707e11) ** 2  # (R_sun / AU)^2
_HG_G_AEROSOL = 0.7
_AEROSOL_SSA = 0.9
_CLOUD_G = 0.85
_EARTH_RADIUS_M = 6.371e6
_OZONE_LAYER_M = 22_000.0
#: Top of the boundary layer that holds the aerosol (m); the molecules above it form the upper layer.
AEROSOL_LAYER_M = 1500.0
#: Scale height of the molecular atmosphere (m).
RAYLEIGH_SCALE_HEIGHT_M = 8000.0
#: Grey ground albedo of :meth:`Illumination.on_surface` when no ground spectrum is given (the sky's
#: ground reflections use the spectral :func:`bionav.light.materials.landscape_albedo`).
GROUND_ALBEDO = 0.15


def black_body_sun(wavelengths_nm=WAVELENGTHS_NM, *, temperature_k: float = 5778.0) -> np.ndarray:
    """Extraterrestrial irradiance of a black-body sun, W m^-2 nm^-1, shape ``(L,)`` (Planck's law at 1 AU)."""
    wl = np.asarray(wavelengths_nm, dtype=float) * 1e-9
    radiance = 2 * _H * _C**2 / wl**5 / np.expm1(_H * _C / (wl * _KB * temperature_k))  # W m^-2 sr^-1 m^-1
    return np.pi * radiance * _SOLID_ANGLE_FACTOR * 1e-9


def solar_spectrum(wavelengths_nm=WAVELENGTHS_NM) -> np.ndarray:
    """Extraterrestrial solar spectral irradiance at 1 AU, W m^-2 nm^-1, shape ``(L,)``.

    The measured ASTM G173-03 spectrum (cell means on the given grid) within
    280-1200 nm, a 5778 K black body (:func:`black_body_sun`) outside it.
    """
    from bionav.light.measured_spectra import extraterrestrial_solar_spectrum

    measured = extraterrestrial_solar_spectrum(wavelengths_nm)
    return np.where(np.isnan(measured), black_body_sun(wavelengths_nm), measured)


def gas_transmittance(state: "SkyState", wavelengths_nm, elevation) -> np.ndarray:
    """Transmittance of a beam from ``elevation`` through ozone, water vapour and mixed gases, shape ``(L,)``.

    Bird & Riordan (1986), eqs. 4-6: ozone ``exp(-a_o O3 M_o)`` along the ozone-layer
    air mass :func:`ozone_air_mass`; water vapour
    ``exp(-0.2385 a_w W M / (1 + 20.07 a_w W M)^0.45)`` and mixed gases
    ``exp(-1.41 a_u M / (1 + 118.93 a_u M)^0.45)`` along the air mass ``M`` of
    :func:`relative_air_mass` (sea level), with the column ``state.ozone_atm_cm``
    and precipitable water ``state.precipitable_water_cm``.
    """
    from bionav.light.measured_spectra import gas_absorption

    a = gas_absorption(wavelengths_nm)
    m = float(relative_air_mass(elevation))
    aw = a["water_vapor"] * state.precipitable_water_cm * m
    au = a["mixed_gases"] * m
    return np.exp(-a["ozone"] * state.ozone_atm_cm * float(ozone_air_mass(elevation))
                  - 0.2385 * aw / (1 + 20.07 * aw) ** 0.45 - 1.41 * au / (1 + 118.93 * au) ** 0.45)


def ozone_air_mass(elevation) -> np.ndarray:
    """Air mass of the ozone layer (22 km) for an elevation in radians: ``(1 + h/R) / sqrt(sin^2 e + 2 h/R)``."""
    ratio = _OZONE_LAYER_M / _EARTH_RADIUS_M
    s = np.sin(np.maximum(np.asarray(elevation, dtype=float), np.deg2rad(-1.0)))
    return (1 + ratio) / np.sqrt(s * s + 2 * ratio)


def rayleigh_optical_depth(wavelengths_nm=WAVELENGTHS_NM) -> np.ndarray:
    """Vertical Rayleigh optical depth at sea level (Hansen & Travis 1974), shape ``(L,)``."""
    lam = np.asarray(wavelengths_nm, dtype=float) / 1000.0
    return 0.008569 * lam**-4 * (1 + 0.0113 * lam**-2 + 0.00013 * lam**-4)


def aerosol_optical_depth(wavelengths_nm=WAVELENGTHS_NM, *, beta: float = 0.1, alpha: float = 1.3) -> np.ndarray:
    """Angstrom aerosol optical depth ``beta * lambda_um^-alpha``, shape ``(L,)``."""
    lam = np.asarray(wavelengths_nm, dtype=float) / 1000.0
    return beta * lam ** (-alpha)


def relative_air_mass(elevation) -> np.ndarray:
    """Kasten & Young (1989) relative optical air mass for an elevation in radians (clipped at -1 deg)."""
    h = np.maximum(np.asarray(elevation, dtype=float), np.deg2rad(-1.0))
    h_deg = np.rad2deg(h)
    return 1.0 / (np.sin(h) + 0.50572 * (h_deg + 6.07995) ** -1.6364)


@dataclass(frozen=True)
class SkyState:
    """Illumination conditions: sun position, aerosol, clouds.

    Parameters
    ----------
    sun_elevation : float
        Radians above the horizon.
    sun_azimuth : float
        Radians counter-clockwise from east.
    turbidity : float
        Angstrom ``beta`` (0.05 very clear .. 0.3 hazy).
    angstrom_alpha : float
        Angstrom exponent.
    ozone_atm_cm : float
        Ozone column in atm-cm (Dobson units / 1000; mid-latitude summer about 0.3-0.35).
    precipitable_water_cm : float
        Precipitable water in cm (mid-latitude summer 1-3).
    clouds : CloudLayer
        Cloud layer (``cover = 0`` for a clear sky).
    time_s : float
        Time since the cloud field's epoch (drift), seconds.
    """

    sun_elevation: float
    sun_azimuth: float = 0.0
    turbidity: float = 0.1
    angstrom_alpha: float = 1.3
    ozone_atm_cm: float = 0.3
    precipitable_water_cm: float = 1.5
    clouds: CloudLayer = CloudLayer()
    time_s: float = 0.0

    @classmethod
    def from_time(cls, time, *, latitude_deg=None, longitude_deg=None, **kwargs) -> "SkyState":
        """Sky state with the sun where it stands at ``time`` (see :func:`bionav.light.sun.sun_position`).

        ``time`` must carry its time zone; the place defaults to Bielefeld
        (:data:`~bionav.light.sun.BIELEFELD_LAT_DEG`, :data:`~bionav.light.sun.BIELEFELD_LON_DEG`).
        """
        sun = sun_position(
            parse_time(time, what="the sky's time", naive_utc=False),
            latitude_deg=BIELEFELD_LAT_DEG if latitude_deg is None else latitude_deg,
            longitude_deg=BIELEFELD_LON_DEG if longitude_deg is None else longitude_deg,
        )
        return cls(sun_elevation=sun.elevation, sun_azimuth=sun.azimuth, **kwargs)

    def with_clouds(self, **changes) -> "SkyState":
        """A copy with cloud-field parameters changed."""
        return replace(self, clouds=replace(self.clouds, **changes))

    @property
    def sun_direction(self) -> np.ndarray:
        """Unit vector towards the sun, shape ``(3,)``."""
        return direction_from_angles(self.sun_azimuth, self.sun_elevation)


def _optical_depths(state: SkyState, wl):
    tr = rayleigh_optical_depth(wl)
    ta = aerosol_optical_depth(wl, beta=state.turbidity, alpha=state.angstrom_alpha)
    return tr, ta


def _sun_transmittance(state: SkyState, wl, *, rayleigh=1.0, aerosol=1.0) -> np.ndarray:
    """Transmittance of the sun's beam through the gases and fractions of the Rayleigh and aerosol depths, ``(L,)``."""
    tr, ta = _optical_depths(state, wl)
    m_s = float(relative_air_mass(state.sun_elevation))
    return np.exp(-(rayleigh * tr + aerosol * ta) * m_s) * gas_transmittance(state, wl, state.sun_elevation)


def _layer_path(tau, m_s, m_v):
    """``m_v / (m_v - m_s) * (exp(-tau m_s) - exp(-tau m_v))``: single scattering of a homogeneous layer."""
    delta = m_v - m_s
    small = np.abs(delta) < 1e-6
    safe = np.where(small, 1.0, delta)
    return m_v * np.where(small, tau * np.exp(-tau * m_s), np.exp(-tau * m_s) * -np.expm1(-tau * safe) / safe)


def _single_scattering(state: SkyState, d, wl) -> np.ndarray:
    tr, ta = _optical_depths(state, wl)
    f_low = 1.0 - np.exp(-AEROSOL_LAYER_M / RAYLEIGH_SCALE_HEIGHT_M)
    tau_up = tr * (1 - f_low)
    tau_low = tr * f_low + ta
    e_in = solar_spectrum(wl) * _sun_transmittance(state, wl, rayleigh=0.0, aerosol=0.0)  # gases only
    m_s = float(relative_air_mass(state.sun_elevation))
    m_v = relative_air_mass(np.arcsin(np.clip(d[..., 2], -1, 1)))[..., None]
    cos_g = np.clip(d @ state.sun_direction, -1, 1)[..., None]
    p_r = 0.75 * (1 + cos_g**2)
    g = _HG_G_AEROSOL
    p_a = (1 - g**2) / (1 + g**2 - 2 * g * cos_g) ** 1.5
    p_low = (tr * f_low * p_r + _AEROSOL_SSA * ta * p_a) / tau_low
    upper = p_r * _layer_path(tau_up, m_s, m_v) * np.exp(-tau_low * m_v)
    lower = p_low * np.exp(-tau_up * m_s) * _layer_path(tau_low, m_s, m_v)
    return e_in / (4 * np.pi) * (upper + lower)


_MS_CACHE: dict = {}


def diffuse_irradiance_bird(state: SkyState, wavelengths_nm=WAVELENGTHS_NM) -> np.ndarray:
    """Clear-sky diffuse irradiance on a horizontal plane, multiple scattering included, W m^-2 nm^-1, ``(L,)``.

    Bird & Riordan (1986), eqs. 7-13 (SPCTRAL2): the Rayleigh part
    ``0.5 E0 cos Z T_gas T_aa (1 - T_r^0.95)`` -- half of all light the molecules
    scatter reaches the ground, whatever the order of scattering -- the aerosol
    part ``E0 cos Z T_gas T_aa T_r^1.5 (1 - T_as) F_s`` with the forward fraction
    ``F_s`` of a Henyey-Greenstein aerosol (asymmetry g = 0.7, single-scattering
    albedo 0.9, as in :func:`clear_sky_radiance`), and the ground-sky
    reflections ``(E_dir cos Z + I_r + I_a) r_s a_g / (1 - r_s a_g)``, all times
    Bird & Riordan's short-wave correction ``(lambda_um + 0.55)^1.8`` below 450 nm.
    Rayleigh depth of Hansen & Travis, aerosol of Angstrom, gases of
    :func:`gas_transmittance`; spectral ground albedo
    :func:`bionav.light.materials.landscape_albedo` (a green landscape: dark in
    the UV, bright in the near infrared).
    """
    wl = np.asarray(wavelengths_nm, dtype=float)
    el = state.sun_elevation
    if el <= 0:
        return np.zeros_like(wl)
    cos_z = np.sin(el)
    tr, ta = _optical_depths(state, wl)
    e0 = solar_spectrum(wl)
    alg = np.log(1 - _HG_G_AEROSOL)
    afs = alg * (1.459 + alg * (0.1595 + alg * 0.4129))
    bfs = alg * (0.0783 + alg * (-0.3824 - alg * 0.5874))

    def parts(m, gas, mu):
        t_r = np.exp(-tr * m)
        t_aa = np.exp(-(1 - _AEROSOL_SSA) * ta * m)
        t_as = np.exp(-_AEROSOL_SSA * ta * m)
        f_s = 1 - 0.5 * np.exp((afs + bfs * mu) * mu)
        return t_r, t_aa, t_as, f_s, gas

    m = float(relative_air_mass(el))
    t_r, t_aa, t_as, f_s, gas = parts(m, gas_transmittance(state, wl, el), cos_z)
    i_r = 0.5 * e0 * cos_z * gas * t_aa * (1 - t_r**0.95)
    i_a = e0 * cos_z * gas * t_aa * t_r**1.5 * (1 - t_as) * f_s
    direct_h = e0 * cos_z * gas * t_r * np.exp(-ta * m)
    m2 = 1.8  # the sky's reflectance for light from the ground, at the effective air mass 1.8
    t_r2, t_aa2, t_as2, f_s2, gas2 = parts(m2, gas_transmittance(state, wl, np.arcsin(1 / m2)), 1 / m2)
    r_s = gas2 * t_aa2 * (0.5 * (1 - t_r2) + (1 - f_s2) * t_r2 * (1 - t_as2))
    a_g = landscape_albedo(wl)
    i_g = (direct_h + i_r + i_a) * r_s * a_g / (1 - r_s * a_g)
    lam = wl / 1000.0
    corr = np.where(lam <= 0.45, (lam + 0.55) ** 1.8, 1.0)
    return (i_r + i_a + i_g) * corr


def _multiple_scattering_source(state: SkyState, wl) -> tuple[np.ndarray, np.ndarray]:
    """Radiance scale and the tau of the path shape of the multiple-scattering term (cached per sun and air)."""
    key = (state.sun_elevation, state.turbidity, state.angstrom_alpha, state.ozone_atm_cm,
           state.precipitable_water_cm, wl.tobytes())
    hit = _MS_CACHE.get(key)
    if hit is not None:
        return hit
    n_el, n_az = 8, 24  # the quadrature of :func:`illumination`
    el = (np.arange(n_el) + 0.5) * (np.pi / 2) / n_el
    az = (np.arange(n_az) + 0.5) * 2 * np.pi / n_az
    ee, aa = np.meshgrid(el, az, indexing="ij")
    flat = replace(state, sun_azimuth=0.0, clouds=CloudLayer())
    rad = _single_scattering(flat, direction_from_angles(aa, ee), wl)
    weight = (np.sin(ee) * np.cos(ee) * (np.pi / 2 / n_el) * (2 * np.pi / n_az))[..., None]
    e_single = np.sum(rad * weight, axis=(0, 1))
    tr, ta = _optical_depths(state, wl)
    tau = tr + ta
    shape = -np.expm1(-tau * relative_air_mass(ee)[..., None])
    norm = np.sum(shape * weight, axis=(0, 1))
    scale = np.maximum(diffuse_irradiance_bird(state, wl) - e_single, 0.0) / norm
    out = (scale, tau)
    if len(_MS_CACHE) > 256:
        _MS_CACHE.clear()
    _MS_CACHE[key] = out
    return out


def clear_sky_radiance(state: SkyState, directions, wavelengths_nm=WAVELENGTHS_NM, *,
                       multiple_scattering: bool = True) -> np.ndarray:
    """Clear-sky spectral radiance, W m^-2 sr^-1 nm^-1: two-layer single scattering plus higher orders.

    Parameters
    ----------
    state : SkyState
    directions : array_like, shape (..., 3)
        Unit viewing directions (east-north-up); directions below the horizon
        are treated as looking 1 degree below it (horizon haze).
    wavelengths_nm : array_like, shape (L,)
    multiple_scattering : bool
        Add the higher orders (default); ``False`` gives single scattering only.

    Returns
    -------
    ndarray, shape (..., L)
        Zero when the sun is more than 1 degree below the horizon (no twilight model).

    Notes
    -----
    Single scattering in two stacked homogeneous layers (module docstring; Liou
    2002, eq. 6.3.5 per layer). Higher orders: the diffuse irradiance that the
    single-scattering sky lacks against Bird & Riordan's (1986) energy budget
    (:func:`diffuse_irradiance_bird`) is spread over the sky in proportion to
    each line of sight's scattering depth ``1 - exp(-tau m_v)`` (brighter
    towards the horizon), so the hemispheric integral of the sky equals that
    budget wherever single scattering falls short of it (the UV and blue,
    most at a low sun).
    """
    wl = np.asarray(wavelengths_nm, dtype=float)
    d = np.asarray(directions, dtype=float)
    if state.sun_elevation <= np.deg2rad(-1.0):
        return np.zeros(d.shape[:-1] + wl.shape)
    single = _single_scattering(state, d, wl)
    if not multiple_scattering or state.sun_elevation <= 0:
        return single
    scale, tau = _multiple_scattering_source(state, wl)
    m_v = relative_air_mass(np.arcsin(np.clip(d[..., 2], -1, 1)))[..., None]
    return single + scale * -np.expm1(-tau * m_v)


def cloud_fraction(state: SkyState, directions, *, origin_m=(0.0, 0.0)) -> np.ndarray:
    """Fraction of each line of sight's footprint on the cloud layer that is cloud, shape ``(...)``, in [0, 1].

    :meth:`bionav.light.clouds.CloudLayer.density_at` of the state's layer at
    its ``time_s``; zero for a layer of zero optical depth (no clouds to see).

    Parameters
    ----------
    state : SkyState
        Its ``clouds`` layer and ``time_s`` (drift).
    directions : array_like, shape (..., 3)
        Unit viewing directions (east-north-up).
    origin_m : tuple of float
        Observer position (east, north) in metres.

    Returns
    -------
    ndarray, shape (...)
        Cloud fraction in [0, 1].
    """
    d = np.asarray(directions, dtype=float)
    if state.clouds.optical_depth <= 0:
        return np.zeros(d.shape[:-1])
    return state.clouds.density_at(d, time_s=state.time_s, origin_m=origin_m)


def _cloud_transmittance(tau_c):
    return 1.0 / (1.0 + 0.75 * (1 - _CLOUD_G) * np.asarray(tau_c, dtype=float))


def sky_radiance(state: SkyState, directions, wavelengths_nm=WAVELENGTHS_NM, *, origin_m=(0.0, 0.0)) -> np.ndarray:
    """Spectral sky radiance with clouds, W m^-2 sr^-1 nm^-1, shape ``(..., L)``.

    Cloud-free lines of sight get :func:`clear_sky_radiance`; cloudy ones the
    grey cloud radiance of the module docstring. A line of sight sees the
    fraction ``f`` of its footprint covered by cloud (:func:`cloud_fraction`),
    each cloud of the layer's full optical depth ``tau``; the radiances are
    averaged over the footprint: ``(1 - f o) L_clear + f o L_cloud`` with the
    opacity ``o = 1 - exp(-tau / 2)`` of one cloud (averaging the optical depth
    first would turn a distant 10 % cover into a uniform veil of a tenth of the
    depth, far more opaque on average: ``1 - exp(-x)`` is concave).
    """
    wl = np.asarray(wavelengths_nm, dtype=float)
    d = np.asarray(directions, dtype=float)
    clear = clear_sky_radiance(state, d, wl)
    if state.clouds.cover <= 0:
        return clear
    frac = cloud_fraction(state, d, origin_m=origin_m)[..., None]
    depth = float(state.clouds.optical_depth)
    opacity = frac * -np.expm1(-0.5 * depth)
    tr, ta = _optical_depths(state, wl)
    mu_s = max(np.sin(state.sun_elevation), 0.0)
    e_top = solar_spectrum(wl) * _sun_transmittance(state, wl, rayleigh=0.8, aerosol=0.3)
    t_c = _cloud_transmittance(depth)
    sides = (1.0 - state.clouds.cover) * (1.0 - t_c)
    # light reflected by the ground and back down by the cloud base (reflectance (1 - T) where cloud):
    # the green landscape's bright near infrared brightens the cloud base there, not in the UV
    base = e_top * mu_s * (t_c + sides) / np.pi / (1.0 - landscape_albedo(wl) * state.clouds.cover * (1.0 - t_c))
    below = 0.2 * clear  # the air between the observer and the cloud base
    cloud = base * np.exp(-(0.2 * tr + 0.7 * ta) * relative_air_mass(np.arcsin(np.clip(d[..., 2], 0.02, 1)))[..., None]) + below
    return (1 - opacity) * clear + opacity * cloud


@dataclass(frozen=True)
class Illumination:
    """Irradiance spectra at the ground (W m^-2 nm^-1).

    Attributes
    ----------
    direct_normal : ndarray, shape (L,)
        Direct solar beam on a plane facing the sun (after cloud attenuation).
    diffuse_horizontal : ndarray, shape (L,)
        Sky (and cloud) irradiance on a horizontal plane.
    sun_direction : ndarray, shape (3,)
    """

    direct_normal: np.ndarray
    diffuse_horizontal: np.ndarray
    sun_direction: np.ndarray

    @property
    def global_horizontal(self) -> np.ndarray:
        """Direct plus diffuse irradiance on a horizontal plane, shape ``(L,)``."""
        return self.direct_normal * max(self.sun_direction[2], 0.0) + self.diffuse_horizontal

    def on_surface(self, normals, *, sunlit=1.0, ground_albedo=GROUND_ALBEDO) -> np.ndarray:
        """Irradiance on tilted surfaces, shape ``(..., L)``.

        Parameters
        ----------
        normals : array_like, shape (..., 3)
            Unit surface normals (east-north-up).
        sunlit : float or array_like, shape (...)
            1 in the sun, 0 in shadow (or any fraction: penumbra, foliage).
        ground_albedo : float or array_like, shape (L,)
            Albedo of the ground that lights surfaces tilted towards it: grey, or
            a reflectance spectrum on the illumination's wavelengths (green
            ground reflects several times more near infrared than UV).

        Notes
        -----
        Isotropic diffuse sky and ground (view factors ``(1 +- n_z)/2``).
        """
        n = np.asarray(normals, dtype=float)
        cos_i = np.clip(n @ self.sun_direction, 0, None)[..., None]
        sky_view = (1 + n[..., 2:3]) / 2
        lit = np.asarray(sunlit, dtype=float)[..., None]
        return (lit * cos_i * self.direct_normal + sky_view * self.diffuse_horizontal
                + (1 - sky_view) * ground_albedo * self.global_horizontal)


def illumination(state: SkyState, wavelengths_nm=WAVELENGTHS_NM, *, origin_m=(0.0, 0.0),
                 n_elevation: int = 8, n_azimuth: int = 24) -> Illumination:
    """Direct and diffuse irradiance at the ground under a sky state.

    The diffuse part integrates :func:`sky_radiance` over the upper hemisphere
    (midpoint rule, ``n_elevation x n_azimuth`` cells, cosine weighted), so it
    is consistent with what a sensor pointed at the sky sees. The direct beam
    passes the cloud fraction ``f`` of the sun's footprint (:func:`cloud_fraction`)
    attenuated by the layer's optical depth ``tau`` along the air mass ``m`` and
    the rest unattenuated: ``(1 - f) + f exp(-tau m)``.
    """
    wl = np.asarray(wavelengths_nm, dtype=float)
    if state.sun_elevation <= np.deg2rad(-1.0):
        z = np.zeros_like(wl)
        return Illumination(z, z, state.sun_direction)
    el = (np.arange(n_elevation) + 0.5) * (np.pi / 2) / n_elevation
    az = (np.arange(n_azimuth) + 0.5) * 2 * np.pi / n_azimuth
    ee, aa = np.meshgrid(el, az, indexing="ij")
    dirs = direction_from_angles(aa, ee)
    rad = sky_radiance(state, dirs, wl, origin_m=origin_m)
    d_omega = np.cos(ee) * (np.pi / 2 / n_elevation) * (2 * np.pi / n_azimuth)
    weight = (np.sin(ee) * d_omega)[..., None]
    diffuse = np.sum(rad * weight, axis=(0, 1))
    t_cloud = float(state.clouds.transmittance_at(state.sun_direction, air_mass=relative_air_mass(state.sun_elevation),
                                                  time_s=state.time_s, origin_m=origin_m))
    direct = solar_spectrum(wl) * _sun_transmittance(state, wl) * t_cloud
    return Illumination(direct, diffuse, state.sun_direction)


def band_sky_radiance(state: SkyState, directions, *, origin_m=(0.0, 0.0)) -> np.ndarray:
    """Sky radiance integrated over the five channels, shape ``(..., 5)``."""
    return band_integrate(sky_radiance(state, directions, WAVELENGTHS_NM, origin_m=origin_m))
