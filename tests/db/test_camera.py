"""The catadioptric camera of the stand-ins (db.realism=camera) against closed forms and the direct renderer."""

from __future__ import annotations

import dataclasses
import hashlib
import math
from pathlib import Path

import numpy as np
import pytest
from omegaconf import OmegaConf

from bionav.db.camera import (
    camera_config_for,
    camera_images,
    camera_setup,
    noise_rng,
    pose_error_config_for,
    pose_offsets,
    raw_frame_from_radiance,
    unfold_frame,
)
from bionav.db.config import CameraConfig
from bionav.db.synthetic import (
    SYNTHETIC_DATABASES,
    get_spec,
    quantise,
    render_world_images,
    synthetic_database,
)
from bionav.errors import UserError
from bionav.geometry import PanoramaGeometry
from bionav.world.catadioptric import MirrorProjection, raw_frame_layout, render_raw_frame
from bionav.world.lights import Ambient, PointLight
from bionav.world.render import render_panorama
from bionav.world.scene import Scene

REPO = Path(__file__).resolve().parents[2]

# a camera without sensor effects: no blur, no vignetting, fixed exposure, (almost) no noise
CLEAN = dict(psf_sigma_px=0.0, vignetting=0.0, auto_exposure=False, full_well_e=1e7, read_noise_e=0.0)


def _projection(**kw):
    kw = {"xi": 0.82, "rim_elevation_deg": 36.0, "rim_radius_px": 230.0, "center": (319.5, 239.5), **kw}
    return MirrorProjection.from_rim(**kw)


def test_mirror_profile_closed_form_and_inverse():
    p = _projection()
    e = np.radians(np.linspace(-80.0, 35.0, 200))
    r = p.radius_from_elevation(e)
    np.testing.assert_allclose(r, p.gamma * np.cos(e) / (0.82 - np.sin(e)))
    assert np.all(np.diff(r) > 0)  # radius grows with elevation
    np.testing.assert_allclose(p.elevation_from_radius(r), e, atol=1e-12)
    assert p.rim_radius == pytest.approx(230.0)
    assert float(p.radius_from_elevation(0.0)) == pytest.approx(p.gamma / 0.82)  # horizon circle: gamma / xi
    h = 1e-6
    numeric = (p.radius_from_elevation(e + h) - p.radius_from_elevation(e - h)) / (2 * h)
    np.testing.assert_allclose(p.radial_resolution(e), numeric, rtol=1e-6)
    # resolution varies with elevation: at +26 deg a degree covers several times more raw pixels than at -26 deg
    hi, lo = p.radial_resolution(np.radians([26.0, -26.0]))
    assert hi / lo > 4.0
    with pytest.raises(ValueError, match="rim"):
        _projection(xi=0.5)  # sin(36 deg) = 0.59 > 0.5: the rim would be at infinity


def _dark_sphere_scene():
    s = Scene(ambient=Ambient(up=0.0, down=0.0))
    s.ellipsoid((0.0, 0.0, 0.6), 6.0, material=s.material(albedo=0.1))  # the camera sits inside
    return s


@pytest.mark.parametrize("heading", [0.0, 0.4])
@pytest.mark.parametrize("az_deg, el_deg", [(60.0, 10.0), (200.0, -15.0), (310.0, 24.0)])
def test_a_feature_lands_at_the_predicted_raw_pixel(az_deg, el_deg, heading):
    s = _dark_sphere_scene()
    az, el = math.radians(az_deg), math.radians(el_deg)
    d = 3.0
    centre = (d * math.cos(el) * math.cos(az), d * math.cos(el) * math.sin(az), 0.6 + d * math.sin(el))
    s.ellipsoid(centre, 0.05, material=s.material(albedo=0.0, emission=5.0))
    p = _projection()
    layout = raw_frame_layout(p, raw_size=(640, 480), radius_range=(20.0, 229.0))
    frame = render_raw_frame(s, position=(0.0, 0.0, 0.6), heading=heading, layout=layout)[:, :, 0]
    bright = frame > 0.5  # the dark sphere reads 0.0 (no light), the emitter 5.0
    assert 3 <= bright.sum() < 400
    rows, cols = np.nonzero(bright)
    wts = frame[bright]
    got = (np.sum(cols * wts) / wts.sum(), np.sum(rows * wts) / wts.sum())
    expected = p.pixel_from_direction(az - heading, el)  # raw angle = azimuth relative to the heading
    assert math.hypot(got[0] - expected[0], got[1] - expected[1]) < 0.5


def _smooth_world():
    s = Scene(ambient=Ambient(up=0.1, down=0.05))
    s.ellipsoid((0.3, -0.2, 1.0), (4.0, 3.0, 2.5), material=s.material(albedo=0.7))
    s.add_light(PointLight((1.5, 1.0, 2.0), 4.0, downward=False))
    s.add_light(PointLight((-2.0, -1.0, 0.0), 1.5, downward=False))
    return s


def test_unfolded_raw_frame_matches_the_directly_rendered_panorama_of_a_smooth_world():
    s = _smooth_world()
    geometry = PanoramaGeometry.square_pixels(561, 81)
    setup = camera_setup(CameraConfig(**CLEAN), geometry)
    position = (0.0, 0.0, 0.6)
    radiance = render_raw_frame(s, position=position, heading=0.0, layout=setup.layout)
    raw = raw_frame_from_radiance(radiance, setup, rng=np.random.default_rng(0))
    unfolded = unfold_frame(raw, setup, geometry)[:, :, 0] / 255.0
    direct = np.clip(render_panorama(s, position=position, geometry=geometry)[:, :, 0], 0, 1)
    assert direct.std() > 0.05  # the world is not flat: the comparison has power
    err = np.abs(unfolded - direct)
    # stated tolerance: 8-bit quantisation (1/510) plus two bilinear resamplings of smooth shading
    assert err.mean() < 0.004 and err.max() < 0.02
    # a wrong mirror profile (unfolding linearly in radius) misses the tolerance
    wrong = dataclasses.replace(setup, row_radii=np.linspace(setup.row_radii[0], setup.row_radii[-1], 81))
    err_wrong = np.abs(unfold_frame(raw, wrong, geometry)[:, :, 0] / 255.0 - direct)
    assert err_wrong.max() > 0.02


def test_auto_exposure_and_noise_follow_the_closed_forms():
    geometry = PanoramaGeometry.square_pixels(561, 81)
    cam = CameraConfig(psf_sigma_px=0.0, vignetting=0.0, ae_target=0.4, max_exposure=2.0, max_gain=4.0,
                       full_well_e=2000.0, read_noise_e=20.0)
    setup = camera_setup(cam, geometry)
    h, w = setup.layout.radius.shape
    level = 0.05  # dark scene: exposure time 2 (the maximum), then gain 0.4 / (0.05 * 2) = 4
    raw = raw_frame_from_radiance(np.full((h, w, 1), level), setup, rng=np.random.default_rng(1))[:, :, 0] / 255.0
    inside = (setup.layout.radius >= setup.band[0]) & (setup.layout.radius <= setup.band[1])
    t, g = 2.0, 4.0
    assert raw[inside].mean() == pytest.approx(level * t * g, abs=0.003)
    expected_std = g * math.sqrt(level * t * 2000.0 + 20.0 ** 2) / 2000.0
    std = raw[inside].std()
    assert std == pytest.approx(math.sqrt(expected_std ** 2 + 1 / 255 ** 2 / 12), rel=0.05)
    # a bright scene is exposed shorter, without gain, to the target level
    bright = raw_frame_from_radiance(np.full((h, w, 1), 1.6), setup, rng=np.random.default_rng(2))[:, :, 0] / 255.0
    assert bright[inside].mean() == pytest.approx(0.4, abs=0.003)


def test_vignetting_darkens_towards_the_rim():
    geometry = PanoramaGeometry.square_pixels(561, 81)
    setup = camera_setup(CameraConfig(**{**CLEAN, "vignetting": 0.5}), geometry)
    h, w = setup.layout.radius.shape
    raw = raw_frame_from_radiance(np.full((h, w, 1), 0.8), setup, rng=np.random.default_rng(0))[:, :, 0] / 255.0
    r = setup.layout.radius
    ring = np.abs(r - 150.0) < 0.5
    assert raw[ring].mean() == pytest.approx(0.8 * (1 - 0.5 * (150.0 / 230.0) ** 2), abs=2 / 255)


def test_pose_errors_have_the_stated_statistics():
    cells = np.argwhere(np.ones((200, 100), bool))
    offsets, headings = pose_offsets(cells, position_sigma_m=0.05, heading_sigma_deg=3.0, seed=7, db_seed=1)
    assert offsets.std(axis=0) == pytest.approx([0.05, 0.05], rel=0.02)
    assert np.abs(offsets.mean(axis=0)).max() < 0.002
    assert np.degrees(headings.std()) == pytest.approx(3.0, rel=0.02)
    assert abs(np.corrcoef(offsets[:, 0], headings)[0, 1]) < 0.02
    # a cell's error does not depend on the other cells rendered (contact sheets show the database's poses)
    part = pose_offsets(cells[[5, 17000]], position_sigma_m=0.05, heading_sigma_deg=3.0, seed=7, db_seed=1)
    assert np.array_equal(part[0], offsets[[5, 17000]]) and np.array_equal(part[1], headings[[5, 17000]])
    other = pose_offsets(cells[:10], position_sigma_m=0.05, heading_sigma_deg=3.0, seed=8, db_seed=1)
    assert not np.array_equal(other[0], offsets[:10])


def test_camera_images_are_rendered_at_the_perturbed_poses():
    spec = get_spec("sim_original")
    world = spec.builder(0)
    positions = np.argwhere(world.cells)[:2]
    geometry = spec.geometry(96, 14)
    cam = CameraConfig(**CLEAN)
    pe = pose_error_config_for("odometry", position_sigma_m=0.0, heading_sigma_deg=0.0, tilt_sigma_deg=0.0)
    exact, _, poses = camera_images(world, positions, geometry, camera=cam, pose_error=pe, seed=0)
    assert np.all(poses["offsets_m"] == 0) and np.all(poses["heading_errors"] == 0)
    # with errors, image k equals the error-free render at the perturbed pose (re-rendered by hand)
    pe2 = dataclasses.replace(pe, position_sigma_m=0.05, heading_sigma_deg=5.0)
    moved, _, poses2 = camera_images(world, positions, geometry, camera=cam, pose_error=pe2, seed=0)
    assert not np.array_equal(moved, exact)
    setup = camera_setup(cam, geometry)
    for k, (i, j) in enumerate(positions):
        x, y, z = world.cell_position(i, j)
        pos = (x + poses2["offsets_m"][k, 0], y + poses2["offsets_m"][k, 1], z)
        rad = render_raw_frame(world.scene, position=pos, heading=poses2["heading_errors"][k], layout=setup.layout)
        raw = raw_frame_from_radiance(rad, setup, rng=noise_rng(0, (i, j)))
        assert np.array_equal(unfold_frame(raw, setup, geometry), moved[k])


@pytest.mark.slow
def test_camera_database_keeps_the_nominal_grid_and_caches(tmp_path):
    kw = dict(image_size=(64, 10), cache_dir=tmp_path)
    db = synthetic_database("sim_original", realism="camera", **kw)
    ideal = synthetic_database("sim_original", **kw)
    assert db.images.shape == ideal.images.shape == (170, 10, 64)
    np.testing.assert_array_equal(db.positions, ideal.positions)  # ground truth: the nominal grid
    assert db.meta["realism"] == "camera" and db.meta["pose_error"]["heading_sigma_deg"] == 1.5
    assert np.abs(db.images - ideal.images).mean() > 0.01
    again = synthetic_database("sim_original", realism="camera", **kw)
    assert again.meta["from_cache"] and np.array_equal(again.images, db.images)
    other = synthetic_database("sim_original", realism="camera", camera=camera_config_for("ultra-wide",
                                                                                           psf_sigma_px=1.5), **kw)
    assert not other.meta["from_cache"] and other.meta["cache_file"] != db.meta["cache_file"]


#: sha256 (first 16 hex digits) of the 48 x 8 ideal images before db.realism existed, with the world
#: digests of that time (commit ad67aa2); a changed world is checked by the recomputation test instead.
GOLDEN = {
    "sim_original": ("f4098f8c37cda8e2f0fe9367914d903d00670400d594625ffd86c67ff3581698", "0f0dec4596a89197"),
    "sim_uni": ("34500b62722e895390ab8be80c745f89a95eaf432d514605f75c757d47a59052", "33c0a33c91e353c6"),
}


@pytest.mark.parametrize("name", sorted(GOLDEN))
def test_ideal_is_bit_identical_to_the_previous_pipeline(name, tmp_path):
    world = get_spec(name).builder(0)
    digest, golden = GOLDEN[name]
    db = synthetic_database(name, image_size=(48, 8), cache_dir=tmp_path)
    # recomputed by hand with the pre-camera recipe: direct panoramas, Gaussian noise, 8 bits
    positions = np.argwhere(world.cells)
    imgs = render_world_images(world, positions, get_spec(name).geometry(48, 8))
    rng = np.random.default_rng(np.random.SeedSequence([0, 0x6E6F6973]))
    expected = quantise(imgs, noise=0.01, rng=rng).astype(np.float32) / np.float32(255.0)
    np.testing.assert_array_equal(db.images, expected[..., 0] if expected.shape[-1] == 1 else expected)
    if world.scene.compile().digest() != digest:
        pytest.skip(f"the {name} world changed since the golden hash was recorded; checked by recomputation only")
    assert hashlib.sha256(db.images.tobytes()).hexdigest()[:16] == golden


def test_sim_configs_choose_camera_with_the_stand_ins_own_mirror_and_pose_errors():
    for name, spec in SYNTHETIC_DATABASES.items():
        node = OmegaConf.load(REPO / "bionav" / "conf" / "db" / f"{name}.yaml")
        assert node.realism == "camera", name
        assert dict(node.camera) == {k: (list(v) if isinstance(v, list) else v)
                                     for k, v in dataclasses.asdict(camera_config_for(spec.mirror)).items()}, name
        assert dict(node.pose_error) == dataclasses.asdict(pose_error_config_for(spec.positions_from)), name


def _load(overrides, tmp_path):
    from bionav.db.compose import compose_database
    from bionav.db.loading import load_database

    composed = compose_database(overrides[0], [*overrides[1:], f"cache_dir={tmp_path}"])
    return load_database(composed.db, data_dir=composed.data_dir, cache_dir=composed.cache_dir)


def test_the_user_door_defaults_to_camera_and_ideal_gives_the_old_images(tmp_path):
    cam = _load(["sim_uni", "db.image_size=[48,8]"], tmp_path)
    assert cam.meta["realism"] == "camera" and cam.meta["camera"]["mirror_xi"] == 0.6
    ideal = _load(["sim_uni", "db.image_size=[48,8]", "db.realism=ideal"], tmp_path)
    assert np.array_equal(ideal.images, synthetic_database("sim_uni", image_size=(48, 8), cache_dir=tmp_path).images)


@pytest.mark.parametrize("override, words", [
    ("db.realism=photo", ["db.realism", "camera", "ideal"]),
    ("db.camera.mirror_xi=1.5", ["db.camera.mirror_xi", "1.5"]),
    ("db.camera.psf_sigma_px=-1", ["db.camera.psf_sigma_px"]),
    ("db.pose_error.heading_sigma_deg=-2", ["db.pose_error.heading_sigma_deg"]),
    ("db.camera.mirror_xi=0.3", ["db.camera.mirror_xi", "rim_elevation_deg"]),
    ("db.camera.rim_elevation_deg=20", ["db.camera.rim_elevation_deg", "top of the panorama"]),
    ("db.camera.rim_radius_px=300", ["db.camera.rim_radius_px", "raw_size"]),
])
@pytest.mark.slow
def test_bad_camera_values_are_rejected_with_one_clear_message(override, words, tmp_path):
    with pytest.raises(UserError) as info:
        _load(["sim_original", "db.image_size=[48,8]", override], tmp_path)
    msg = str(info.value)
    assert all(w in msg for w in words), msg
    assert "\n" not in msg.strip()


@pytest.mark.slow
def test_documented_camera_sheet_command_on_a_tiny_input(tmp_path):
    import cv2
    from helpers import run_bionav

    proc = run_bionav("camera", "sim_uni", "--out", str(tmp_path / "sheets"), "--cells", "2", "db.image_size=[48,8]",
                      module="bionav.db", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    sheet = cv2.imread(str(tmp_path / "sheets" / "sim_uni_camera.png"), cv2.IMREAD_GRAYSCALE)
    assert sheet is not None and sheet.shape[1] >= 400
    assert "wrote" in proc.stdout and sheet.std() > 20  # raw thumbnails and panoramas, not a blank page
    bad = run_bionav("camera", "sim_uni", "--out", str(tmp_path / "s2"), "db.camera.mirror_xi=0.2",
                     module="bionav.db", cwd=tmp_path)
    assert bad.returncode == 2 and "db.camera.mirror_xi" in bad.stderr and "Traceback" not in bad.stderr
