"""Daylight during the recording of the living-room stand-ins (camera model only).

The light is :class:`bionav.light.capture.CaptureLight` with a stated sun path and clouds along the
capture order; it enters the room through :class:`bionav.world.worlds.common.Windows`.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from bionav.db.camera import session_seed
from bionav.db.synthetic import get_spec, synthetic_database
from bionav.light.capture import CaptureLight
from bionav.world.lights import Ambient
from bionav.world.render import render_ray_grid
from bionav.world.scene import Scene
from bionav.world.worlds.common import OpenSky, Supervisor, Windows, World, lane_order, stream

ROOM = (4.0, 4.0, 2.5)
WINDOW = ("y0", 1.5, 2.5, 1.0, 2.0)  # on the wall y = 0, x 1.5 .. 2.5, z 1.0 .. 2.0


def _empty_room() -> World:
    """A plain room (albedo 0.5, no lamps, ambient 0.1) with one window on the wall y = 0."""
    scene = Scene(name="empty room")
    grey = scene.material(albedo=0.5)
    scene.box((0, 0, 0), ROOM, grey, inside=True, shadow=False)
    scene.ambient = Ambient(up=0.1, down=0.1)
    scene.exposure = 1.0
    daylight = CaptureLight(order=lane_order((1, 1)), seconds_per_capture=40.0, sun_azimuth_deg=(-90.0, -90.0),
                            sun_elevation_deg=(45.0, 45.0), sun_irradiance=2.0, cloud_sigma=0.0)
    return World(scene=scene, grid_origin=(2.0, 2.0), spacing=0.1, grid_shape=(1, 1), camera_height=0.6,
                 capture_light=daylight, aperture=Windows(room=ROOM, windows=(WINDOW,)))


def _radiance_towards(scene, eye, target) -> float:
    d = np.asarray(target, float) - np.asarray(eye, float)
    az = np.arctan2(d[1], d[0])
    el = np.arctan2(d[2], np.hypot(d[0], d[1]))
    return float(render_ray_grid(scene, position=eye, azimuths=np.array([az]), elevations=np.array([el]),
                                 pixel_angle=1e-3)[0, 0, 0])


def test_the_sun_lights_the_floor_only_where_it_enters_through_the_window():
    world = _empty_room()
    scene_at = world.capture_scenes(np.array([[0, 0]]), seed=session_seed(0, 0))
    sunny = scene_at(0)
    eye = world.cell_position(0, 0)
    # sun from -y at 45 deg: a floor point at y = 1.5 sees the wall y = 0 at height 1.5, inside the window
    # (z 1.0 .. 2.0) when x lies in 1.5 .. 2.5; the lit floor patch is y = 1.0 .. 2.0 below the window
    inside, outside_x, outside_y = (2.0, 1.5, 0.0), (3.2, 1.5, 0.0), (2.0, 2.6, 0.0)
    ambient = 0.5 * 0.1  # albedo x ambient
    sun = 0.5 * 2.0 * np.sin(np.radians(45.0))  # albedo x irradiance x cos(incidence) on the floor
    assert _radiance_towards(sunny, eye, inside) == pytest.approx(ambient + sun, rel=1e-6)
    assert _radiance_towards(sunny, eye, outside_x) == pytest.approx(ambient, rel=1e-6)  # wall beside the window
    assert _radiance_towards(sunny, eye, outside_y) == pytest.approx(ambient, rel=1e-6)  # beyond the patch
    # the scene the world was built with (and db.realism=ideal renders) has no sun
    assert _radiance_towards(world.scene, eye, inside) == pytest.approx(ambient, rel=1e-6)


def test_capture_time_follows_boustrophedon_lanes_and_the_sun_moves_with_it():
    d = CaptureLight(order=lane_order((2, 3), lane_axis=1), seconds_per_capture=1440.0,
                     sun_azimuth_deg=(-60.0, -100.0), sun_elevation_deg=(40.0, 20.0), sun_irradiance=1.0)
    cells = np.array([[0, 0], [0, 1], [0, 2], [1, 2], [1, 1], [1, 0]])
    np.testing.assert_allclose(d.capture_fraction(cells), np.arange(6) / 5)
    c = d.session_conditions(cells, rng=np.random.default_rng(1))
    np.testing.assert_allclose(np.linalg.norm(c["sun_dir"], axis=1), 1.0)
    np.testing.assert_allclose(np.degrees(np.arcsin(c["sun_dir"][[0, -1], 2])), [40.0, 20.0])
    np.testing.assert_allclose(np.degrees(np.arctan2(c["sun_dir"][[0, -1], 1], c["sun_dir"][[0, -1], 0])),
                               [-60.0, -100.0])
    np.testing.assert_allclose(c["transmission"], 1.0)  # no clouds
    # the same path by time: cell (1, 1) is capture 4 of 6, 4 x 1440 s after the first (4/5 of the session)
    az, el = np.radians(-60.0 - 40.0 * 0.8), np.radians(40.0 - 20.0 * 0.8)
    np.testing.assert_allclose(d.sun_direction(d.time_s(1, 1)),
                               [np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], atol=1e-12)


def test_a_capture_light_needs_exactly_one_sun_path_and_comes_with_windows():
    order = lane_order((2, 3))
    with pytest.raises(ValueError, match="one sun path"):
        CaptureLight(order=order, seconds_per_capture=40.0)
    with pytest.raises(ValueError, match="one sun path"):
        CaptureLight(order=order, seconds_per_capture=40.0, sun_azimuth_deg=(0.0, 0.0), sun_elevation_deg=(30.0, 30.0),
                     site_deg=(49.0, 8.4), start_utc="2006-07-01T10:00:00Z")
    light = CaptureLight(order=order, seconds_per_capture=40.0, sun_azimuth_deg=(0.0, 0.0),
                         sun_elevation_deg=(30.0, 30.0))
    with pytest.raises(ValueError, match="cloud layer"):  # the whole-sky view needs the drifting layer
        light.conditions(0, 0)
    with pytest.raises(ValueError, match="come together"):
        World(scene=Scene(name="x"), grid_origin=(0.0, 0.0), spacing=0.1, grid_shape=(2, 3), camera_height=0.6,
              capture_light=light)


def test_clouds_are_seeded_by_the_recording_session():
    d = CaptureLight(order=lane_order((11, 22)), seconds_per_capture=40.0, sun_azimuth_deg=(0.0, 0.0),
                     sun_elevation_deg=(30.0, 30.0), sun_irradiance=1.0, cloud_sigma=1.0, cloud_images=5.0)
    cells = np.argwhere(np.ones((11, 22), bool))
    a = d.session_conditions(cells, rng=stream(session_seed(0), "daylight/clouds"))["transmission"]
    b = d.session_conditions(cells, rng=stream(session_seed(0), "daylight/clouds"))["transmission"]
    c = d.session_conditions(cells, rng=stream(session_seed(1), "daylight/clouds"))["transmission"]
    np.testing.assert_array_equal(a, b)
    assert not np.allclose(a, c)
    assert np.all(a > 0) and 0.5 < np.mean(a) < 1.5 and np.std(np.log(a)) == pytest.approx(1.0, abs=0.3)
    # neighbours in capture order are correlated (clouds last several images)
    order = np.argsort(d.capture_fraction(cells))
    z = np.log(a[order])
    assert np.corrcoef(z[:-1], z[1:])[0, 1] > 0.6


@pytest.mark.slow
@pytest.mark.parametrize("name", ["sim_moeller1", "sim_roeben1"])
def test_living_rooms_are_recorded_in_daylight_and_ideal_ignores_it(name, tmp_path):
    world = get_spec(name).builder(0)
    assert world.capture_light is not None and world.capture_light.sun_irradiance > 0
    assert isinstance(world.aperture, Windows)
    kw = dict(image_size=(48, 8), cache_dir=tmp_path)
    cam = synthetic_database(name, realism="camera", **kw)
    assert cam.images.shape[0] == int(np.prod(world.grid_shape))
    # without the sun the camera images change (the cache key knows the daylight too)
    dark = replace(world.capture_light, sun_irradiance=0.0)
    orig = get_spec(name).builder

    def build_dark(seed):
        w = orig(seed)
        w.capture_light = dark
        return w

    import bionav.db.synthetic as syn

    spec = syn.SYNTHETIC_DATABASES[name]
    syn.SYNTHETIC_DATABASES[name] = replace(spec, builder=build_dark)
    try:
        cam_dark = synthetic_database(name, realism="camera", **kw)
        ideal_dark = synthetic_database(name, realism="ideal", **kw)
    finally:
        syn.SYNTHETIC_DATABASES[name] = spec
    assert cam_dark.meta["cache_file"] != cam.meta["cache_file"]
    assert not np.array_equal(cam_dark.images, cam.images)
    ideal = synthetic_database(name, realism="ideal", **kw)
    np.testing.assert_array_equal(ideal.images, ideal_dark.images)


def test_the_supervisor_stands_behind_the_robot_facing_it():
    sup = Supervisor(room=(4.0, 4.0), distance_m=1.2, jitter_m=0.0, margin_m=0.3, lane_axis=1)
    cells = np.array([[0, 5], [1, 5], [0, 0]])
    xy = np.array([[2.0, 2.0], [2.1, 2.0], [2.0, 0.5]])
    feet, yaw = sup.stances(cells, xy, seed=0)
    # lane 0 drives towards +y (the person is at -y), lane 1 back towards -y; clipped 0.3 m from the wall
    np.testing.assert_allclose(feet, [[2.0, 0.8], [2.1, 3.2], [2.0, 0.3]])
    np.testing.assert_allclose(yaw, [np.pi / 2, -np.pi / 2, np.pi / 2])
    jittered = Supervisor(room=(4.0, 4.0), jitter_m=0.3).stances(cells, xy, seed=3)[0]
    np.testing.assert_array_equal(jittered, Supervisor(room=(4.0, 4.0), jitter_m=0.3).stances(cells, xy, seed=3)[0])
    assert not np.allclose(jittered, Supervisor(room=(4.0, 4.0), jitter_m=0.3).stances(cells, xy, seed=4)[0])


def test_the_supervisor_is_seen_where_he_stands_and_nowhere_else():
    world = _empty_room()
    world.capture_light, world.aperture = None, None
    world.supervisor = Supervisor(room=ROOM[:2], distance_m=1.2, jitter_m=0.0)
    scene_at = world.capture_scenes(np.array([[0, 0]]), seed=session_seed(0, 0))
    eye = world.cell_position(0, 0)  # (2.0, 2.0, 0.6): lane 0, the person stands at (2.0, 0.8)
    seen = scene_at(0)
    torso, beside = (2.0, 0.8, 1.2), (3.0, 0.8, 1.2)
    wall = _radiance_towards(world.scene, eye, torso)
    assert _radiance_towards(seen, eye, torso) != pytest.approx(wall, rel=1e-3)  # the shirt, not the wall
    assert _radiance_towards(seen, eye, beside) == pytest.approx(_radiance_towards(world.scene, eye, beside))
    assert World(scene=world.scene, grid_origin=(2.0, 2.0), spacing=0.1, grid_shape=(1, 1),
                 camera_height=0.6).capture_scenes(np.array([[0, 0]]), seed=0) is None


def test_one_capture_light_outdoors_and_through_windows_agree():
    """The uni capture's light (ephemeris, drifting layer) seen through windows gives the whole-sky view's sun."""
    from bionav.world.worlds.outdoor import build_uni, uni_capture_light

    world = build_uni(0)
    light = uni_capture_light(world.cells, 0)
    cells = np.argwhere(world.cells)[[0, 40, 100, -1]]
    through = light.session_conditions(cells, rng=np.random.default_rng(0))
    for k, (i, j) in enumerate(cells):
        whole = light.conditions(i, j)
        np.testing.assert_allclose(through["sun_dir"][k], whole["sun"], atol=1e-12)
        assert through["transmission"][k] == pytest.approx(whole["sun_transmittance"], abs=1e-12)
    np.testing.assert_allclose(through["fraction"], light.order[cells[:, 0], cells[:, 1]] / (light.n_captures - 1))
