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
