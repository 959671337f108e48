"""The cleaning robot in a rendered world: floor plans from scenes, layout placement, the camera."""

import numpy as np
import pytest

from bionav.robot.controller import LanePlan
from bionav.robot.floorplan import FloorPlan, floorplan_from_scene
from bionav.robot.kinematics import Pose
from bionav.robot.worldview import place_plan, plan_clearance
from bionav.world.scene import Scene


def test_floorplan_from_scene():
    scene = Scene()
    m = scene.material()
    scene.box((0, 0, 0), (4, 3, 2.5), m, inside=True)  # the room
    scene.box((1, 1, 0), (1.5, 1.4, 0.8), m)  # a cabinet
    scene.box((2, 2, 0.7), (3, 2.6, 0.75), m)  # a table top: the robot drives under it
    scene.cylinder((2.1, 2.1), 0.0, 0.7, 0.03, material=m)  # its leg
    fp = floorplan_from_scene(scene, max_height=0.35)
    assert fp.is_wall.sum() == 4 and len(fp.segments) == 4 + 4 + 16
    # distances to the cabinet's faces, the wall, and under the table (only the leg is near)
    assert fp.clearance(1.25, 0.5) == pytest.approx(0.5)
    assert fp.clearance(0.2, 2.0) == pytest.approx(0.2)
    assert fp.clearance(2.6, 2.3) == pytest.approx(np.hypot(0.5, 0.2) - 0.03, abs=2e-3)
    assert fp.raycast(0.5, 1.2, 0.0) == pytest.approx(0.5)
    assert fp.enclosed(2.0, 1.5) and not fp.enclosed(5.0, 1.5)


def test_place_plan_along_a_wall_and_with_a_guide_wall():
    plan = LanePlan(n_lanes=3, lane_length=2.0)
    room = FloorPlan.from_shapes(rooms=[((0, 0), (3, 3))], boxes=[((1.5, 2.7), (1.5, 0.3), 0.0)])

    class World:
        free_area = (0.5, 0.5, 2.5, 2.2)

    placed = place_plan(World(), room, plan, robot_radius=0.17)
    assert not placed.guide_wall
    # the first lane runs 0.25 m from a wall on its right, every lane keeps clear of the furniture
    s = placed.start
    right = s.theta - np.pi / 2
    assert room.raycast(s.x, s.y, right) == pytest.approx(0.25)
    assert plan_clearance(room, plan, s) >= 0.17
    # a room whose walls are too short for a 4 m lane: a guide wall along the free area's edge
    long_plan = LanePlan(n_lanes=3, lane_length=4.0)
    # 1 m cabinets with gaps along every wall: no straight stretch of 4 m to follow
    cabinets = []
    for k in range(5):
        c = 0.6 + 1.2 * k
        cabinets += [((c, 0.3), (0.5, 0.3), 0.0), ((c, 5.7), (0.5, 0.3), 0.0),
                     ((0.3, c), (0.3, 0.5), 0.0), ((5.7, c), (0.3, 0.5), 0.0)]
    big = FloorPlan.from_shapes(rooms=[((0, 0), (6, 6))], boxes=cabinets)

    class Free:
        free_area = (0.8, 1.5, 5.2, 4.5)

    with_guide = place_plan(Free(), big, long_plan, robot_radius=0.17)
    assert with_guide.guide_wall
    g = with_guide.start
    assert with_guide.floor.raycast(g.x, g.y, g.theta - np.pi / 2) == pytest.approx(0.25)
    assert len(with_guide.floor.segments) == len(big.segments) + 1


def test_apartment_layouts_fit():
    from bionav.robot.worldview import load_world

    world = load_world("apartment", seed=0)
    floor = floorplan_from_scene(world.scene, max_height=0.35)
    for plan in (LanePlan(n_lanes=7, lane_length=4.0), LanePlan(n_lanes=14, lane_length=2.0)):
        placed = place_plan(world, floor, plan, robot_radius=0.17)
        assert plan_clearance(placed.floor, plan, placed.start) >= 0.17


def test_render_camera_is_deterministic_and_in_the_robot_frame():
    from bionav.geometry import PanoramaGeometry
    from bionav.robot.worldview import render_camera
    from bionav.world.worlds.apartment import build_apartment

    world = build_apartment(0)
    geo = PanoramaGeometry.square_pixels(72, 8)
    cam = render_camera(world.scene, geo, height=0.3, noise=0.01, seed=4)
    x, y = np.mean(np.reshape(world.free_area, (2, 2)), axis=0)
    a = cam(Pose(x, y, 0.0), 7)
    assert a.shape == (8, 72) and a.dtype == np.float32
    np.testing.assert_array_equal(a, cam(Pose(x, y, 0.0), 7))  # same capture: same noise
    assert not np.array_equal(a, cam(Pose(x, y, 0.0), 8))
    # turning the robot by 10 columns rolls its own-frame panorama by 10 columns
    clean = render_camera(world.scene, geo, height=0.3, noise=0.0)
    b = clean(Pose(x, y, 0.0), 0)
    c = clean(Pose(x, y, 2 * np.pi * 10 / 72), 0)
    np.testing.assert_allclose(c, np.roll(b, -10, axis=1), atol=1.5 / 255)
