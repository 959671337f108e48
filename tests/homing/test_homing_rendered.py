"""SIFT homing and MFDID point home on rendered pairs at known displacements."""

import numpy as np
import pytest

from bionav.geometry import PanoramaGeometry
from bionav.plugins.homing.mfdid import MfdidConfig, MfdidHoming
from bionav.plugins.homing.sift import SiftConfig, SiftHoming
from bionav.testing import assert_homing_plugin, assert_points_home

SNAPSHOT = (4, 8)
# (dx, dy) of the current view relative to the snapshot, in grid cells (0.3 m)
DISPLACEMENTS = [(3, 0), (-2, 2), (0, -4), (2, 3), (-3, -3), (1, -1)]


@pytest.fixture(scope="module")
def lab():
    from bionav.world.worlds.lab import build_lab

    return build_lab(0)


def _render(world, cell, geometry, heading=0.0):
    from bionav.world.render import render_panorama

    img = render_panorama(world.scene, position=world.cell_position(*cell), heading=heading, geometry=geometry)
    return img[..., 0] if img.ndim == 3 else img


@pytest.fixture(scope="module")
def rendered(lab):
    geometry = PanoramaGeometry.square_pixels(561, 81)
    snap = _render(lab, SNAPSHOT, geometry)
    currents = {d: _render(lab, (SNAPSHOT[0] + d[0], SNAPSHOT[1] + d[1]), geometry) for d in DISPLACEMENTS}
    return geometry, snap, currents


@pytest.mark.parametrize("cls", [SiftHoming, MfdidHoming])
def test_plugin_contract(cls):
    assert_homing_plugin(cls)


@pytest.mark.parametrize("d", DISPLACEMENTS)
def test_sift_points_home(rendered, d):
    geometry, snap, currents = rendered
    method = SiftHoming(SiftConfig(), geometry=geometry)
    hv = assert_points_home(method, snap, currents[d], expected_angle=np.arctan2(-d[1], -d[0]),
                            tolerance=np.deg2rad(15))
    assert hv.extras["correspondences"] > 20


@pytest.mark.parametrize("d", DISPLACEMENTS)
def test_mfdid_points_home(rendered, d):
    geometry, snap, currents = rendered
    method = MfdidHoming(MfdidConfig(), geometry=geometry)
    assert_points_home(method, snap, currents[d], expected_angle=np.arctan2(-d[1], -d[0]), tolerance=np.deg2rad(40))


def test_sift_combination_by_histogram_maximum(rendered):
    geometry, snap, currents = rendered
    method = SiftHoming(SiftConfig(combine="max"), geometry=geometry)
    assert_points_home(method, snap, currents[(3, 0)], expected_angle=np.pi, tolerance=np.deg2rad(15))
