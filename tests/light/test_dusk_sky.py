"""The clear evening sky of the one-day series, classified with the J_sigma lines of the natural samples.

Issue 18 asks that the clear dusk sky is not classified as objects. With the physical sky of
bionav.light.daylight (two layers, gases, Bird & Riordan's multiple-scattering budget, a broken cloud
cover averaged over each footprint's cloud fraction) it holds at 20:03 (sun 12.9 degrees) for UV-IR
and for the dual contrasts on average, but not at the lowest sun of the series, 20:43 (sun 7.4
degrees; UV-IR sky recall 0.87), where the sky within about 60 degrees of the sun and low above
the horizon is redder in UV-IR than the day-time objects (forward-scattered sunlight reddened by
the long path; see docs/spectral.md, "Dusk"). The strict xfail keeps that requirement executable:
it fails loudly once the gap is closed, so the marker must then be removed.

With each scan's own threshold along the learned directions (``threshold="local"``,
``experiment.separation=local``; Differt & Moeller 2016) the dusk sky stays sky at 20:43 and later.
"""

import numpy as np
import pytest

from bionav.light.clouds import CloudLayer
from bionav.light.daylight import SkyState
from bionav.spectral.lda_analysis import learn_discriminants
from bionav.spectral.samples import sim_natural
from bionav.spectral.scan import ScanGrid, separation_images
from bionav.spectral.sensor_model import LogSensorModel
from bionav.world.worlds.garden import backyard_scene

DUALS = ("UV-B", "UV-G", "UV-R", "UV-IR", "B-G", "B-R", "B-IR", "G-R", "G-IR", "R-IR")


def _sky_recall(time, cover, depth, threshold="learned"):
    """Fraction of the true sky classified as sky, per dual contrast, and of the objects as objects (UV-IR)."""
    disc = learn_discriminants(sim_natural(seed=0), sigma=30.0)
    sky = SkyState.from_time(time, clouds=CloudLayer(cover=cover, optical_depth=depth, seed=0))
    scene = backyard_scene(sky, seed=0)
    grid = ScanGrid.from_steps(n_pan=57, pan_step=np.deg2rad(4.0), n_tilt=13, tilt_step=np.deg2rad(6.0),
                               tilt_start=np.deg2rad(-45.0))
    pan, tilt = grid.angles()
    rad, truth = scene.render(scene.view_direction(pan, tilt))
    counts = LogSensorModel().read(rad, rng=np.random.default_rng(1))[0, ..., :5]
    sep = separation_images(counts, {f: disc[f] for f in DUALS}, threshold=threshold)
    assert truth.any() and (~truth).any()
    return {f: float(np.mean(sep[f][truth])) for f in DUALS}, float(np.mean(~sep["UV-IR"][~truth]))


def test_overcast_noon_sky_and_objects_separate():
    sky, objects = _sky_recall("2009-06-17T11:27:04+02:00", 0.85, 35.0)
    assert sky["UV-IR"] > 0.95 and objects > 0.9


def test_clear_evening_sky_at_sun_13_degrees_is_sky_for_the_dual_contrasts():
    sky, objects = _sky_recall("2009-06-17T20:03:57+02:00", 0.15, 10.0)
    assert np.mean(list(sky.values())) >= 0.9 and sky["UV-IR"] >= 0.9, sky
    assert objects > 0.9


@pytest.mark.xfail(strict=True, reason="known gap (issue 18): at 20:43 (sun 7.4 deg) the reddened sky near the sun "
                   "falls on the object side of the day-time UV-IR J_sigma line (sky recall 0.87)")
def test_clear_dusk_sky_at_sun_7_degrees_is_classified_as_sky():
    sky, _ = _sky_recall("2009-06-17T20:43:36+02:00", 0.1, 10.0)
    assert sky["UV-IR"] >= 0.9, sky


# --------------------------------------------------------------------------- local (per-scan) thresholds
# The learned lines' directions with each scan's own Otsu threshold (bionav.spectral.scan.image_discriminant;
# Differt & Moeller 2016): the evening scene moves along the direction as a whole, and the border moves with it.
@pytest.mark.parametrize("time, cover, depth", [("2009-06-17T20:43:36+02:00", 0.1, 10.0),   # sun 7.4 deg
                                                ("2009-06-17T21:15:00+02:00", 0.1, 10.0)])  # sun 3.6 deg
@pytest.mark.slow
def test_local_threshold_keeps_the_dusk_sky_sky(time, cover, depth):
    learned, _ = _sky_recall(time, cover, depth)
    sky, objects = _sky_recall(time, cover, depth, threshold="local")
    assert sky["UV-IR"] >= 0.95 and np.mean(list(sky.values())) >= 0.95, sky
    assert objects >= 0.9
    assert sky["UV-IR"] > learned["UV-IR"] + 0.05  # where the day-time border fails


@pytest.mark.slow
def test_local_threshold_by_day_keeps_sky_and_objects_apart():
    sky, objects = _sky_recall("2009-06-17T11:27:04+02:00", 0.85, 35.0, threshold="local")
    assert sky["UV-IR"] > 0.95 and objects > 0.9


@pytest.mark.slow
def test_local_separation_through_the_contrast_scan_command(tmp_path):
    """``python -m bionav experiment=contrast_scan experiment.separation=local`` on the 20:43 scan (docs/spectral.md)."""
    import json

    from helpers import run_bionav

    scan = ["experiment=contrast_scan", "experiment.times=[2009-06-17T20:43:36+02:00]", "experiment.cloud_cover=0.1",
            "experiment.cloud_optical_depth=10", "experiment.n_pan=57", "experiment.pan_step_deg=4",
            "experiment.n_tilt=13", "experiment.tilt_step_deg=6", "experiment.plots=false"]
    recall = {}
    for border in ("learned", "local"):
        out = tmp_path / border
        r = run_bionav(*scan, f"experiment.separation={border}", f"hydra.run.dir={out}", cwd=tmp_path)
        assert r.returncode == 0, r.stderr[-2000:]
        m = json.loads((out / "metrics.json").read_text())
        recall[border] = (m["sky_recall"]["UV-IR"][0], m["object_recall"]["UV-IR"][0])
    assert recall["local"][0] >= 0.95 and recall["local"][1] >= 0.9, recall
    assert recall["learned"][0] < recall["local"][0] - 0.05, recall
    bad = run_bionav(*scan, "experiment.separation=global", cwd=tmp_path)
    assert bad.returncode != 0 and "Traceback" not in bad.stderr
    assert "separation" in bad.stderr and "local" in bad.stderr, bad.stderr[-1000:]
