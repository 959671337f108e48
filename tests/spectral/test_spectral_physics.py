"""Physics of the five-channel sensor model against closed forms and known facts."""

from dataclasses import replace

import numpy as np
import pytest

from bionav.geometry import direction_from_angles
from bionav.light.bands import CHANNELS, FWHM_NM, PEAK_NM, band_integrate, band_sensitivity, feature_subsets
from bionav.light.clouds import CloudLayer
from bionav.light.daylight import (
    SkyState,
    clear_sky_radiance,
    cloud_fraction,
    diffuse_irradiance_bird,
    gas_transmittance,
    illumination,
    ozone_air_mass,
    rayleigh_optical_depth,
    relative_air_mass,
    sky_radiance,
    solar_spectrum,
)
from bionav.light.materials import MATERIALS, landscape_albedo
from bionav.spectral.sensor_model import LogSensorModel


def test_band_peaks_and_bandwidths_match_table_6_1():
    wl = np.arange(250.0, 1200.0, 0.1)
    s = band_sensitivity(wl)
    for row, peak, fwhm in zip(s, PEAK_NM, FWHM_NM):
        assert wl[np.argmax(row)] == pytest.approx(peak, abs=0.1)
        above = wl[row >= 0.5]
        assert above[-1] - above[0] == pytest.approx(fwhm, abs=0.3)


def test_band_integrate_flat_spectrum():
    flat = np.ones(161)
    sig = band_integrate(flat)
    # integral of a unit-peak Gaussian = sd * sqrt(2 pi)
    sd = np.asarray(FWHM_NM) / (2 * np.sqrt(2 * np.log(2)))
    np.testing.assert_allclose(sig, sd * np.sqrt(2 * np.pi), rtol=0.02)


def test_feature_names():
    f = feature_subsets()
    assert len(f) == 16
    assert list(f)[:6] == ["UV", "B", "G", "R", "IR", "UV-B"]
    assert f["R-IR"] == (3, 4) and f["all"] == (0, 1, 2, 3, 4)


def test_rayleigh_and_air_mass_known_values():
    assert rayleigh_optical_depth([550.0])[0] == pytest.approx(0.0973, rel=0.02)
    # lambda^-4 with the Hansen & Travis depolarisation/dispersion corrections
    corr = (1 + 0.0113 / 0.35**2 + 0.00013 / 0.35**4) / (1 + 0.0113 / 0.7**2 + 0.00013 / 0.7**4)
    assert rayleigh_optical_depth([350.0])[0] / rayleigh_optical_depth([700.0])[0] == pytest.approx(16 * corr)
    assert relative_air_mass(np.pi / 2) == pytest.approx(1.0, abs=1e-3)
    assert relative_air_mass(np.deg2rad(30.0)) == pytest.approx(1.9942, abs=0.01)


def test_solar_constant():
    wl = np.arange(100.0, 100000.0, 1.0)
    assert np.sum(solar_spectrum(wl)) == pytest.approx(1361, rel=0.01)


def test_clear_sky_is_blue_and_clouds_flatten_it():
    wl = np.array([350.0, 440.0, 500.0, 680.0, 800.0])
    zenith = np.array([0.0, 0.0, 1.0])
    clear = SkyState(np.deg2rad(45.0))
    ratio_clear = clear_sky_radiance(clear, zenith, wl) / solar_spectrum(wl)
    assert np.all(np.diff(ratio_clear) < 0)  # relative radiance falls with wavelength
    assert ratio_clear[0] / ratio_clear[-1] > 2  # Rayleigh lambda^-4, diluted by grey-ish aerosol
    overcast = clear.with_clouds(cover=1.0, optical_depth=40.0)
    ratio_cloud = sky_radiance(overcast, zenith, wl) / solar_spectrum(wl)
    assert ratio_cloud[0] / ratio_cloud[-1] < 0.5 * ratio_clear[0] / ratio_clear[-1]
    # the sky darkens as the sun sets
    low = SkyState(np.deg2rad(5.0))
    assert np.all(clear_sky_radiance(low, zenith, wl) < clear_sky_radiance(clear, zenith, wl))


def test_single_scattering_thin_limit():
    """Optically thin limit, sun and view at the zenith, no aerosol, no gas absorption at 800 nm.

    Single scattering (both layers together): ``E0 tau P(0) / (4 pi) exp(-tau)`` with ``P(0) = 1.5``.
    """
    wl = np.array([800.0])
    state = SkyState(np.deg2rad(90.0), turbidity=1e-9, precipitable_water_cm=0.0)
    tau = rayleigh_optical_depth(wl)
    d = direction_from_angles(0.0, np.deg2rad(89.999))
    expected = solar_spectrum(wl) * tau * np.exp(-tau) * 1.5 / (4 * np.pi)
    assert clear_sky_radiance(state, d, wl, multiple_scattering=False)[0] == pytest.approx(expected[0], rel=0.01)


def test_sky_integrates_to_the_bird_riordan_diffuse_budget():
    """Where single scattering falls short (UV/blue, low sun) the sky's hemispheric integral is Bird & Riordan's."""
    wl = np.array([350.0, 440.0, 500.0])
    for el in (50.0, 12.0, 6.0):
        state = SkyState(np.deg2rad(el), np.deg2rad(37.0), turbidity=0.1)
        budget = diffuse_irradiance_bird(state, wl)
        got = illumination(state, wl).diffuse_horizontal
        single = illumination(replace(state), wl, n_elevation=8)  # same state: consistency of the cache
        np.testing.assert_allclose(got, single.diffuse_horizontal)
        np.testing.assert_allclose(got, budget, rtol=0.03)
    # Bird & Riordan without aerosol and gases, sun at the zenith: I_r = 0.5 E0 (1 - T_r^0.95) (half of the
    # scattered light) plus the ground-sky reflections (E0 T_r + I_r) r_s a_g / (1 - r_s a_g), r_s = 0.5 (1 - T_r(1.8))
    thin = SkyState(np.deg2rad(90.0), turbidity=1e-9, ozone_atm_cm=0.0, precipitable_water_cm=0.0)
    e = diffuse_irradiance_bird(thin, np.array([800.0]))[0]
    tau = rayleigh_optical_depth([800.0])[0]
    e0 = solar_spectrum([800.0])[0]
    i_r = 0.5 * e0 * (1 - np.exp(-0.95 * tau))
    r_s = 0.5 * (1 - np.exp(-1.8 * tau))
    a_g = landscape_albedo([800.0])[0]
    i_g = (e0 * np.exp(-tau) + i_r) * r_s * a_g / (1 - r_s * a_g)
    assert e == pytest.approx(i_r + i_g, rel=1e-3)


def test_ozone_filters_the_low_sun_in_the_chappuis_band():
    """Direct beam ratio with/without ozone = exp(-a_o(600) * column * m_oz), a_o(600 nm) ~ 0.12 /cm."""
    wl = np.array([440.0, 600.0])
    low = SkyState(np.deg2rad(5.0), turbidity=0.05)
    none = SkyState(np.deg2rad(5.0), turbidity=0.05, ozone_atm_cm=0.0)
    ratio = illumination(low, wl).direct_normal / illumination(none, wl).direct_normal
    m_oz = ozone_air_mass(np.deg2rad(5.0))
    assert ratio[1] == pytest.approx(np.exp(-0.3 * np.interp(600.0, [593.0, 610.0], [0.119, 0.12]) * m_oz), rel=1e-3)
    assert ratio[0] == pytest.approx(1.0)  # no ozone absorption at 440 nm
    # the ozone-layer air mass at the horizon is finite (spherical shell), at the zenith 1
    assert ozone_air_mass(np.pi / 2) == pytest.approx(1.0, abs=1e-3)
    assert 10 < ozone_air_mass(0.0) < 20


def test_water_vapour_and_oxygen_bands_in_the_ir():
    """Bird & Riordan's transmittance laws at the zenith: 940 nm water band, 760 nm oxygen A band."""
    state = SkyState(np.deg2rad(90.0), precipitable_water_cm=2.0, ozone_atm_cm=0.0)
    t = gas_transmittance(state, np.array([660.0, 762.5, 937.0]), np.pi / 2)
    aw = 55.0 * 2.0  # a_w(937 nm) = 55 /cm
    assert t[2] == pytest.approx(np.exp(-0.2385 * aw / (1 + 20.07 * aw) ** 0.45), rel=1e-3)
    assert t[1] == pytest.approx(np.exp(-1.41 * 4.0 / (1 + 118.93 * 4.0) ** 0.45), rel=1e-3)
    assert t[0] > 0.99


def test_cloud_field_cover_fraction_and_motion():
    field = CloudLayer(cover=0.4, optical_depth=20.0, seed=3, softness=0.01)
    rng = np.random.default_rng(0)
    v = rng.normal(size=(20000, 3))
    v[:, 2] = np.abs(v[:, 2]) + 0.3
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    tau = field.optical_depth_at(v)
    assert np.mean(tau > 10) == pytest.approx(0.4, abs=0.07)
    assert not np.allclose(tau, field.optical_depth_at(v, time_s=300.0))


def test_shadow_is_bluer_than_sun():
    ill = illumination(SkyState(np.deg2rad(40.0), np.deg2rad(90.0)))
    up = np.array([0.0, 0.0, 1.0])
    sun = band_integrate(ill.on_surface(up, sunlit=1.0))
    shade = band_integrate(ill.on_surface(up, sunlit=0.0))
    assert np.all(shade < sun)
    assert shade[0] / shade[4] > 2 * sun[0] / sun[4]


def test_sensor_chain():
    sensor = LogSensorModel(noise_counts=0.0)
    white = np.asarray(sensor.white_radiance)
    rng = np.random.default_rng(0)
    assert sensor.counts_per_decade == pytest.approx(819.2)
    r = sensor.read(white, rng=rng)[0]
    np.testing.assert_array_equal(r, np.full(6, 3277))
    r10 = sensor.read(white / 10, rng=rng)[0]
    np.testing.assert_array_equal(r10[:5], np.full(5, 3277 - 819))
    assert np.all(sensor.read(white * 1e3, rng=rng)[0, :5] == 4095)
    assert np.all(sensor.read(white * 1e-6, rng=rng)[0, :5] == 0)
    np.testing.assert_allclose(sensor.log_radiance(sensor.ideal_counts(white * 0.3)), np.log10(0.3))
    noisy = LogSensorModel(noise_counts=5.0).read(white, rng=rng, n_readings=4000)
    assert noisy[..., 0].std() == pytest.approx(5.0, rel=0.1)


def test_vegetation_red_edge_and_low_uv():
    """Vegetation uses the measured green leaf: chlorophyll trough at 680 nm, red edge, UV a few per cent."""
    from bionav.light.bands import WAVELENGTHS_NM

    at = {w: int(np.argmin(np.abs(WAVELENGTHS_NM - w))) for w in (350, 550, 680, 800)}
    for name in ("grass", "shrub", "tree"):
        spec = MATERIALS[name].mean_spectrum()
        assert spec[at[800]] > 3 * spec[at[680]] and spec[at[680]] < spec[at[550]] and spec[at[350]] < 0.06
        uv, b, g, r, ir = MATERIALS[name].reflectance
        assert ir > 2 * r and uv < b < g  # band means (the R band's Gaussian reaches into the red edge)
    for name in ("paint_white", "plastic_white"):
        assert MATERIALS[name].reflectance[0] < 0.1 < MATERIALS[name].reflectance[1]
    assert len(CHANNELS) == 5


def test_a_scattered_cloud_cover_neither_hides_a_low_sun_nor_veils_the_horizon():
    """A 10 % cover of thick clouds seen at grazing angles (footprints averaging many clouds) lets through the
    clear fraction of the light, not exp(-(mean optical depth) m): the radiances are averaged, not the depths.

    Known answers: direct beam ``(1 - f) + f exp(-tau m)`` of the clear beam, with ``f`` the cloud fraction of
    the sun's footprint, which for a low sun tends to the cover (here within 0.1 of it); the sky at 3 degrees
    elevation, averaged over azimuth, differs from the clear sky by at most the cloud fraction.
    """
    wl = np.array([350.0, 800.0])
    clear = SkyState(np.deg2rad(7.4), np.deg2rad(150.0), turbidity=0.1)
    cloudy = replace(clear, clouds=CloudLayer(cover=0.1, optical_depth=10.0, seed=0))
    f = float(cloud_fraction(cloudy, cloudy.sun_direction))
    assert 0.0 <= f <= 0.2
    m = float(relative_air_mass(cloudy.sun_elevation))
    want = illumination(clear, wl).direct_normal * ((1 - f) + f * np.exp(-10.0 * m))
    np.testing.assert_allclose(illumination(cloudy, wl).direct_normal, want, rtol=1e-9)
    assert np.all(illumination(cloudy, wl).direct_normal > 0.8 * illumination(clear, wl).direct_normal)
    d = direction_from_angles(np.linspace(0, 2 * np.pi, 72, endpoint=False), np.deg2rad(3.0))
    rel = sky_radiance(cloudy, d, wl).mean(axis=0) / clear_sky_radiance(clear, d, wl).mean(axis=0)
    frac = float(cloud_fraction(cloudy, d).mean())
    assert 0.0 < frac < 0.2
    assert np.all(np.abs(rel - 1) <= frac), (rel, frac)


def test_green_ground_lights_tilted_surfaces_with_its_own_spectrum():
    """A vertical wall facing away from the sun: E = diffuse / 2 + a(lambda) E_global / 2 (isotropic sky and ground)."""
    wl = np.array([350.0, 800.0])
    state = SkyState(np.deg2rad(40.0), np.deg2rad(90.0), turbidity=0.1)
    ill = illumination(state, wl)
    away = -np.array([state.sun_direction[0], state.sun_direction[1], 0.0])
    away /= np.linalg.norm(away)
    grass = np.array([0.03, 0.45])
    got = ill.on_surface(away, ground_albedo=grass)
    expected = 0.5 * ill.diffuse_horizontal + 0.5 * grass * ill.global_horizontal
    np.testing.assert_allclose(got, expected, rtol=1e-12)
    # the green ground makes the wall's light redder in UV-IR than a grey ground of 0.15 does
    grey = ill.on_surface(away, ground_albedo=0.15)
    assert got[1] / got[0] > 1.5 * grey[1] / grey[0]


def test_landscape_albedo_is_dark_in_uv_and_bright_in_ir_and_brightens_the_cloud_base(monkeypatch):
    import bionav.light.daylight as daylight

    a = landscape_albedo(np.array([350.0, 440.0, 800.0]))
    assert 0.02 < a[0] < 0.1 and a[1] < 0.12 and 0.25 < a[2] < 0.4
    # overcast of optical depth 40: the cloud base reflects the ground's light back down, L = L0 / (1 - a c (1 - T))
    wl = np.array([350.0, 800.0])
    state = SkyState(np.deg2rad(45.0), turbidity=0.1, clouds=CloudLayer(cover=1.0, optical_depth=40.0, seed=3))
    zenith = np.array([0.0, 0.0, 1.0])
    with_ground = sky_radiance(state, zenith, wl)
    below = 0.2 * clear_sky_radiance(state, zenith, wl)
    monkeypatch.setattr(daylight, "landscape_albedo", lambda w: np.zeros(np.shape(w)))
    monkeypatch.setattr(daylight, "_MS_CACHE", {})  # the clear sky's ground-sky term changes too
    without = sky_radiance(state, zenith, wl)
    below_without = 0.2 * clear_sky_radiance(state, zenith, wl)
    t_c = 1.0 / (1.0 + 0.75 * (1 - 0.85) * 40.0)
    np.testing.assert_allclose((with_ground - below) / (without - below_without),
                               1.0 / (1.0 - a[[0, 2]] * (1.0 - t_c)), rtol=1e-9)
