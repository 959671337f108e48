"""Camera tilt of the stand-ins (uneven floors, World.floor_tilt_deg) against a closed form."""

from __future__ import annotations

import math

import numpy as np
import pytest

from bionav.db.camera import (
    camera_images,
    camera_setup,
    noise_rng,
    pose_error_config_for,
    raw_frame_from_radiance,
    resolve_pose_error,
    tilt_offsets,
    unfold_frame,
)
from bionav.db.config import CameraConfig
from bionav.db.synthetic import SYNTHETIC_DATABASES, get_spec
from bionav.db.unfold import unfold_panorama
from bionav.geometry import PanoramaGeometry
from bionav.world.catadioptric import render_raw_frame
from bionav.world.lights import Ambient
from bionav.world.scene import Scene
from bionav.world.worlds.common import World

CLEAN = dict(psf_sigma_px=0.0, vignetting=0.0, auto_exposure=False, full_well_e=1e7, read_noise_e=0.0)
E0 = math.radians(5.0)  # the world's only edge: a sky bright above 5 degrees elevation, dark below


def _edge_scene() -> Scene:
    s = Scene(ambient=Ambient(up=0.0, down=0.0), sky=lambda d: (d[:, 2:3] > math.sin(E0)).astype(float) * 0.8)
    s.box((100.0, 100.0, -2.0), (100.1, 100.1, -1.9), s.material(albedo=0.0), shadow=False)  # far below: unseen
    return s


def _edge_elevation(pano: np.ndarray, geometry: PanoramaGeometry) -> np.ndarray:
    """Per column, the elevation where the panorama crosses half the sky level (linear between rows)."""
    el = geometry.row_elevations()
    out = np.empty(pano.shape[1])
    for j in range(pano.shape[1]):
        col = pano[:, j]
        bright = int(np.flatnonzero(col >= 0.4)[0])  # the sky (rows beyond the mirror rim read 0)
        r = bright + int(np.flatnonzero(col[bright:] < 0.4)[0])  # the first dark row below it
        f = (col[r - 1] - 0.4) / (col[r - 1] - col[r])
        out[j] = el[r - 1] + f * (el[r] - el[r - 1])
    return out


def _edge_panorama(tilt) -> tuple[np.ndarray, PanoramaGeometry]:
    geometry = PanoramaGeometry.square_pixels(561, 81)
    setup = camera_setup(CameraConfig(**CLEAN), geometry, tilt_margin=float(np.abs(tilt).sum()))
    radiance = render_raw_frame(_edge_scene(), position=(0.0, 0.0, 0.0), heading=0.0, layout=setup.layout)
    raw = raw_frame_from_radiance(radiance, setup, rng=np.random.default_rng(0))
    return _edge_elevation(unfold_frame(raw, setup, geometry, tilt=tilt)[:, :, 0] / 255.0, geometry), geometry


@pytest.mark.parametrize("tilt_deg", [(2.0, 0.0), (-1.0, 2.5)])
def test_a_tilted_camera_sees_the_horizon_edge_where_the_small_angle_formula_puts_it(tilt_deg):
    upright, geometry = _edge_panorama(np.zeros(2))
    # the upright camera finds the edge at 5 deg up to the raw frame's sampling (a fifth of a 0.64 deg row)
    assert np.degrees(np.abs(upright - E0)).max() < 0.25
    tilt = np.radians(tilt_deg)
    tilted, _ = _edge_panorama(tilt)
    phi = 2 * np.pi * np.arange(geometry.width) / geometry.width
    # a view raised by t_a cos(phi) + t_b sin(phi) sees the world's edge that much lower in the panorama
    shift = tilt[0] * np.cos(phi) + tilt[1] * np.sin(phi)
    err = np.degrees(np.abs(tilted - (upright - shift)))
    # tolerance: bilinear sampling of the raw frame along the shifted radii (most columns are within 0.02 deg)
    assert err.max() < 0.25 and np.median(err) < 0.05
    assert np.degrees(np.abs(shift)).max() > 1.5  # the tilt moves the edge six times the tolerance


def test_unfold_with_per_pixel_radii_equal_per_row_radii():
    raw = np.random.default_rng(1).random((120, 160))
    radii = np.linspace(50.0, 20.0, 9)
    a = unfold_panorama(raw, center=(80.0, 60.0), radii=radii, size=(64, 9))
    b = unfold_panorama(raw, center=(80.0, 60.0), radii=np.repeat(radii[:, None], 64, axis=1), size=(64, 9))
    np.testing.assert_array_equal(a, b)
    with pytest.raises(ValueError, match="per pixel"):
        unfold_panorama(raw, center=(80.0, 60.0), radii=np.ones((9, 10)), size=(64, 9))


def test_tilts_have_the_stated_statistics_and_their_own_stream():
    t = tilt_offsets(np.argwhere(np.ones((200, 200), bool)), tilt_sigma_deg=2.0, seed=3, db_seed=1)
    assert np.degrees(t.std(axis=0)) == pytest.approx([2.0, 2.0], rel=0.02)
    assert abs(np.corrcoef(t[:, 0], t[:, 1])[0, 1]) < 0.02
    assert np.all(tilt_offsets([[0, 0], [1, 2]], tilt_sigma_deg=0.0, seed=3) == 0)


@pytest.mark.slow
def test_the_world_floor_sets_the_tilt_unless_the_config_does():
    world = World(scene=Scene(), grid_origin=(0, 0), spacing=1.0, grid_shape=(1, 1), camera_height=0.5,
                  floor_tilt_deg=1.7)
    pe = pose_error_config_for("odometry")
    assert pe.tilt_sigma_deg is None and resolve_pose_error(pe, world).tilt_sigma_deg == 1.7
    pe0 = pose_error_config_for("odometry", tilt_sigma_deg=0.0)
    assert resolve_pose_error(pe0, world).tilt_sigma_deg == 0.0
    # every stand-in states a tilt of at least the mast sway of a stopped robot
    tilt = {n: get_spec(n).builder(0).floor_tilt_deg for n in SYNTHETIC_DATABASES}
    assert min(tilt.values()) >= 0.3
    assert all(0.0 <= v <= 3.0 for v in tilt.values())


def test_camera_images_apply_the_drawn_tilt():
    spec = get_spec("sim_original")
    world = spec.builder(0)
    positions = np.argwhere(world.cells)[:2]
    geometry = spec.geometry(96, 14)
    cam = CameraConfig(**CLEAN)
    pe = pose_error_config_for("odometry", position_sigma_m=0.0, heading_sigma_deg=0.0, tilt_sigma_deg=2.0)
    imgs, _, poses = camera_images(world, positions, geometry, camera=cam, pose_error=pe, seed=0)
    assert np.all(poses["tilts"] == tilt_offsets(positions, tilt_sigma_deg=2.0, seed=0, db_seed=0))
    setup = camera_setup(cam, geometry, tilt_margin=float(np.abs(poses["tilts"]).sum(axis=1).max()))
    for k, (i, j) in enumerate(positions):
        rad = render_raw_frame(world.scene, position=world.cell_position(i, j), heading=0.0, layout=setup.layout)
        raw = raw_frame_from_radiance(rad, setup, rng=noise_rng(0, (i, j)))
        assert np.array_equal(unfold_frame(raw, setup, geometry, tilt=poses["tilts"][k]), imgs[k])
        assert not np.array_equal(unfold_frame(raw, setup, geometry), imgs[k])
