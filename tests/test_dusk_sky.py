"""The clear evening sky of the one-day series, classified with the J_sigma lines of the natural samples.

Issue 18 asks that the clear dusk sky is not classified as objects. With the physical sky of
bionav.light.daylight (two layers, ozone, second-order scattering) and lines learned on day-time
samples this does not hold yet at the lowest sun of the series (measured: UV-IR sky recall 0.29 at
20:43, sun 7.4 degrees; see docs/spectral.md, "Dusk"). The strict xfail keeps the requirement
executable: it fails loudly once the gap is closed, so the marker must then be removed.
"""

import numpy as np
import pytest

from bionav.light.clouds import CloudLayer
from bionav.light.daylight import SkyState
from bionav.spectral.lda_analysis import learn_discriminants
from bionav.spectral.samples import sim_natural
from bionav.spectral.scan import ScanGrid, separation_images
from bionav.spectral.scene import backyard_scene
from bionav.spectral.sensor_model import LogSensorModel


def _sky_recall(time, cover, depth):
    disc = learn_discriminants(sim_natural(seed=0), sigma=30.0)
    sky = SkyState.from_time(time, clouds=CloudLayer(cover=cover, optical_depth=depth, seed=0))
    scene = backyard_scene(sky, seed=0)
    grid = ScanGrid.from_steps(n_pan=57, pan_step=np.deg2rad(4.0), n_tilt=13, tilt_step=np.deg2rad(6.0),
                               tilt_start=np.deg2rad(-45.0))
    pan, tilt = grid.angles()
    rad, truth = scene.render(scene.view_direction(pan, tilt))
    counts = LogSensorModel().read(rad, rng=np.random.default_rng(1))[0, ..., :5]
    sep = separation_images(counts, {"UV-IR": disc["UV-IR"]})["UV-IR"]
    assert truth.any()
    return float(np.mean(sep[truth])), float(np.mean(~sep[~truth]))


def test_overcast_noon_sky_and_objects_separate():
    sky_recall, object_recall = _sky_recall("2009-06-17T11:27:04+02:00", 0.85, 35.0)
    assert sky_recall > 0.95 and object_recall > 0.9


@pytest.mark.xfail(strict=True, reason="known gap (issue 18): the clear dusk sky near the horizon falls on the "
                   "object side of the day-time J_sigma line; UV-IR sky recall 0.29 at 20:43")
def test_clear_dusk_sky_is_classified_as_sky():
    sky_recall, _ = _sky_recall("2009-06-17T20:43:36+02:00", 0.1, 10.0)
    assert sky_recall >= 0.9
