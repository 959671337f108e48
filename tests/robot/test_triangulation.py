"""Triangulation of the distance to the previous lane, and the choice of the snapshot pair."""

from dataclasses import dataclass

import numpy as np
import pytest

from bionav.homing.base import HomeVector, HomingMethod
from bionav.plugins.controllers.triangulation import MapNode, TriangulationConfig, TriangulationController
from bionav.robot.controller import LanePlan
from bionav.robot.kinematics import Pose
from bionav.robot.triangulation import intersection_angle, lateral_error_std, triangulate


def test_worked_example():
    # SS1 = (0, 0), SS2 = (0.6, 0), CV = (0.3, 0.3): bearings -135 and -45 degrees, 90 degrees apart
    t = triangulate(0.6, np.radians(-135), np.radians(-45))
    assert (t.x, t.y) == pytest.approx((0.3, 0.3))
    assert t.gamma == pytest.approx(np.pi / 2)
    assert (t.t1, t.t2) == pytest.approx((0.3 * np.sqrt(2), 0.3 * np.sqrt(2)))
    assert t.consistent
    # CV = (0.5, -1): right of the lane, h = -1
    t = triangulate(1.0, np.arctan2(1, -0.5), np.arctan2(1, 0.5))
    assert (t.x, t.y) == pytest.approx((0.5, -1.0))
    # bearings pointing away from the snapshots: an inconsistent triangle
    t = triangulate(0.6, np.radians(-135) + np.pi, np.radians(-45) + np.pi)
    assert not t.consistent


def test_random_geometry_round_trip():
    rng = np.random.default_rng(0)
    for _ in range(200):
        d = rng.uniform(0.1, 2.0)
        cv = rng.uniform(-2, 2, size=2)
        if abs(cv[1]) < 0.05:
            continue
        b1 = np.arctan2(-cv[1], -cv[0])
        b2 = np.arctan2(-cv[1], d - cv[0])
        t = triangulate(d, b1, b2)
        assert (t.x, t.y) == pytest.approx(tuple(cv), abs=1e-9)


def test_parallel_bearings_give_nan():
    t = triangulate(0.5, 0.3, 0.3)
    assert np.isnan(t.y) and t.gamma == 0.0


def test_error_propagation_matches_finite_differences():
    d, b1, b2, eps = 0.7, np.radians(-150), np.radians(-60), 1e-6
    h = lambda a, b: triangulate(d, a, b).y  # noqa: E731
    g1 = (h(b1 + eps, b2) - h(b1 - eps, b2)) / (2 * eps)
    g2 = (h(b1, b2 + eps) - h(b1, b2 - eps)) / (2 * eps)
    s = 0.05
    assert lateral_error_std(d, b1, b2, bearing_std=s) == pytest.approx(s * np.hypot(g1, g2), rel=1e-6)
    assert lateral_error_std(d, b1, b2, bearing_std=0.0, common_std=s) == pytest.approx(s * abs(g1 + g2), rel=1e-6)
    # a symmetric pair at +-a seen from h = 0.3 is best conditioned at a = h, sigma_h = sqrt(2) h sigma
    a = np.linspace(0.05, 1.5, 2901)
    sig = lateral_error_std(2 * a, np.arctan2(-0.3, -a), np.arctan2(-0.3, a), bearing_std=s)
    assert a[np.argmin(sig)] == pytest.approx(0.3, abs=1e-3)
    assert sig.min() == pytest.approx(np.sqrt(2) * 0.3 * s, rel=1e-6)
    assert intersection_angle(np.radians(170), np.radians(-170)) == pytest.approx(np.radians(20))


@dataclass
class NoParameters:
    pass


class FixedHoming(HomingMethod):
    """Returns pre-set home vectors, keyed by snapshot id."""

    Config = NoParameters

    def __init__(self, vectors):
        super().__init__(None, geometry=None)
        self.vectors = vectors

    def home_vector(self, snapshot, current, *, neighbours=None):
        return self.vectors[snapshot]


def make_controller(nodes_x, *, robot_x=0.0, h=0.3, **cfg):
    plan = LanePlan(n_lanes=3, lane_length=4.0)
    c = TriangulationController(TriangulationConfig(**cfg))
    c.reset(plan, homing=FixedHoming({}))
    c.lane = 1
    c.origin_in_prev = Pose(4.0, 0.3, np.pi)  # lane 1 starts across from the end of lane 0
    c.est = Pose(4.0 - robot_x, 0.3 - h, 0.0)  # robot at x = robot_x along lane 0, h from it
    prev = [MapNode(i, 0, x, 0.0, Pose(x, 0.0, 0.0), i) for i, x in enumerate(nodes_x)]
    c._current = "current"
    return c, prev


def test_pair_choice_prefers_good_conditioning():
    # snapshots every 0.1 m around the robot at x = 2: the best pair lies near +-h = +-0.3
    c, prev = make_controller(np.round(np.arange(1.0, 3.01, 0.1), 6), robot_x=2.0)
    n1, n2, sigma = c.choose_pair(prev)
    assert (n1.x, n2.x) == pytest.approx((1.7, 2.3))
    assert sigma == pytest.approx(np.sqrt(2) * 0.3 * np.radians(5.0), rel=1e-6)


def test_bad_pair_rejected():
    # only snapshots far ahead: every pair is seen under less than 30 degrees -> no pair at all
    c, prev = make_controller([3.8, 3.9, 4.0], robot_x=2.0, max_snapshot_distance=3.0)
    gam = intersection_angle(np.arctan2(-0.3, 1.8), np.arctan2(-0.3, 2.0))
    assert np.degrees(gam) < 30
    assert c.choose_pair(prev) is None
    # a pair that looked fine but whose measured bearings intersect under 10 degrees is rejected
    c, prev = make_controller([1.7, 2.3], robot_x=2.0)
    c.homing = FixedHoming({0: HomeVector(np.pi + 0.05, 0.0), 1: HomeVector(np.pi - 0.05, 0.0)})
    out = c.measure(prev[0], prev[1], Pose(0, 0, np.pi))
    assert not out["accepted"] and out["reason"] == "ill-conditioned bearings"
    # the same pair with the true bearings is accepted and gives h = 0.3 m
    # robot heading pi in the lane-0 frame: SS1 (behind along lane 0) is ahead-right of the robot
    a1 = np.arctan2(-0.3, -0.3) - np.pi
    a2 = np.arctan2(-0.3, 0.3) - np.pi
    c.homing = FixedHoming({0: HomeVector(a1, np.pi), 1: HomeVector(a2, np.pi)})
    out = c.measure(prev[0], prev[1], Pose(0, 0, np.pi))
    assert out["accepted"], out
    assert out["h"] == pytest.approx(0.3) and out["e"] == pytest.approx(0.0, abs=1e-12)
    assert out["snapshots"] == [0, 1]
