"""Daylight during the recording of the living-room stand-ins (``Daylight``, camera model only)."""

from __future__ import annotations

import numpy as np
import pytest

from bionav.db.camera import capture_scenes, session_seed
from bionav.db.synthetic import get_spec, synthetic_database
from bionav.world.lights import Ambient
from bionav.world.render import render_ray_grid
from bionav.world.scene import Scene
from bionav.world.worlds.common import Daylight, Supervisor, World

ROOM = (4.0, 4.0, 2.5)
WINDOW = ("y0", 1.5, 2.5, 1.0, 2.0)  # on the wall y = 0, x 1.5 .. 2.5, z 1.0 .. 2.0


def _empty_room() -> World:
    """A plain room (albedo 0.5, no lamps, ambient 0.1) with one window on the wall y = 0."""
    scene = Scene(name="empty room")
    grey = scene.material(albedo=0.5)
    scene.box((0, 0, 0), ROOM, grey, inside=True, shadow=False)
    scene.ambient = Ambient(up=0.1, down=0.1)
    scene.exposure = 1.0
    daylight = Daylight(room=ROOM, windows=(WINDOW,), sun_azimuth_deg=(-90.0, -90.0), sun_elevation_deg=(45.0, 45.0),
                        sun_irradiance=2.0, duration_h=1.0, cloud_sigma=0.0, lane_axis=1)
    return World(scene=scene, grid_origin=(2.0, 2.0), spacing=0.1, grid_shape=(1, 1), camera_height=0.6,
                 daylight=daylight)


def _radiance_towards(scene, eye, target) -> float:
    d = np.asarray(target, float) - np.asarray(eye, float)
    az = np.arctan2(d[1], d[0])
    el = np.arctan2(d[2], np.hypot(d[0], d[1]))
    return float(render_ray_grid(scene, position=eye, azimuths=np.array([az]), elevations=np.array([el]),
                                 pixel_angle=1e-3)[0, 0, 0])


def test_the_sun_lights_the_floor_only_where_it_enters_through_the_window():
    world = _empty_room()
    scene_at = capture_scenes(world, np.array([[0, 0]]), seed=0, db_seed=0)
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
    d = Daylight(room=ROOM, windows=(WINDOW,), sun_azimuth_deg=(-60.0, -100.0), sun_elevation_deg=(40.0, 20.0),
                 sun_irradiance=1.0, duration_h=2.0, lane_axis=1)
    cells = np.array([[0, 0], [0, 1], [0, 2], [1, 2], [1, 1], [1, 0]])
    np.testing.assert_allclose(d.capture_fraction(cells, (2, 3)), np.arange(6) / 5)
    c = d.conditions(cells, (2, 3), seed=1)
    np.testing.assert_allclose(np.linalg.norm(c["sun_dir"], axis=1), 1.0)
    np.testing.assert_allclose(np.degrees(np.arcsin(c["sun_dir"][[0, -1], 2])), [40.0, 20.0])
    np.testing.assert_allclose(np.degrees(np.arctan2(c["sun_dir"][[0, -1], 1], c["sun_dir"][[0, -1], 0])),
                               [-60.0, -100.0])
    np.testing.assert_allclose(c["transmission"], 1.0)  # no clouds


def test_clouds_are_seeded_by_the_recording_session():
    d = Daylight(room=ROOM, windows=(WINDOW,), sun_azimuth_deg=(0.0, 0.0), sun_elevation_deg=(30.0, 30.0),
                 sun_irradiance=1.0, duration_h=2.0, cloud_sigma=1.0, cloud_images=5.0)
    cells = np.argwhere(np.ones((11, 22), bool))
    a = d.conditions(cells, (11, 22), seed=session_seed(0))["transmission"]
    b = d.conditions(cells, (11, 22), seed=session_seed(0))["transmission"]
    c = d.conditions(cells, (11, 22), seed=session_seed(1))["transmission"]
    np.testing.assert_array_equal(a, b)
    assert not np.allclose(a, c)
    assert np.all(a > 0) and 0.5 < np.mean(a) < 1.5 and np.std(np.log(a)) == pytest.approx(1.0, abs=0.3)
    # neighbours in capture order are correlated (clouds last several images)
    order = np.argsort(d.capture_fraction(cells, (11, 22)))
    z = np.log(a[order])
    assert np.corrcoef(z[:-1], z[1:])[0, 1] > 0.6


@pytest.mark.slow
@pytest.mark.parametrize("name", ["sim_moeller1", "sim_roeben1"])
def test_living_rooms_are_recorded_in_daylight_and_ideal_ignores_it(name, tmp_path):
    world = get_spec(name).builder(0)
    assert world.daylight is not None and world.daylight.sun_irradiance > 0
    kw = dict(image_size=(48, 8), cache_dir=tmp_path)
    cam = synthetic_database(name, realism="camera", **kw)
    assert cam.images.shape[0] == int(np.prod(world.grid_shape))
    # without the sun the camera images change (the cache key knows the daylight too)
    import bionav.world.worlds.common as common

    dark = common.Daylight(**{**world.daylight.__dict__, "sun_irradiance": 0.0})
    orig = get_spec(name).builder

    def build_dark(seed):
        w = orig(seed)
        w.daylight = dark
        return w

    from dataclasses import replace

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
    world.daylight = None
    world.supervisor = Supervisor(room=ROOM[:2], distance_m=1.2, jitter_m=0.0)
    scene_at = capture_scenes(world, np.array([[0, 0]]), seed=0, db_seed=0)
    eye = world.cell_position(0, 0)  # (2.0, 2.0, 0.6): lane 0, the person stands at (2.0, 0.8)
    seen = scene_at(0)
    torso, beside = (2.0, 0.8, 1.2), (3.0, 0.8, 1.2)
    wall = _radiance_towards(world.scene, eye, torso)
    assert _radiance_towards(seen, eye, torso) != pytest.approx(wall, rel=1e-3)  # the shirt, not the wall
    assert _radiance_towards(seen, eye, beside) == pytest.approx(_radiance_towards(world.scene, eye, beside))
    assert capture_scenes(World(scene=world.scene, grid_origin=(2.0, 2.0), spacing=0.1, grid_shape=(1, 1),
                                camera_height=0.6), np.array([[0, 0]]), seed=0) is None
