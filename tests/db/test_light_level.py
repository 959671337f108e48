"""The light a world gives the camera (World.light_level): the night hall is dim for the sensor."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from bionav.db.camera import (
    camera_images,
    camera_setup,
    noise_rng,
    pose_error_config_for,
    raw_frame_from_radiance,
    unfold_frame,
)
from bionav.db.config import CameraConfig
from bionav.db.synthetic import SYNTHETIC_DATABASES, get_spec
from bionav.world.catadioptric import render_raw_frame
from bionav.world.scene import Scene
from bionav.world.worlds.common import World

CLEAN = dict(psf_sigma_px=0.0, vignetting=0.0, auto_exposure=False, full_well_e=1e7, read_noise_e=0.0)
STILL = pose_error_config_for("odometry", position_sigma_m=0.0, heading_sigma_deg=0.0, tilt_sigma_deg=0.0)


def _lab(light_level: float, size=(96, 14)):
    spec = get_spec("sim_original")
    world = dataclasses.replace(spec.builder(0), light_level=light_level)
    return world, np.argwhere(world.cells)[[0, 60, 120]], spec.geometry(*size)


def test_the_camera_gets_the_radiance_times_the_light_level():
    world, positions, geometry = _lab(0.3)
    cam = CameraConfig(**CLEAN)
    imgs, _, _ = camera_images(world, positions, geometry, camera=cam, pose_error=STILL, seed=0)
    setup = camera_setup(cam, geometry)
    for k, (i, j) in enumerate(positions):  # re-rendered by hand: radiance x exposure x light level
        rad = render_raw_frame(world.scene, position=world.cell_position(i, j), heading=0.0, layout=setup.layout)
        raw = raw_frame_from_radiance(rad * 0.3, setup, rng=noise_rng(0, (i, j)))
        assert np.array_equal(unfold_frame(raw, setup, geometry), imgs[k])
    bright, _, _ = camera_images(dataclasses.replace(world, light_level=1.0), positions, geometry, camera=cam,
                                 pose_error=STILL, seed=0)
    assert imgs.mean() == pytest.approx(0.3 * bright.mean(), rel=0.03)  # no automatic exposure: just darker


def _shoot(light_level, **camera):
    """Images at the native size (no binning) and their noise (from two noise draws), shot noise only."""
    cam = CameraConfig(psf_sigma_px=0.0, vignetting=0.0, read_noise_e=0.0, full_well_e=1000.0, **camera)
    world, positions, geometry = _lab(light_level, size=(561, 81))
    a, _, _ = camera_images(world, positions, geometry, camera=cam, pose_error=STILL, seed=0)
    b, _, _ = camera_images(world, positions, geometry, camera=cam, pose_error=STILL, seed=1)
    return a.astype(float), (a.astype(float) - b) / np.sqrt(2)


def test_fixed_exposure_shot_noise_grows_as_the_square_root_of_the_light():
    full, noise_full = _shoot(1.0, auto_exposure=False)
    dim, noise_dim = _shoot(0.25, auto_exposure=False)
    assert dim.mean() == pytest.approx(0.25 * full.mean(), rel=0.05)
    # sigma = g sqrt(x t N) / N: a quarter of the light, half the noise (twice the relative noise)
    assert noise_dim.std() / noise_full.std() == pytest.approx(0.5, rel=0.1)


def test_automatic_exposure_makes_up_for_dim_light_until_its_limits():
    full, noise_full = _shoot(1.0)
    dim, noise_dim = _shoot(0.25)
    # a longer exposure collects the same photons: the same image and the same noise
    assert dim.mean() == pytest.approx(full.mean(), rel=0.02)
    assert noise_dim.std() == pytest.approx(noise_full.std(), rel=0.15)
    # beyond the longest exposure the gain amplifies fewer photons, and beyond the gain the image darkens
    dark, noise_dark = _shoot(0.03)
    assert dark.mean() < 0.6 * full.mean()
    assert noise_dark.std() / dark.mean() > 2 * noise_full.std() / full.mean()


@pytest.mark.slow
def test_only_the_night_hall_is_dim_and_bad_levels_are_refused():
    levels = {n: get_spec(n).builder(0).light_level for n in SYNTHETIC_DATABASES}
    assert levels["sim_hall1"] == levels["sim_hall2"] < 0.2
    assert all(v == 1.0 for n, v in levels.items() if n not in ("sim_hall1", "sim_hall2"))
    for bad in (0.0, -1.0, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="light_level"):
            World(scene=Scene(), grid_origin=(0, 0), spacing=1.0, grid_shape=(1, 1), camera_height=0.5,
                  light_level=bad)


@pytest.mark.slow
def test_the_kiosk_takes_the_hall_grid_corner_and_no_obstacle_stands_inside_the_grid():
    from bionav.geometry import PanoramaGeometry
    from bionav.world.render import render_depth

    geo = PanoramaGeometry.square_pixels(180, 3)
    for part in ("sim_hall1", "sim_hall2"):
        world = get_spec(part).builder(0)
        assert world.cells.sum() == 170  # table 3.1
        missing = np.argwhere(~world.cells)
        # one 5 x 6 block at the far corner, the cells within the robot's reach of the kiosk
        assert set(map(tuple, missing)) == {(i, j) for i in range(5, 10) for j in range(14, 20)}
        # open floor: from the grid's centre nothing stands within 1.5 m at the camera's height
        depth, _, _ = render_depth(world.scene, position=world.cell_position(4, 9), geometry=geo)
        assert depth.min() > 1.5
