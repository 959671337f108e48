"""Odometry heading drift of the stand-ins (db.pose_error.heading_drift_deg, World.heading_drift_deg)."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

from bionav.db.camera import (
    camera_images,
    camera_setup,
    lane_heading_drift,
    noise_rng,
    pose_error_config_for,
    pose_offsets,
    raw_frame_from_radiance,
    resolve_pose_error,
    unfold_frame,
)
from bionav.db.config import CameraConfig
from bionav.db.synthetic import SYNTHETIC_DATABASES, get_spec
from bionav.world.catadioptric import render_raw_frame
from bionav.world.scene import Scene
from bionav.world.worlds.common import World

CLEAN = dict(psf_sigma_px=0.0, vignetting=0.0, auto_exposure=False, full_well_e=1e7, read_noise_e=0.0)


def test_drift_is_a_random_walk_over_the_lane_turns():
    n_lanes = 3000
    cells = np.array([[i, j] for i in range(n_lanes) for j in (0, 5)])
    d = lane_heading_drift(cells, drift_sigma_deg=4.0, seed=2, db_seed=1)
    per_lane = d[::2]
    assert np.array_equal(d[::2], d[1::2])  # every cell of a lane has its lane's drift
    assert per_lane[0] == 0.0  # the first lane is driven before any turn
    steps = np.diff(per_lane)
    assert np.degrees(steps.std()) == pytest.approx(4.0, rel=0.05)  # one Gaussian step per turn
    assert abs(np.corrcoef(steps[:-1], steps[1:])[0, 1]) < 0.1  # independent steps (SE 0.018): a walk
    # a lane's drift does not depend on which other cells are rendered
    alone = lane_heading_drift([[17, 3]], drift_sigma_deg=4.0, seed=2, db_seed=1)
    assert alone[0] == per_lane[17]
    # other seeds draw other walks; no drift without a sigma
    assert lane_heading_drift([[17, 3]], drift_sigma_deg=4.0, seed=3, db_seed=1)[0] != per_lane[17]
    assert np.all(lane_heading_drift(cells[:10], drift_sigma_deg=0.0, seed=2) == 0.0)
    # linear in the sigma (the same walk, scaled)
    np.testing.assert_allclose(lane_heading_drift(cells[:40], drift_sigma_deg=8.0, seed=2, db_seed=1), 2 * d[:40])


@pytest.mark.slow
def test_the_world_floor_sets_the_drift_unless_the_config_does():
    world = World(scene=Scene(), grid_origin=(0, 0), spacing=1.0, grid_shape=(1, 1), camera_height=0.5,
                  heading_drift_deg=7.0)
    pe = pose_error_config_for("semi-automatic")
    assert pe.heading_drift_deg is None and resolve_pose_error(pe, world).heading_drift_deg == 7.0
    assert resolve_pose_error(pose_error_config_for("semi-automatic", heading_drift_deg=0.0),
                              world).heading_drift_deg == 0.0
    drift = {n: get_spec(n).builder(0).heading_drift_deg for n in SYNTHETIC_DATABASES}
    # only the semi-automatically corrected living rooms drift; carpet (moeller1) more than tiles (roeben1)
    assert drift["sim_moeller1"] > drift["sim_roeben1"] > 0.0
    assert all(v == 0.0 for n, v in drift.items() if n not in ("sim_moeller1", "sim_roeben1"))


def test_camera_images_turn_each_capture_by_its_drift():
    spec = get_spec("sim_original")
    world = spec.builder(0)
    positions = np.argwhere(world.cells)
    positions = positions[np.isin(positions[:, 0], (0, 3))][[0, -1]]  # one cell in lane 0, one in lane 3
    geometry = spec.geometry(96, 14)
    cam = CameraConfig(**CLEAN)
    pe = pose_error_config_for("odometry", position_sigma_m=0.0, heading_sigma_deg=0.5, tilt_sigma_deg=0.0,
                               heading_drift_deg=20.0, seed=4)
    imgs, _, poses = camera_images(world, positions, geometry, camera=cam, pose_error=pe, seed=0)
    _, noise_heads = pose_offsets(positions, position_sigma_m=0.0, heading_sigma_deg=0.5, seed=4, db_seed=0)
    drift = lane_heading_drift(positions, drift_sigma_deg=20.0, seed=4, db_seed=0)
    assert drift[0] == 0.0 and abs(drift[1]) > math.radians(1.0)
    np.testing.assert_allclose(poses["heading_errors"], noise_heads + drift)
    setup = camera_setup(cam, geometry)
    for k, (i, j) in enumerate(positions):
        rad = render_raw_frame(world.scene, position=world.cell_position(i, j), heading=float(noise_heads[k] + drift[k]),
                               layout=setup.layout)
        assert np.array_equal(unfold_frame(raw_frame_from_radiance(rad, setup, rng=noise_rng(0, (i, j))), setup, geometry),
                              imgs[k])


def test_a_negative_drift_is_refused_through_the_cli(tmp_path):
    r = subprocess.run([sys.executable, "-m", "bionav", "experiment=grid_homing", "db=sim_moeller1",
                        "db.pose_error.heading_drift_deg=-2", f"hydra.run.dir={tmp_path / 'run'}"],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode != 0
    assert "db.pose_error.heading_drift_deg" in r.stderr and "Traceback" not in r.stderr
