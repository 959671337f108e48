"""Representations of five-channel images and experiment=skyline_homing on a tiny grid."""

import numpy as np
import pytest
from omegaconf import OmegaConf
from spectral_ctx import FakeContext, run_with

from bionav.spectral.representations import representation_image, representation_names
from bionav.stats import fisher_lda


def test_representations():
    rng = np.random.default_rng(0)
    counts = rng.uniform(1000, 3000, (4, 6, 5))
    assert len(representation_names()) == 5 + 10 + 16
    np.testing.assert_allclose(representation_image(counts, "G"), counts[..., 2] / 4095, rtol=1e-6)
    c = representation_image(counts, "UV-IR")
    np.testing.assert_allclose(c, np.clip(0.5 + (counts[..., 0] - counts[..., 4]) / 2048, 0, 1), rtol=1e-6)
    # an illumination change shifts every log channel equally: contrasts do not move, channels do
    np.testing.assert_array_equal(representation_image(counts + 200, "UV-IR"), c)
    assert not np.allclose(representation_image(counts + 200, "UV"), representation_image(counts, "UV"))
    # skyline: 1 = object, 0 = sky, from a discriminant with sky = class 1
    x = np.r_[rng.normal(3000, 50, 40), rng.normal(1500, 50, 40)]
    lda = fisher_lda(x, np.r_[np.ones(40, bool), np.zeros(40, bool)])
    img = np.zeros((2, 2, 5))
    img[0, :, 0] = 3100
    img[1, :, 0] = 1400
    sky = representation_image(img, "skyline:UV", discriminants={"UV": lda})
    np.testing.assert_array_equal(sky, [[0, 0], [1, 1]])
    with pytest.raises(ValueError, match="unknown representation"):
        representation_image(counts, "UV-X")
    # local thresholds: a dusk image, everything 1700 counts darker, is all "object" to the learned border,
    # while each image of a stack gets its own border along the direction
    stack = np.stack([img, img - 1700.0])
    learned = representation_image(stack, "skyline:UV", discriminants={"UV": lda})
    np.testing.assert_array_equal(learned[1], [[1, 1], [1, 1]])
    local = representation_image(stack, "skyline:UV", discriminants={"UV": lda}, threshold="local")
    np.testing.assert_array_equal(local, [[[0, 0], [1, 1]], [[0, 0], [1, 1]]])
    with pytest.raises(ValueError, match="learned, local"):
        representation_image(img, "skyline:UV", discriminants={"UV": lda}, threshold="global")


def test_skyline_homing_tiny(tmp_path):
    from bionav.experiments import common
    from bionav.plugins.homing.mfdid import MfdidHoming

    cfg = OmegaConf.create({
        "seed": 0, "workers": 1, "homing": {"name": "mfdid"},
        "experiment": {
            "name": "skyline_homing", "world": "garden", "grid": [3, 3], "spacing_m": 0.5, "image_width": 48,
            "image_height": 8, "elevation_top_deg": 45.0,
            "conditions": [
                {"name": "overcast", "time": "2009-06-17T12:00:00+02:00", "cloud_cover": 0.95, "cloud_optical_depth": 40},
                {"name": "evening", "time": "2009-06-17T20:00:00+02:00", "cloud_cover": 0.1, "cloud_optical_depth": 10},
            ],
            "representations": ["UV", "UV-IR", "skyline:UV-IR"], "snapshot_stride": 2, "square_test": True,
            "learn": {"name": "sim_natural", "seed": 0, "n_objects": 60, "n_sky": 60}, "plots": False,
        },
    })

    class Ctx(FakeContext):
        def plugin(self, kind, node, **kw):
            return MfdidHoming(MfdidHoming.Config(), **kw)

    original = common.make_homing
    common.make_homing = lambda cfg, ctx, geometry: ctx.plugin("homing", cfg.homing, geometry=geometry)
    try:
        ctx = Ctx(tmp_path)
        m = run_with(cfg, ctx)
    finally:
        common.make_homing = original
    assert m["n_positions"] == 9 and m["n_snapshots"] == 4 and m["n_conditions"] == 2
    for key in ("rr", "aae", "rr_same", "aae_same", "square_aae", "square_aae_changed"):
        assert set(m[key]) == {"UV", "UV-IR", "skyline:UV-IR"}
    assert all(0 <= v <= 1 for v in m["rr"].values())
    assert m["best_representation"] in m["rr"]
    rows = (tmp_path / "skyline_homing.csv").read_text().splitlines()
    assert len(rows) == 1 + 3 * 4
    assert sum(t == "/skyline_homing/cell" for t, _, _ in ctx.log.messages) == 12
    data = np.load(tmp_path / "panoramas.npz")
    assert data["counts"].shape == (2, 9, 8, 48, 5) and data["sky"].any()


def test_campus_world_in_five_bands():
    """The world renderer's outdoor campus with bionav.spectral albedos and sky (when the campus exists)."""
    pytest.importorskip("bionav.world.worlds.outdoor")
    from bionav.world.worlds.outdoor import campus_world, render_campus_counts
    from bionav.geometry import PanoramaGeometry
    from bionav.light.clouds import CloudLayer
    from bionav.light.daylight import SkyState
    from bionav.spectral.sensor_model import LogSensorModel

    sky = SkyState.from_time("2009-06-17T16:00:00+02:00", clouds=CloudLayer(cover=0.3, optical_depth=20, seed=1))
    world = campus_world(sky, seed=0)
    g = PanoramaGeometry(60, 10, 7.5, 2 * np.pi / 60)
    counts, is_sky = render_campus_counts(world, g, np.array([[2, 3]]), sensor_model=LogSensorModel(noise_counts=0.0),
                                          rng=np.random.default_rng(0))
    assert counts.shape == (1, 10, 60, 5) and 0.05 < is_sky.mean() < 0.95
    uv_ir = counts[0, ..., 0] - counts[0, ..., 4]
    assert uv_ir[is_sky[0]].mean() > uv_ir[~is_sky[0]].mean() + 300  # sky is UV-rich, the world is not


@pytest.mark.slow
def test_local_skylines_through_the_command_keep_homing_across_the_day(tmp_path):
    """``experiment=skyline_homing experiment.separation=local``: changed light homes as well as the same light."""
    import json

    from helpers import run_bionav

    args = ["experiment=skyline_homing", "homing=mfdid", "experiment.grid=[5,5]", "experiment.image_width=60",
            "experiment.image_height=10", "experiment.representations=[skyline:UV-IR]", "experiment.square_test=false",
            "experiment.plots=false"]
    m = {}
    for border in ("learned", "local"):
        r = run_bionav(*args, f"experiment.separation={border}", f"hydra.run.dir={tmp_path / border}", cwd=tmp_path)
        assert r.returncode == 0, r.stderr[-2000:]
        m[border] = json.loads((tmp_path / border / "metrics.json").read_text())
    changed = {b: m[b]["rr"]["skyline:UV-IR"] for b in m}
    assert changed["local"] > changed["learned"] + 0.03, changed
    assert changed["local"] >= m["local"]["rr_same"]["skyline:UV-IR"] - 0.02, m["local"]
