"""Sky model against closed forms (Rayleigh, Berry et al. 2004, CIE, sun position, clouds)."""

import numpy as np
import pytest

from bionav.geometry import direction_from_angles
from bionav.light import (
    CloudLayer,
    PolarizerLamp,
    SkyModel,
    SunPosition,
    angle_in_frame,
    berry_polarization,
    cie_relative_radiance,
    max_degree_from_turbidity,
    random_cloud_map,
    rayleigh_polarization,
    sun_position,
)
from bionav.light.rayleigh import local_frame

ZENITH = np.array([0.0, 0.0, 1.0])


@pytest.mark.parametrize("sun_az_deg", [-170.0, -45.0, 0.0, 30.0, 90.0, 135.0])
@pytest.mark.parametrize("sun_el_deg", [0.0, 30.0, 75.0])
def test_zenith_evector_is_perpendicular_to_solar_meridian(sun_az_deg, sun_el_deg):
    sun = direction_from_angles(np.deg2rad(sun_az_deg), np.deg2rad(sun_el_deg))
    degree, e = rayleigh_polarization(ZENITH, sun, max_degree=0.8)
    meridian = np.array([np.cos(np.deg2rad(sun_az_deg)), np.sin(np.deg2rad(sun_az_deg)), 0.0])
    assert abs(np.dot(e, meridian)) < 1e-12
    assert abs(e[2]) < 1e-12
    # Degree at the zenith: gamma = 90 deg - elevation.
    g = np.deg2rad(90.0 - sun_el_deg)
    assert degree == pytest.approx(0.8 * np.sin(g) ** 2 / (1 + np.cos(g) ** 2), abs=1e-12)


def test_degree_zero_at_sun_and_antisun_and_maximal_at_90_degrees():
    sun = direction_from_angles(0.4, 0.5)
    d_sun, _ = rayleigh_polarization(sun[None], sun, max_degree=0.7)
    d_anti, _ = rayleigh_polarization(-sun[None], sun, max_degree=0.7)
    assert d_sun[0] == pytest.approx(0.0, abs=1e-12)
    assert d_anti[0] == pytest.approx(0.0, abs=1e-12)
    # A great circle of points 90 degrees from the sun all have the maximum degree.
    u = np.cross(sun, [0.0, 0.0, 1.0])
    u /= np.linalg.norm(u)
    w = np.cross(sun, u)
    t = np.linspace(0, 2 * np.pi, 13)
    circle = np.cos(t)[:, None] * u + np.sin(t)[:, None] * w
    d, e = rayleigh_polarization(circle, sun, max_degree=0.7)
    np.testing.assert_allclose(d, 0.7, atol=1e-12)
    # e-vectors perpendicular to the view and to the scattering plane.
    np.testing.assert_allclose(np.sum(e * circle, -1), 0.0, atol=1e-12)
    np.testing.assert_allclose(np.abs(e @ sun), 0.0, atol=1e-12)
    # Any other point has a smaller degree.
    rng = np.random.default_rng(0)
    v = rng.standard_normal((200, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    d_any, _ = rayleigh_polarization(v, sun, max_degree=0.7)
    assert np.all(d_any <= 0.7 + 1e-12)


def test_degree_at_60_degrees_from_sun_hand_value():
    sun = direction_from_angles(0.0, 0.0)
    view = direction_from_angles(np.deg2rad(60.0), 0.0)
    d, _ = rayleigh_polarization(view, sun, max_degree=1.0)
    assert d == pytest.approx(0.75 / 1.25)


def test_max_degree_from_turbidity():
    assert max_degree_from_turbidity(1.0) == pytest.approx((1 - 0.0279) / (1 + 0.0279))
    assert max_degree_from_turbidity(2.0) == pytest.approx(max_degree_from_turbidity(1.0) / 2)
    with pytest.raises(ValueError):
        max_degree_from_turbidity(0.5)


def test_berry_reduces_to_rayleigh_and_has_four_neutral_points():
    rng = np.random.default_rng(3)
    view = direction_from_angles(rng.uniform(-np.pi, np.pi, 50), rng.uniform(0.05, 1.5, 50))
    sun = direction_from_angles(-1.0, 0.6)
    d_r, e_r = rayleigh_polarization(view, sun, max_degree=0.8)
    d_b, e_b = berry_polarization(view, sun, neutral_point_separation=0.0, max_degree=0.8)
    np.testing.assert_allclose(d_b, d_r, atol=1e-12)
    np.testing.assert_allclose(np.abs(np.sum(e_b * e_r, -1)), 1.0, atol=1e-12)
    # With separation delta the Babinet and Brewster points (sun elevation +- delta/2) are
    # unpolarized, the sun itself is not, and so are their antipodes (Arago, fourth point).
    delta = np.deg2rad(30.0)
    babinet = direction_from_angles(-1.0, 0.6 + delta / 2)
    brewster = direction_from_angles(-1.0, 0.6 - delta / 2)
    d, _ = berry_polarization(np.stack([babinet, brewster, -babinet, -brewster, sun]), sun, neutral_point_separation=delta)
    np.testing.assert_allclose(d[:4], 0.0, atol=1e-12)
    assert d[4] > 0.01
    # Far from the neutral points the pattern stays close to Rayleigh's.
    _, e_z = berry_polarization(ZENITH[None], sun, neutral_point_separation=delta)
    _, e_zr = rayleigh_polarization(ZENITH[None], sun)
    assert abs(np.dot(e_z[0], e_zr[0])) > np.cos(np.deg2rad(1.0))


def test_cie_radiance_is_one_at_zenith_and_brightest_near_sun():
    sun = direction_from_angles(0.0, np.deg2rad(30.0))
    assert cie_relative_radiance(ZENITH, sun) == pytest.approx(1.0)
    near_sun = direction_from_angles(0.0, np.deg2rad(35.0))
    away = direction_from_angles(np.pi, np.deg2rad(35.0))
    assert cie_relative_radiance(near_sun, sun) > 3 * cie_relative_radiance(away, sun)


def test_sun_position_at_equinox_noon():
    # 2024-03-20, Greenwich meridian: the sun culminates at about 12:07 UTC
    # (equation of time -7.5 min), due south, at elevation 90 - latitude + declination (~0).
    pos = sun_position("2024-03-20T12:07:30", latitude_deg=52.0, longitude_deg=0.0)
    assert np.degrees(pos.elevation) == pytest.approx(38.0, abs=0.5)
    assert np.degrees(pos.azimuth) == pytest.approx(-90.0, abs=1.0)  # south = -90 deg CCW from east
    morning = sun_position("2024-03-20T07:00:00+01:00", latitude_deg=52.0, longitude_deg=0.0)
    assert -np.pi / 2 < morning.azimuth < np.pi / 2  # eastern half of the sky


def test_local_frame_and_angle_in_frame():
    view = direction_from_angles(0.3, 0.7)
    e_t, e_p = local_frame(view)
    assert np.dot(e_t, view) == pytest.approx(0.0, abs=1e-12)
    assert np.dot(e_p, view) == pytest.approx(0.0, abs=1e-12)
    assert e_t[2] < 0  # away from the zenith
    assert angle_in_frame(e_p, e_t, e_p) == pytest.approx(np.pi / 2 - np.pi)  # axial: wrapped to -pi/2


def test_cloud_field_cover_and_reproducibility():
    a = random_cloud_map(np.random.default_rng(5), cover=0.4)
    b = random_cloud_map(np.random.default_rng(5), cover=0.4)
    np.testing.assert_array_equal(a.cloudiness, b.cloudiness)
    assert not np.array_equal(a.cloudiness, random_cloud_map(np.random.default_rng(6), cover=0.4).cloudiness)
    # the map is a perspective snapshot of a layer of that cover: its solid-angle-weighted mean
    # cloudiness over the sky is the cover on average over layers (one map: +-0.04, 40 maps: +-0.007)
    n = a.cloudiness.shape[0]
    u = np.linspace(-1, 1, n)
    r = np.hypot(*np.meshgrid(u, u))
    weight = np.where(r <= 1, np.sinc(r / 2), 0.0)  # sin(zenith) / zenith of the equidistant projection
    for cover in (0.2, 0.7):
        means = [np.sum(weight * random_cloud_map(np.random.default_rng(s), cover=cover).cloudiness) / weight.sum()
                 for s in range(40)]
        assert np.mean(means) == pytest.approx(cover, abs=0.03)
    clear = random_cloud_map(np.random.default_rng(1), cover=0.0)
    assert clear.clear_fraction() == 1.0
    overcast = random_cloud_map(np.random.default_rng(1), cover=1.0)
    assert overcast.clear_fraction() == 0.0
    # Clouds lower the degree where they are.
    sun = SunPosition(0.0, np.deg2rad(30))
    views = direction_from_angles(np.linspace(-3, 3, 40), np.deg2rad(60.0))
    clear_light = SkyModel(sun).light(views)
    cloudy = SkyModel(sun, clouds=overcast).light(views)
    np.testing.assert_allclose(cloudy.degree, clear_light.degree * (1 - overcast.depolarization), atol=1e-12)
    np.testing.assert_allclose(np.sum(cloudy.evector * views, -1), 0.0, atol=1e-12)


def test_a_cloud_map_is_a_snapshot_of_its_layer():
    layer = CloudLayer(cover=0.5, seed=3, height_m=1200.0, scale_m=3000.0, angle_noise_sigma=np.deg2rad(15.0),
                       depolarization=0.8, brightness=1.3)
    snap = layer.hemisphere_map(resolution=65, time_s=40.0, origin_m=(10.0, -5.0))
    assert (snap.angle_noise_sigma, snap.depolarization, snap.brightness) == (np.deg2rad(15.0), 0.8, 1.3)
    # at the map's nodes (zenith, and along the grid's axes) the map gives what the layer gives
    zen = np.array([0.0, 0.25, 0.5, 0.75, 1.0]) * np.pi / 2  # nodes of a 65 grid at r = 0, 1/4 ... 1
    views = np.concatenate([direction_from_angles(np.zeros(5), np.pi / 2 - zen),
                            direction_from_angles(np.full(5, np.pi / 2), np.pi / 2 - zen)])
    kw = dict(time_s=40.0, origin_m=(10.0, -5.0))
    np.testing.assert_allclose(snap.cloudiness_at(views), np.clip(layer.cloudiness_at(views, **kw), 0, 1),
                               atol=1e-9)
    np.testing.assert_allclose(snap.angle_noise_at(views), layer.angle_noise_at(views, **kw), atol=1e-9)
    # between the nodes it interpolates: close to the layer where clouds are wider than a pixel
    rng = np.random.default_rng(0)
    views = direction_from_angles(rng.uniform(-np.pi, np.pi, 200), np.deg2rad(rng.uniform(30.0, 90.0, 200)))
    assert np.max(np.abs(snap.cloudiness_at(views) - layer.cloudiness_at(views, **kw))) < 0.1


def test_polarizer_lamp():
    lamp = PolarizerLamp(axis_azimuth=0.5, degree=0.95)
    light = lamp.light(ZENITH[None])
    assert light.degree[0] == 0.95
    assert abs(np.dot(light.evector[0], [np.cos(0.5), np.sin(0.5), 0.0])) == pytest.approx(1.0)
