"""Warping plugins and HiSS on ray-cast pairs at known displacement and rotation."""

import dataclasses
import tomllib
from pathlib import Path

import numpy as np
import pytest

from bionav.errors import UserError
from bionav.geometry import PanoramaGeometry, angular_difference
from bionav.homing.base import HomingMethod
from bionav.plugins.homing.hiss import HissHoming
from bionav.plugins.homing.warping import MinWarping, Warping1D, Warping2D
from bionav.testing.pillar_scene import render_pillar_panorama

# (current position in metres, current heading in radians); the snapshot is at the origin, heading 0
POSES = [((0.5, 0.3), 0.5), ((-0.6, 0.2), -1.0), ((0.2, -0.6), 2.5), ((-0.4, -0.4), -2.8)]


@pytest.fixture(scope="module")
def views():
    w, h = 576, 100  # the warping plugins resize to their own 288 x 50
    snap, geometry = render_pillar_panorama((0.0, 0.0), width=w, height=h, supersample=1)
    currents = [render_pillar_panorama(p, heading=hd, width=w, height=h, supersample=1)[0] for p, hd in POSES]
    return geometry, snap, currents


def _true_home(pos, heading):
    # home direction in the grid frame, expressed in the current view's frame
    return np.arctan2(-pos[1], -pos[0]) - heading


@pytest.mark.parametrize(
    "cls, options, home_tol_deg, psi_tol_deg",
    [
        (MinWarping, {}, 5.0, 3.0),
        (MinWarping, {"compass_acceleration": True}, 5.0, 3.0),
        (MinWarping, {"fine_search": True, "double_search": True}, 3.0, 1.5),
        (Warping2D, {}, 5.0, 3.0),
        (Warping1D, {}, 10.0, 6.0),
    ],
)
def test_warping_points_home_and_recovers_rotation(views, cls, options, home_tol_deg, psi_tol_deg):
    geometry, snap, currents = views
    method = cls(cls.Config(**options), geometry=geometry)
    assert method.requires_alignment is False
    s = method.prepare(snap)
    for (pos, heading), cur in zip(POSES, currents):
        hv = method.home_vector(s, method.prepare(cur))
        assert np.degrees(angular_difference(hv.angle, _true_home(pos, heading))) < home_tol_deg
        assert np.degrees(angular_difference(hv.compass, heading)) < psi_tol_deg
        assert all(isinstance(v, (int, float)) for v in hv.extras.values())


def test_hiss_points_home_without_a_compass(views):
    geometry, snap, currents = views
    method = HissHoming(HissHoming.Config(), geometry=geometry)
    assert method.requires_alignment is False
    s = method.prepare(snap)
    errors = []
    for (pos, heading), cur in zip(POSES, currents):
        hv = method.home_vector(s, method.prepare(cur))
        assert hv.compass is None and hv.extras["n_contracted"] > 0 and hv.extras["n_expanded"] > 0
        errors.append(np.degrees(angular_difference(hv.angle, _true_home(pos, heading))))
    assert max(errors) < 30.0 and np.mean(errors) < 15.0


def test_hiss_signs_on_hand_made_features():
    # one landmark straight ahead (column 0) that shrank: home is ahead
    from bionav.homing.features import SiftFeatures
    from bionav.homing.hiss import hiss

    feats = lambda size: SiftFeatures(  # noqa: E731
        xy=np.array([[0.0, 0.0], [30.0, 0.0]], np.float32),
        descriptors=np.eye(2, 128, dtype=np.float32) * 100,
        sq_norms=np.full(2, 1e4, np.float32),
        size=np.array([size, 5.0], np.float32),
        width=np.array(120, np.int64),
    )

    r = hiss(feats(8.0), feats(4.0), scale_threshold=0.1)  # second keypoint unchanged: ignored
    assert (r.n_contracted, r.n_expanded) == (1, 0) and abs(r.home_angle) < 1e-9
    r = hiss(feats(4.0), feats(8.0), scale_threshold=0.1)  # it grew: home is behind
    assert (r.n_contracted, r.n_expanded) == (0, 1) and abs(abs(r.home_angle) - np.pi) < 1e-9
    r = hiss(feats(5.0), feats(5.0), scale_threshold=0.1)
    assert np.isnan(r.home_angle)


def test_prepare_resizes_to_the_configured_size():
    g = PanoramaGeometry.square_pixels(576, 100)
    img = np.random.default_rng(0).random((100, 576)).astype(np.float32)
    prep = MinWarping(MinWarping.Config(), geometry=g).prepare(img)
    assert prep["snap"].shape == (9, 49, 288)
    prep = MinWarping(MinWarping.Config(butterworth_cutoff=0.1), geometry=g).prepare(img)
    assert prep["snap"].shape == (9, 49, 288)
    assert Warping1D(Warping1D.Config(), geometry=g).prepare(img).shape == (288,)


@pytest.mark.parametrize(
    "cls, options",
    [
        (MinWarping, {"n_alpha": 500}),
        (MinWarping, {"scales": [1.0, 0.5]}),
        (MinWarping, {"thresholds": [1.0, 2.0]}),
        (MinWarping, {"compass_fraction": 0.0}),
        (MinWarping, {"image_size": [287, 50], "double_search": True}),
        (MinWarping, {"butterworth_cutoff": 2.0}),
        (MinWarping, {"threshold_rule": "median"}),
        (MinWarping, {"threshold_rule": "reference", "max_scale_ratio": 1.5}),
        (Warping2D, {"rho_max": 1.0}),
        (Warping1D, {"strip_rows": 0}),
        (HissHoming, {"ratio": 1.5}),
    ],
)
def test_bad_parameters_are_user_errors(cls, options):
    with pytest.raises(UserError):
        cls(cls.Config(**options), geometry=PanoramaGeometry.square_pixels(288, 50))


def test_plugins_are_registered_with_typed_configs():
    pyproject = tomllib.loads((Path(__file__).parents[2] / "pyproject.toml").read_text())
    group = pyproject["project"]["entry-points"]["bionav.homing"]
    want = {
        "minwarping": MinWarping,
        "warping2d": Warping2D,
        "warping1d": Warping1D,
        "hiss": HissHoming,
    }
    for name, cls in want.items():
        module, attr = group[name].split(":")
        assert f"{cls.__module__}:{cls.__name__}" == f"{module}:{attr}"
        assert issubclass(cls, HomingMethod) and dataclasses.is_dataclass(cls.Config)


@pytest.mark.parametrize("preset, cls", [("minwarping_thesis", MinWarping), ("warping2d_thesis", Warping2D)])
def test_thesis_presets_fit_the_typed_config(preset, cls):
    from omegaconf import OmegaConf

    raw = OmegaConf.load(Path(__file__).parents[2] / "bionav" / "conf" / "homing" / f"{preset}.yaml")
    assert list(raw.pop("defaults")) == [cls.name, "_self_"]
    cfg = OmegaConf.to_object(OmegaConf.merge(OmegaConf.structured(cls.Config), raw))
    assert cfg.n_alpha == cfg.n_psi == 72 and cfg.image_size == [346, 50]
    assert cfg.scales == pytest.approx([0.2, 0.4, 0.6, 0.8, 1.0, 1.2, 1.4, 1.6, 1.8])
    method = cls(cfg, geometry=PanoramaGeometry.square_pixels(692, 100), raw_horizon_radius_px=80.5)
    assert method.prepare(np.zeros((100, 692), np.float32))["snap"].shape == (9, 49, 346)


# pairs in the world renderer's laboratory (bionav.world): snapshot at cell (3, 5), heading 0
LAB_CASES = [((5, 8), 0.7), ((1, 3), -2.0), ((7, 4), 2.8), ((2, 9), -0.4)]


@pytest.fixture(scope="module")
def lab_views():
    from bionav.world.render import render_panorama
    from bionav.world.worlds.lab import build_lab

    world = build_lab(0)
    geometry = PanoramaGeometry.square_pixels(561, 81)  # sim_original's native size

    def view(cell, heading):
        img = render_panorama(world.scene, position=world.cell_position(*cell), heading=heading, geometry=geometry)
        return img.mean(axis=2) if img.ndim == 3 else img

    return geometry, view((3, 5), 0.0), [view(c, h) for c, h in LAB_CASES]


@pytest.mark.parametrize(
    "cls, max_home_deg, mean_home_deg, psi_tol_deg",
    [
        (MinWarping, 5.0, 3.0, 3.0),
        (Warping2D, 5.0, 3.0, 3.0),
        (Warping1D, 40.0, 20.0, 10.0),  # equal-distance assumption on a 1-D strip: the weakest
        (HissHoming, 60.0, 25.0, None),
    ],
)
def test_methods_home_in_the_rendered_lab(lab_views, cls, max_home_deg, mean_home_deg, psi_tol_deg):
    geometry, snap, currents = lab_views
    method = cls(cls.Config(), geometry=geometry)
    s = method.prepare(snap)
    errors = []
    for ((cx, cy), heading), cur in zip(LAB_CASES, currents):
        hv = method.home_vector(s, method.prepare(cur))
        errors.append(np.degrees(angular_difference(hv.angle, np.arctan2(5 - cy, 3 - cx) - heading)))
        if psi_tol_deg is not None:
            assert np.degrees(angular_difference(hv.compass, heading)) < psi_tol_deg
    assert max(errors) < max_home_deg and np.mean(errors) < mean_home_deg


@pytest.mark.parametrize("options", [{}, {"compass_acceleration": True, "compass_fraction": 0.3},
                                     {"fine_search": True, "double_search": True}])
def test_quantised_minwarping_agrees_with_the_float_search(views, lab_views, options):
    # the 8-bit search (default) against the float32 one on rendered pairs:
    # home direction and compass within one search step (360 / 96 degrees)
    step_deg = 360.0 / 96
    for geometry, snap, currents in (views, lab_views):
        fast = MinWarping(MinWarping.Config(**options), geometry=geometry)
        slow = MinWarping(MinWarping.Config(quantised=False, **options), geometry=geometry)
        s_fast, s_slow = fast.prepare(snap), slow.prepare(snap)
        for cur in currents:
            a = fast.home_vector(s_fast, fast.prepare(cur))
            b = slow.home_vector(s_slow, slow.prepare(cur))
            assert np.degrees(angular_difference(a.angle, b.angle)) <= step_deg + 1e-9
            assert np.degrees(angular_difference(a.compass, b.compass)) <= step_deg + 1e-9


def test_reference_threshold_rule_gives_arithmetic_midpoints_and_a_largest_ratio():
    from bionav.homing.warping.scaleplanes import default_scales

    s = default_scales()
    g = PanoramaGeometry.square_pixels(288, 50)
    _, tau = MinWarping(MinWarping.Config(), geometry=g)._scales()  # the default rule
    # by hand: (2**((k-4)/4) + 2**((k-3)/4)) / 2, then the largest ratio 2.5
    assert tau[:-1] == pytest.approx([(s[k] + s[k + 1]) / 2 for k in range(8)])
    assert tau[3] == pytest.approx((2 ** -0.25 + 1.0) / 2) and tau[-1] == 2.5
    _, tau_g = MinWarping(MinWarping.Config(threshold_rule="geometric"), geometry=g)._scales()
    assert tau_g[3] == pytest.approx(2 ** -0.125) and np.isinf(tau_g[-1])
    # explicit thresholds win over the rule
    explicit = [float(x) for x in tau_g[:-1]] + [3.0]
    _, tau_e = MinWarping(MinWarping.Config(threshold_rule="reference", thresholds=explicit), geometry=g)._scales()
    assert tau_e == pytest.approx(explicit)
