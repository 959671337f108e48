"""Controllers driving the simulated robot, with perfect home vectors from true geometry."""

import numpy as np
import pytest

from bionav.robot.worldview import oracle_world
from bionav.plugins.controllers.odometry import OdometryConfig, OdometryController
from bionav.plugins.controllers.random_bounce import RandomConfig, RandomController
from bionav.plugins.controllers.triangulation import TriangulationConfig, TriangulationController
from bionav.robot.controller import LanePlan
from bionav.robot.coverage import Raster, coverage_fractions, sweep_counts
from bionav.robot.kinematics import DriveModel, Pose
from bionav.robot.oracle import GeometricHoming, GeometricHomingConfig, oracle_camera
from bionav.robot.simulator import SimulatedRobot, run_episode

PLAN = LanePlan(n_lanes=4, lane_length=1.5)


def simulate(controller, *, wheel_error=(0.05, -0.05), homing=None, plan=PLAN, seed=0):
    world = oracle_world(plan)
    lo, hi = plan.target_rectangle()
    controller.reset(plan, homing=homing, rng=np.random.default_rng(seed))
    robot = SimulatedRobot(DriveModel(wheel_error=wheel_error), world.start, floor=world.floor,
                           camera=oracle_camera if controller.uses_camera else None,
                           confine=(lo, hi, world.start) if controller.confined else None,
                           rng=np.random.default_rng(seed + 1))
    return run_episode(controller, robot, max_time=2000)


def lane_offsets(ep, plan):
    """Mean true y of each lane's middle part (plan frame), from the lane start/end events."""
    ticks = {}
    for t, info in ep.info:
        if "lane_start" in info:
            ticks.setdefault(info["lane_start"], [None, None])[0] = t
        if "lane_end" in info:
            ticks.setdefault(info["lane_end"], [0, None])[1] = t
    out = []
    for k in range(plan.n_lanes):
        a, b = ticks[k]
        p = ep.true_pose[a:b]
        mid = (p[:, 0] > 0.4) & (p[:, 0] < plan.lane_length - 0.4)
        out.append(p[mid, 1].mean())
    return np.array(out)


@pytest.mark.parametrize("wheel_error", [(0.05, -0.05), (-0.05, 0.05)])
def test_triangulation_keeps_lanes_030_apart(wheel_error):
    ctrl = TriangulationController(TriangulationConfig())
    ep = simulate(ctrl, wheel_error=wheel_error, homing=GeometricHoming())
    assert ep.finished
    fixes = [i["fix"] for _, i in ep.info if "fix" in i]
    accepted = [f for f in fixes if f["accepted"]]
    assert len(accepted) >= 0.95 * len(fixes) > 30
    # the triangulated distance to the previous lane stays at 0.30 m
    h = np.abs([f["h"] for f in accepted])
    assert np.median(np.abs(h - 0.30)) < 0.01
    assert np.max(np.abs(h - 0.30)) < 0.05
    # and so does the true spacing of the lanes
    y = lane_offsets(ep, PLAN)
    np.testing.assert_allclose(np.diff(y), 0.30, atol=0.015)
    # the controller learned the wheel error: kappa = (e_r - e_l) / b rad per metre
    assert ctrl.kappa == pytest.approx((wheel_error[1] - wheel_error[0]) / 0.30, rel=0.15)


def test_odometry_meander_is_perfect_without_wheel_error_and_drifts_with_it():
    ep = simulate(OdometryController(OdometryConfig()), wheel_error=(0.0, 0.0))
    assert ep.finished
    np.testing.assert_allclose(lane_offsets(ep, PLAN), 0.30 * np.arange(4), atol=0.01)
    ep = simulate(OdometryController(OdometryConfig()), wheel_error=(0.05, -0.05))
    # the first lane follows the wall; afterwards the unknown error bends the lanes away
    p = ep.true_pose
    assert np.max(np.abs(p[20:140, 1])) < 0.02
    lane1 = [t for t, i in ep.info if i.get("lane_start") == 1][0]
    end1 = [t for t, i in ep.info if i.get("lane_end") == 1][0]
    assert np.max(np.abs(p[lane1:end1, 1] - 0.30)) > 0.1


def test_triangulation_beats_odometry_coverage():
    plan = PLAN
    lo, hi = plan.target_rectangle()
    raster = Raster.around(lo, hi, cell=0.01, margin=0.5)
    target = raster.rectangle_mask(lo, hi)
    tri = simulate(TriangulationController(TriangulationConfig()), homing=GeometricHoming(
        GeometricHomingConfig(angle_noise_deg=3.0, compass_noise_deg=2.0, seed=1)))
    odo = simulate(OdometryController(OdometryConfig()))
    f_tri = coverage_fractions(sweep_counts(tri.true_pose, raster), target)
    f_odo = coverage_fractions(sweep_counts(odo.true_pose, raster), target)
    assert f_tri["coverage"] > f_odo["coverage"] + 0.1
    assert f_tri["uncovered"] < f_odo["uncovered"]


def test_random_bounce_stays_inside_and_stops():
    plan = LanePlan(n_lanes=3, lane_length=1.0)
    ctrl = RandomController(RandomConfig())
    ep = simulate(ctrl, plan=plan, seed=4)
    assert ep.finished
    lo, hi = plan.target_rectangle()
    p = ep.true_pose
    assert np.all((p[:, 0] >= lo[0] - 1e-9) & (p[:, 0] <= hi[0] + 1e-9))
    assert np.all((p[:, 1] >= lo[1] - 1e-9) & (p[:, 1] <= hi[1] + 1e-9))
    bumps = sum(1 for _, i in ep.info if i.get("bump"))
    assert bumps >= 3
    # it drove about the ideal meander's path length (odometry distance)
    d = np.sum(np.hypot(*np.diff(ep.odometry[:, :2], axis=0).T))
    assert d == pytest.approx(plan.ideal_path_length, rel=0.05)


def test_same_seed_same_commands():
    a = simulate(RandomController(RandomConfig()), plan=LanePlan(n_lanes=2, lane_length=1.0), seed=7)
    b = simulate(RandomController(RandomConfig()), plan=LanePlan(n_lanes=2, lane_length=1.0), seed=7)
    np.testing.assert_array_equal(a.command, b.command)


def test_blocked_moves_and_escape_from_a_slightly_bad_start():
    from bionav.robot.floorplan import FloorPlan

    floor = FloorPlan.from_shapes(rooms=[((-1.0, -1.0), (1.0, 1.0))])
    drive = DriveModel(wheel_error=(0.0, 0.0))
    # 0.165 m from the wall at x = 1 with radius 0.17: driving on towards the wall is blocked
    robot = SimulatedRobot(drive, Pose(0.835, 0.0, 0.0), floor=floor, radius=0.17)
    robot.apply(0.1, 0.1, 0.1)
    assert robot.bumper and robot.pose.x == 0.835 and robot.odometry.x == 0.0
    # turning on the spot is always possible, and driving away from the wall too
    robot.apply(-0.1, 0.1, np.pi / 2 * 0.3 / 0.2)
    assert not robot.bumper and robot.pose.theta == pytest.approx(np.pi / 2)
    robot.apply(-0.1, -0.1, 0.1)
    assert not robot.bumper
    # virtual walls: a centre 1 cm outside may move back in but not further out
    lo, hi = (0.0, 0.0), (1.0, 1.0)
    robot = SimulatedRobot(drive, Pose(-0.01, 0.5, np.pi), confine=(lo, hi, Pose(0, 0, 0)))
    robot.apply(0.1, 0.1, 0.1)
    assert robot.bumper
    robot.apply(-0.1, -0.1, 0.1)
    assert not robot.bumper and robot.pose.x == pytest.approx(0.0)


def test_track_width_is_the_robots_one_setting(tmp_path):
    """The controllers turn (v, omega) into wheel speeds with the robot's track width (issue 28: one setting)."""
    import dataclasses

    from helpers import assert_fails_cleanly, run_bionav

    for config_cls in (OdometryConfig, TriangulationConfig, RandomConfig):
        assert "track_width" not in {f.name for f in dataclasses.fields(config_cls)}
    ctrl = OdometryController(OdometryConfig(), track_width=0.5)
    # a turn on the spot at 1 rad/s: the wheels run at -/+ omega * b / 2
    assert ctrl._wheels(0.0, 1.0) == pytest.approx((-0.25, 0.25))
    assert OdometryController(OdometryConfig())._wheels(0.0, 1.0) == pytest.approx((-0.15, 0.15))  # default 0.30 m
    proc = run_bionav("experiment=cleaning", "controller.track_width=0.4", f"hydra.run.dir={tmp_path / 'run'}",
                      cwd=tmp_path)
    # the moved setting is named with its one home (it was a bare "unknown key" before the hint)
    assert_fails_cleanly(proc, "controller.track_width is no longer a setting", "pass experiment.track_width=",
                         code=2)
