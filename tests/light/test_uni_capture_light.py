"""sim_uni: the light changing while the grid was captured (sun moving, clouds drifting)."""

import datetime as dt

import numpy as np
import pytest

from bionav.geometry import PanoramaGeometry
from bionav.light.sun import parse_time, sun_position
from bionav.world.lights import Ambient, DirectionalLight
from bionav.world.render import render_panorama
from bionav.world.worlds import outdoor
from bionav.world.worlds.outdoor import CaptureLight, CloudField, build_campus, build_uni, capture_order


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
    light = CaptureLight(order=capture_order(uni.cells), seed=0)
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
    clouds = CloudField(3)
    rng = np.random.default_rng(0)
    d = rng.normal(size=(20000, 3))
    d[:, 2] = np.abs(d[:, 2]) + 0.3  # above the horizon
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    frac = [float((clouds.coverage(d, t) > 0.5).mean()) for t in (0.0, 1800.0)]
    assert frac == pytest.approx([outdoor.CLOUD_COVER] * 2, abs=0.1)
    # frozen turbulence: what is seen at layer point p at time t is seen at p + wind * dt at t + dt
    *_, wind = clouds._waves()
    p = d[:50, :2] * (clouds.height_m / d[:50, 2])[:, None]
    dt_s = 60.0
    q = p + wind[None, :] * clouds.wind_m_s * dt_s
    dq = np.concatenate([q, np.full((50, 1), clouds.height_m)], axis=1)
    dq /= np.linalg.norm(dq, axis=1, keepdims=True)
    assert np.allclose(clouds.coverage(dq, dt_s), clouds.coverage(d[:50], 0.0), atol=1e-9)
    # deterministic per seed, different between seeds
    assert np.array_equal(CloudField(3).coverage(d, 10.0), clouds.coverage(d, 10.0))
    assert not np.array_equal(CloudField(4).coverage(d, 10.0), clouds.coverage(d, 10.0))


def test_direct_sunlight_drops_behind_clouds_and_the_light_changes_during_the_capture(uni):
    light = CaptureLight(order=capture_order(uni.cells), seed=0)
    cond = [light.conditions(i, j) for i, j in np.argwhere(uni.cells)]
    tr = np.array([c["sun_transmittance"] for c in cond])
    assert tr.min() == pytest.approx(outdoor.CLOUD_SUN_TRANSMITTANCE) and tr.max() == pytest.approx(1.0)
    assert 0.2 < np.mean(tr < 0.5) < 0.7  # the sun is behind a cloud for part of the captures
    ratio = np.array([c["diffuse_ratio"] for c in cond])
    assert np.all(ratio > 1.0)  # sunlit clouds are brighter than the blue sky they hide


def test_relit_scene_renders_as_a_freshly_built_one(uni):
    """Scene.relit reuses the compiled geometry: same pixels as compiling the relit world from scratch."""
    light = CaptureLight(order=capture_order(uni.cells), seed=0)
    geometry = PanoramaGeometry.square_pixels(96, 16)
    pos = uni.cell_position(4, 9)
    relit = light.scene_at(uni.scene, 4, 9)
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
    assert uni.capture_scene is not None and "capture_light" in uni.info
