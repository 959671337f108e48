"""sim_uni: the light changing while the grid was captured (sun moving, clouds drifting)."""

import datetime as dt

import numpy as np
import pytest

from bionav.geometry import PanoramaGeometry
from bionav.light.clouds import CloudLayer
from bionav.light.simple_sky import SimpleSky
from bionav.light.sun import parse_time, sun_position
from bionav.world.lights import Ambient, DirectionalLight
from bionav.world.render import render_panorama
from bionav.world.worlds import outdoor
from bionav.world.worlds.common import OpenSky
from bionav.world.worlds.outdoor import build_campus, build_uni, capture_order, uni_capture_light


@pytest.fixture(scope="module")
def uni():
    return build_uni(0)


def test_capture_order_runs_the_lanes_in_alternate_directions():
    cells = np.ones((10, 17), bool)
    order = capture_order(cells)
    assert order[0, 0] == 0 and order[0, 16] == 16  # first lane north
    assert order[1, 16] == 17 and order[1, 0] == 33  # second lane back south
    assert order[9, 0] == 169 and sorted(order.ravel()) == list(range(170))
    cells[2, 3] = False
    order = capture_order(cells)
    assert order[2, 3] == -1 and order.max() == 168


def test_sun_follows_the_ephemeris_and_the_grid_stays_in_the_buildings_shadow(uni):
    light = uni_capture_light(uni.cells, 0)
    for cell in [(0, 0), (4, 9), (9, 0)]:
        t = light.time_s(*cell)
        assert t == pytest.approx(outdoor.SECONDS_PER_CAPTURE * capture_order(uni.cells)[cell])
        when = parse_time(outdoor.CAPTURE_START_UTC) + dt.timedelta(seconds=t)
        ref = sun_position(when, latitude_deg=outdoor.SITE_DEG[0], longitude_deg=outdoor.SITE_DEG[1]).direction
        assert np.allclose(light.sun_direction(t), ref, atol=1e-12)
    # over the 85 minutes the sun crosses the meridian: it moves by about 21 deg/h in azimuth
    first, last = light.sun_direction(0.0), light.sun_direction(169 * outdoor.SECONDS_PER_CAPTURE)
    az = np.degrees(np.arctan2([first[1], last[1]], [first[0], last[0]]))
    assert -80 < az[0] < -72 and -105 < az[1] < -98  # SSE to SSW (azimuth CCW from east; -90 south)
    # thesis 3.1: "during the collection time, the area was in the shadow" of the main building
    # (x -45..55, y -26..-9, at least 18 m high): the sun ray from every cell hits its north face
    for (i, j), k in np.ndenumerate(capture_order(uni.cells)):
        s = light.sun_direction(k * outdoor.SECONDS_PER_CAPTURE)
        x, y, z = uni.cell_position(i, j)
        lam = (-9.0 - y) / s[1]  # where the ray reaches the plane of the north face
        assert lam > 0 and -45 < x + lam * s[0] < 55 and z + lam * s[2] < 18.0


def test_clouds_cover_the_stated_fraction_and_drift_with_the_wind():
    clouds = uni_capture_light(np.ones(outdoor.GRID_SHAPE, bool), 3).clouds
    assert clouds.cover == outdoor.CLOUD_COVER and clouds.wind_mps == outdoor.WIND_MPS
    rng = np.random.default_rng(0)
    d = rng.normal(size=(20000, 3))
    d[:, 2] = np.abs(d[:, 2]) + 0.3  # above the horizon
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    frac = [float((clouds.density_at(d, time_s=t) > 0.5).mean()) for t in (0.0, 1800.0)]
    assert frac == pytest.approx([outdoor.CLOUD_COVER] * 2, abs=0.1)
    # frozen turbulence: what is seen at t + dt equals what an observer moved with the wind saw at t
    dt_s = 60.0
    moved = tuple(np.asarray(outdoor.WIND_MPS) * dt_s)
    assert np.allclose(clouds.density_at(d[:50], time_s=dt_s, origin_m=moved), clouds.density_at(d[:50]), atol=1e-9)
    assert not np.allclose(clouds.density_at(d[:50], time_s=dt_s), clouds.density_at(d[:50]), atol=1e-3)
    # deterministic per seed, different between seeds
    same = uni_capture_light(np.ones(outdoor.GRID_SHAPE, bool), 3).clouds
    assert np.array_equal(same.density_at(d, time_s=10.0), clouds.density_at(d, time_s=10.0))
    other = CloudLayer(**{**clouds.__dict__, "seed": 4})
    assert not np.array_equal(other.density_at(d, time_s=10.0), clouds.density_at(d, time_s=10.0))


def test_direct_sunlight_drops_behind_clouds_and_the_light_changes_during_the_capture(uni):
    light = uni_capture_light(uni.cells, 0)
    cond = [light.conditions(i, j) for i, j in np.argwhere(uni.cells)]
    tr = np.array([c["sun_transmittance"] for c in cond])
    # a cloud passes exp(-tau m) of the sun's direct light, about 15 % (tau 1, air mass 1.8-1.9 at 31-33 deg)
    full = [np.exp(-outdoor.CLOUD_OPTICAL_DEPTH / c["sun"][2]) for c in cond]
    assert tr.min() == pytest.approx(min(full), abs=0.01) and tr.max() == pytest.approx(1.0)
    assert 0.13 < min(full) < 0.17
    assert 0.2 < np.mean(tr < 0.5) < 0.7  # the sun is behind a cloud for part of the captures
    ratio = np.array([c["diffuse_ratio"] for c in cond])
    assert np.all(ratio > 1.0)  # sunlit clouds are brighter than the blue sky they hide


def test_relit_scene_renders_as_a_freshly_built_one(uni):
    """Scene.relit reuses the compiled geometry: same pixels as compiling the relit world from scratch."""
    light = uni_capture_light(uni.cells, 0)
    geometry = PanoramaGeometry.square_pixels(96, 16)
    pos = uni.cell_position(4, 9)
    relit = OpenSky().capture_scene(uni.scene, light, (4, 9))
    fresh = build_campus(0)
    fresh.scene.lights = list(relit.lights)
    fresh.scene.ambient = Ambient(up=relit.ambient.up, down=relit.ambient.down)
    fresh.scene.sky = relit.sky
    a = render_panorama(relit, position=pos, geometry=geometry)
    b = render_panorama(fresh.scene, position=pos, geometry=geometry)
    assert np.array_equal(a, b)
    # and the base world is untouched (db.realism=ideal renders it)
    base = render_panorama(uni.scene, position=pos, geometry=geometry)
    assert np.array_equal(base, render_panorama(build_campus(0).scene, position=pos, geometry=geometry))
    assert not np.array_equal(a, base)
    assert isinstance(relit.lights[0], DirectionalLight)


def test_ideal_uni_is_the_campus_unchanged(uni):
    assert uni.scene.compile().digest() == build_campus(0).scene.compile().digest()
    assert isinstance(uni.aperture, OpenSky)
    assert uni.info["capture_light"] == uni.capture_light.describe() == uni_capture_light(uni.cells, 0).describe()


def test_the_campus_sky_shows_the_capture_layer_frozen_at_the_first_capture(uni):
    """db.realism=ideal: the campus' clouds are the capture light's layer (outdoor.campus_clouds) at time 0."""
    sky = uni.scene.sky
    layer = uni_capture_light(uni.cells, 0).clouds
    assert sky.layer == layer == outdoor.campus_clouds(0) and sky.time_s == 0.0
    assert uni.info["sky"] == sky.describe() and uni.info["sky"]["layer"]["cover"] == outdoor.CLOUD_COVER
    # the sky seen from the grid: the clear sky blended by the layer's cloud fraction towards the cloud's
    # radiance, 1.25 times the clear east horizon (0.95 plus a trace of the sun's glow); the first capture's sky
    # (other sun) has the same clouds
    d = np.random.default_rng(5).normal(size=(4000, 3))
    d[:, 2] = np.abs(d[:, 2]) + 0.1
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    c = layer.density_at(d)[:, None]
    assert 0.2 < np.mean(c > 0.5) < 0.6
    first = uni_capture_light(uni.cells, 0).conditions(0, 0)["sky"]
    for s in (sky, first):
        clear = SimpleSky(sun_direction=s.sun_direction)
        horizon = clear(np.array([[1.0, 0.0, 0.0]]))
        assert horizon[0, 0] == pytest.approx(0.95, abs=1e-3)
        np.testing.assert_allclose(s(d), (1 - c) * clear(d) + c * outdoor.CLOUD_RADIANCE * horizon, rtol=1e-12)
    assert first.time_s == 0.0 and first.layer == sky.layer and first.sun_direction != sky.sun_direction
