"""Coverage raster against hand-computed shapes."""

import numpy as np
import pytest

from bionav.robot.controller import LanePlan
from bionav.robot.coverage import Raster, coverage_fractions, sweep_counts, sweep_counts_reference
from bionav.robot.lanes import ideal_meander

CELL = 0.01
A = CELL * CELL


def stroke(p0, p1, n=50):
    th = np.arctan2(p1[1] - p0[1], p1[0] - p0[0])
    t = np.linspace(0, 1, n)[:, None]
    xy = np.asarray(p0) + t * (np.asarray(p1) - np.asarray(p0))
    return np.c_[xy, np.full(n, th)]


def test_straight_stroke_area():
    raster = Raster.around((-0.5, -0.5), (1.5, 0.5), cell=CELL)
    c = sweep_counts(stroke((0, 0), (1.2, 0)), raster, width=0.30)
    assert c.max() == 1
    assert c.sum() * A == pytest.approx(1.2 * 0.30, abs=1e-9)  # grid-aligned: exact
    # a diagonal stroke: L * w up to the discretisation of its outline (perimeter * cell / 2)
    c = sweep_counts(stroke((0.03, -0.2), (0.83, 0.4)), raster, width=0.30)
    L = np.hypot(0.8, 0.6)
    assert c.max() == 1
    assert c.sum() * A == pytest.approx(L * 0.30, abs=(2 * L + 0.6) * CELL / 2)


def test_two_parallel_overlapping_strokes():
    raster = Raster.around((-0.5, -0.5), (1.5, 0.8), cell=CELL)
    # two 1 m strokes 0.20 m apart, the second driven back: overlap strip 0.10 m wide
    poses = np.r_[stroke((0, 0), (1, 0)), stroke((1, 0.2), (0, 0.2))]
    # join them with a jump far away (the unit never sweeps between them)
    c = sweep_counts(stroke((0, 0), (1, 0)), raster) + sweep_counts(stroke((1, 0.2), (0, 0.2)), raster)
    assert np.count_nonzero(c >= 2) * A == pytest.approx(1.0 * 0.10, abs=1e-9)
    assert np.count_nonzero(c == 1) * A == pytest.approx(2 * 1.0 * 0.20, abs=1e-9)
    # one continuous trajectory: two strokes joined by a turn on the spot at (1, 0) / (1, 0.2) sweeps more,
    # but the strip 0 < x < 0.85 is only swept by the strokes
    assert poses.shape[1] == 3
    raster_mid = Raster.around((0.0, -0.15), (0.85, 0.35), cell=CELL)
    c2 = sweep_counts(poses, raster_mid)
    assert np.count_nonzero(c2 >= 2) * A == pytest.approx(0.85 * 0.10, abs=1e-9)


def test_crossing_strokes_overlap_square():
    raster = Raster.around((-1, -1), (1, 1), cell=CELL)
    c = sweep_counts(stroke((-0.6, 0.0), (0.6, 0.0)), raster) + sweep_counts(stroke((0.0, -0.6), (0.0, 0.6)), raster)
    assert np.count_nonzero(c == 2) * A == pytest.approx(0.30 * 0.30, abs=1e-9)


def test_passes_are_counted_per_visit():
    raster = Raster.around((-0.5, -0.5), (1.5, 0.5), cell=CELL)
    # forth and back on the same line with a 180 degree turn on the spot at the far end
    th = np.linspace(0, np.pi, 60)
    back = np.c_[stroke((1, 0), (0, 0))[:, :2], np.full(50, np.pi)]
    poses = np.r_[stroke((0, 0), (1, 0)), np.c_[np.ones(60), np.zeros(60), th], back]
    c = sweep_counts(poses, raster)
    # the strip x in [0, 0.85] was swept exactly twice (forth and back)
    xc, yc = raster.centres()
    strip = (xc[None, :] > 0) & (xc[None, :] < 0.85) & (np.abs(yc)[:, None] < 0.15)
    assert np.all(c[strip] == 2)
    # standing still does not split a pass
    still = np.r_[stroke((0, 0), (0.5, 0)), np.repeat(stroke((0.5, 0), (1, 0))[:1], 20, axis=0), stroke((0.5, 0), (1, 0))]
    assert sweep_counts(still, raster).max() == 1


def test_kernel_equals_reference():
    rng = np.random.default_rng(3)
    steps = rng.normal(size=(40, 3)) * [0.03, 0.03, 0.2]
    poses = np.cumsum(steps, axis=0)
    raster = Raster.around((-0.6, -0.6), (0.6, 0.6), cell=0.02)
    np.testing.assert_array_equal(sweep_counts(poses, raster), sweep_counts_reference(poses, raster))


def test_fractions_and_ideal_meander():
    counts = np.array([[0, 1], [2, 3]])
    f = coverage_fractions(counts, np.ones((2, 2), bool))
    assert f == {"coverage": 0.25, "overlap": 0.5, "uncovered": 0.25}
    # the ideal meander leaves nothing uncovered; its only overlap is where turns on the spot and
    # lane changes sweep the ends of the lanes
    plan = LanePlan(n_lanes=3, lane_length=2.0)
    lo, hi = plan.target_rectangle()
    assert lo == pytest.approx((0.0, -0.15)) and hi == pytest.approx((2.0, 0.75))
    r = Raster.around(lo, hi, cell=CELL, margin=0.3)
    f = coverage_fractions(sweep_counts(ideal_meander(plan), r), r.rectangle_mask(lo, hi))
    assert f["uncovered"] == 0.0
    # overlap only within 0.15 m of the two lane-change ends, at most two 0.15 x 0.6 m corners per change
    assert 0 < f["overlap"] * 2.0 * 0.9 <= 2 * 0.15 * 0.6 + 1e-9
