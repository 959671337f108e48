"""The one cloud layer (bionav.light.clouds.CloudLayer): its cover, shade and polarization views agree."""

import numpy as np
import pytest

from bionav.light.clouds import CloudLayer
from bionav.light.polarized_sky import SkyModel
from bionav.light.simple_sky import SimpleSky
from bionav.light.sun import SunPosition


def _directions(n=400, seed=0):
    d = np.random.default_rng(seed).normal(size=(n, 3))
    d[:, 2] = np.abs(d[:, 2]) + 0.2
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def test_optical_depth_and_transmittance_are_views_of_the_density():
    layer = CloudLayer(cover=0.4, optical_depth=12.0, seed=5)
    d = _directions()
    f = layer.density_at(d, time_s=30.0)
    assert f.shape == (400,) and 0.0 <= f.min() and f.max() <= 1.0 and 0.05 < f.mean() < 0.95
    np.testing.assert_array_equal(layer.optical_depth_at(d, time_s=30.0), 12.0 * f)
    m = 1.0 / d[:, 2]
    # Beer-Lambert through the cloudy part of the footprint only: (1 - f) + f exp(-tau m)
    np.testing.assert_allclose(layer.transmittance_at(d, air_mass=m, time_s=30.0), (1 - f) + f * np.exp(-12.0 * m),
                               rtol=1e-12)
    assert np.all(CloudLayer(cover=0.0).transmittance_at(d, air_mass=m) == 1.0)
    np.testing.assert_allclose(CloudLayer(cover=1.0, optical_depth=2.0).transmittance_at(d, air_mass=m),
                               np.exp(-2.0 * m), rtol=1e-12)


def test_polarization_view_depolarizes_where_the_layer_is_cloudy():
    layer = CloudLayer(cover=0.5, seed=2, depolarization=0.9, brightness=1.5)
    sun = SunPosition(azimuth=0.3, elevation=0.5)
    d = _directions(seed=1)
    clear = SkyModel(sun).light(d)
    cloudy = SkyModel(sun, clouds=layer).light(d)
    c = layer.cloudiness_at(d)
    np.testing.assert_array_equal(c, layer.density_at(d))
    np.testing.assert_allclose(cloudy.degree, clear.degree * (1 - 0.9 * c), rtol=1e-12)
    np.testing.assert_allclose(cloudy.radiance, clear.radiance * (1 - c) + 1.5 * c, rtol=1e-12)
    # the e-vector turns by the layer's angle noise, which vanishes where there is no cloud
    turn = layer.angle_noise_at(d)
    cos = np.abs(np.sum(cloudy.evector * clear.evector, axis=1))
    np.testing.assert_allclose(cos, np.abs(np.cos(turn)), atol=1e-9)
    assert np.all(np.abs(turn[c < 1e-6]) < 1e-6) and np.std(turn[c > 0.9]) > np.deg2rad(5)


def test_simple_sky_behind_the_layer():
    layer = CloudLayer(cover=0.4, seed=3, brightness=1.25)
    sun = (0.0, -0.8, 0.6)
    clear = SimpleSky(sun_direction=sun)
    sky = SimpleSky(sun_direction=sun, layer=layer, time_s=100.0)
    d = _directions(seed=2)
    c = layer.cloudiness_at(d, time_s=100.0)[:, None]
    np.testing.assert_allclose(sky(d), (1 - c) * clear(d) + c * 1.25 * clear(np.array([[1.0, 0, 0]])), rtol=1e-12)
    assert sky(d).shape == (400, 1) and not np.allclose(sky(d), clear(d))
    assert SimpleSky(sun_direction=sun, layer=CloudLayer(cover=0.0))(d) == pytest.approx(clear(d))


def test_simple_sky_is_brighter_where_the_layer_is_denser():
    """Away from the sun's glow the clear sky is the same at one elevation: the radiance rises with the density."""
    layer = CloudLayer(cover=0.4, seed=3, scale_m=600.0, softness=0.05, resolution=1e-4, brightness=1.25)
    sky = SimpleSky(sun_direction=(0.0, 0.0, 1.0), glow=0.0, layer=layer, time_s=50.0)
    az = np.linspace(0.0, 2.0 * np.pi, 720, endpoint=False)
    el = np.deg2rad(40.0)
    d = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.full_like(az, np.sin(el))], axis=1)
    c = layer.density_at(d, time_s=50.0)
    assert np.sum(c < 1e-6) > 20 and np.sum(c > 1.0 - 1e-6) > 20  # clear and cloudy lines of sight
    radiance = sky(d)[:, 0]
    order = np.argsort(c, kind="stable")
    assert np.all(np.diff(radiance[order]) >= -1e-12)  # never darker where denser
    # clear: the clear-sky formula by hand; full cloud: 1.25 times the clear horizon (0.95)
    clear = 0.55 + (0.95 - 0.55) * (1.0 - np.sin(el)) ** 2
    assert radiance[c < 1e-6] == pytest.approx(clear, abs=1e-6)
    assert radiance[c > 1.0 - 1e-6] == pytest.approx(1.25 * 0.95, abs=1e-6)


def test_simple_sky_without_cover_is_exactly_the_clear_sky_and_the_texture_is_deterministic():
    sun = (0.3, -0.7, 0.65)
    d = _directions(seed=4)
    clear = SimpleSky(sun_direction=sun, channels=("UV", "G"))(d)
    assert np.array_equal(SimpleSky(sun_direction=sun, channels=("UV", "G"), layer=CloudLayer(cover=0.0))(d), clear)
    cloudy = SimpleSky(sun_direction=sun, channels=("UV", "G"), layer=CloudLayer(cover=0.5, seed=7), time_s=12.0)
    again = SimpleSky(sun_direction=sun, channels=("UV", "G"), layer=CloudLayer(cover=0.5, seed=7), time_s=12.0)
    other = SimpleSky(sun_direction=sun, channels=("UV", "G"), layer=CloudLayer(cover=0.5, seed=8), time_s=12.0)
    assert np.array_equal(cloudy(d), again(d)) and not np.allclose(cloudy(d), other(d))
    # the bands keep their sky gains (UV 1.4, G 1.0) behind the clouds too
    np.testing.assert_allclose(cloudy(d)[:, 0], 1.4 * cloudy(d)[:, 1], rtol=1e-12)
    assert cloudy.describe()["layer"]["seed"] == 7 and cloudy.describe() != other.describe()
