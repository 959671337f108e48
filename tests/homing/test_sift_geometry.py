"""SIFT homing's per-correspondence home angle (eq. 5.12) against worked triangles."""

import numpy as np
import pytest

from bionav.homing.sift_homing import combine_home_angles, correspondence_home_angles


def _observe(cam, landmark):
    """Azimuth (CCW) and elevation of a 3-D landmark from a camera at height 0."""
    d = np.asarray(landmark[:2], float) - np.asarray(cam, float)
    return np.arctan2(d[1], d[0]), np.arctan2(landmark[2], np.hypot(*d))


@pytest.mark.parametrize(
    "snapshot, current, landmark",
    [
        ((0, 0), (3, 0), (1.5, 4.0, 1.0)),      # landmark beside the path
        ((0, 0), (2, 2), (-3.0, 1.0, 0.5)),     # behind the snapshot: r < cos(dx) -- printed arctan's bad quadrant
        ((1, -2), (0, 0), (4.0, 4.0, -0.7)),    # below the horizon
        ((0, 0), (-1, 3), (0.5, -2.0, 2.0)),
        ((5, 5), (4, 1), (4.5, 3.0, 0.3)),      # landmark between the two positions
    ],
)
def test_home_angle_of_worked_triangles(snapshot, current, landmark):
    ts, es = _observe(snapshot, landmark)
    tc, ec = _observe(current, landmark)
    beta = correspondence_home_angles(ts, es, tc, ec)
    expected = np.arctan2(snapshot[1] - current[1], snapshot[0] - current[0])
    assert np.cos(beta - expected) == pytest.approx(1.0, abs=1e-12)


def test_equals_printed_formula_where_its_arctan_is_valid():
    rng = np.random.default_rng(1)
    ts, tc = rng.uniform(-np.pi, np.pi, 2)
    es, ec = 0.3, 0.45
    r = np.tan(ec) / np.tan(es)
    dx = tc - ts
    assert r - np.cos(dx) > 0
    printed = ts - np.arctan(np.sin(dx) / (r - np.cos(dx))) + np.pi
    got = correspondence_home_angles(ts, es, tc, ec)
    assert np.cos(got - printed) == pytest.approx(1.0, abs=1e-12)


def test_guard_ignores_landmarks_on_the_horizon_and_impossible_ratios():
    got = correspondence_home_angles(np.array([0.1, 0.1, 0.1]), np.array([0.005, 0.2, 0.2]),
                                     np.array([0.3, 0.3, 0.3]), np.array([0.2, -0.2, 0.25]))
    assert np.isnan(got[0]) and np.isnan(got[1]) and np.isfinite(got[2])


def test_combination_methods_hand_computed():
    angles = np.deg2rad([-46.2, -45.5, -44.7, -44.2, 120.0])
    assert np.rad2deg(combine_home_angles(angles, method="max", window=10)) == pytest.approx(-45.0, abs=5)
    avg = combine_home_angles(angles, method="average")
    # four angles share a ~2 degree span; the outlier has weight 1 against bins of weight 1..2
    assert -50 < np.rad2deg(avg) < -35
    assert np.isnan(combine_home_angles(np.array([np.nan])))
