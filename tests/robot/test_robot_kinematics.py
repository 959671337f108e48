"""Differential-drive kinematics against closed forms."""

import numpy as np
import pytest

from bionav.robot.kinematics import DriveModel, Pose, body_velocity, integrate_pose, wheel_speeds


def test_arc_of_known_radius():
    # wheels 0.3 m apart at 0.09 and 0.11 m/s: v = 0.1, omega = 0.02/0.3, R = v/omega = 1.5 m
    b, vl, vr = 0.3, 0.09, 0.11
    v, omega = body_velocity(vl, vr, track_width=b)
    assert v == pytest.approx(0.1)
    assert omega == pytest.approx(0.02 / 0.3)
    R = v / omega
    assert R == pytest.approx(1.5)
    # a quarter circle starting at the origin heading +x: centre at (0, R), end at (R, R) heading +y
    t = (np.pi / 2) / omega
    end = integrate_pose(Pose(0.0, 0.0, 0.0), vl, vr, t, track_width=b)
    assert (end.x, end.y, end.theta) == pytest.approx((R, R, np.pi / 2), abs=1e-12)
    # integrating in 1000 small steps gives the same point (the update is exact)
    p = Pose(0.0, 0.0, 0.0)
    for _ in range(1000):
        p = integrate_pose(p, vl, vr, t / 1000, track_width=b)
    assert (p.x, p.y, p.theta) == pytest.approx((R, R, np.pi / 2), abs=1e-9)
    # every intermediate point lies on the circle
    q = integrate_pose(Pose(0.0, 0.0, 0.0), vl, vr, 0.37 * t, track_width=b)
    assert np.hypot(q.x, q.y - R) == pytest.approx(R, abs=1e-12)


def test_straight_line_and_turn_on_the_spot():
    p = integrate_pose(Pose(1.0, 2.0, np.pi / 3), 0.2, 0.2, 5.0, track_width=0.3)
    assert (p.x, p.y, p.theta) == pytest.approx((1.0 + np.cos(np.pi / 3), 2.0 + np.sin(np.pi / 3), np.pi / 3))
    q = integrate_pose(Pose(1.0, 2.0, 0.0), -0.15, 0.15, 1.0, track_width=0.3)
    assert (q.x, q.y, q.theta) == pytest.approx((1.0, 2.0, 1.0))
    assert wheel_speeds(0.1, 1.0, track_width=0.3) == pytest.approx((-0.05, 0.25))


def test_static_wheel_error_is_invisible_to_odometry():
    # +5 % left / -5 % right: commanded straight, the robot really turns right with
    # kappa = (e_r - e_l) / b = -0.1 / 0.3 rad per metre
    drive = DriveModel(track_width=0.3, wheel_error=(0.05, -0.05))
    vl, vr = drive.true_speeds(0.1, 0.1)
    true = integrate_pose(Pose(0, 0, 0), vl, vr, 10.0, track_width=0.3)
    odo = integrate_pose(Pose(0, 0, 0), 0.1, 0.1, 10.0, track_width=0.3)
    assert (odo.x, odo.y, odo.theta) == pytest.approx((1.0, 0.0, 0.0))
    assert true.theta == pytest.approx(-0.1 / 0.3 * 1.0)
    R = 0.3 / 0.1
    assert (true.x, true.y) == pytest.approx((R * np.sin(1 / R), -R * (1 - np.cos(1 / R))))


def test_pose_compose_and_relative_are_inverse():
    a = Pose(0.3, -1.2, 2.5)
    b = Pose(-0.7, 0.4, -2.9)
    r = b.relative_to(a)
    back = a.compose(r)
    assert (back.x, back.y, back.theta) == pytest.approx((b.x, b.y, b.theta))
    # a point 1 m ahead of a pose heading +y lies at +1 along x of that pose's frame
    assert Pose(0, 1, 0).relative_to(Pose(0, 0, np.pi / 2)).as_tuple() == pytest.approx((1, 0, -np.pi / 2))
