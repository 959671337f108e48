"""Config of ``experiment=contrast_scan`` (thesis 6.4).

Angles in degrees only in keys ending ``_deg``; times ISO 8601 with zone. Checked by the runner
before the run (:func:`bionav.experiments.settings.experiment_config`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from bionav.spectral.sample_config import LearnSamplesConfig
from bionav.validation import bounded


def _scan_times() -> list[str]:
    return ["2009-06-17T11:27:04+02:00", "2009-06-17T12:06:19+02:00", "2009-06-17T12:46:02+02:00",
            "2009-06-17T13:25:05+02:00", "2009-06-17T14:07:52+02:00", "2009-06-17T14:47:21+02:00",
            "2009-06-17T15:26:36+02:00", "2009-06-17T16:07:15+02:00", "2009-06-17T16:46:10+02:00",
            "2009-06-17T17:26:10+02:00", "2009-06-17T18:44:09+02:00", "2009-06-17T19:24:41+02:00",
            "2009-06-17T20:03:57+02:00", "2009-06-17T20:43:36+02:00"]


@dataclass
class ContrastScanConfig:
    """``experiment=contrast_scan`` (thesis 6.4): 2-D scans with the five-channel sensor over a day.

    times : one scan per time (ISO 8601 with zone); default: the one-day data set of 17 June 2009 (appendix D.3).
    cloud_cover, cloud_optical_depth : simulated weather per scan (one value or one per time).
    scan_minutes : simulated duration of one scan (sun and clouds move meanwhile).
    n_pan, pan_step_deg, pan_centre_deg, n_tilt, tilt_step_deg, tilt_start_deg : the scan grid
        (thesis 6.4.1: 113 pan x 26 tilt steps of 2 and 3 degrees); tilt = elevation of the optical axis.
    sigma : receptor noise of the J_sigma separation lines, counts.
    separation : class border of the sky/object separation on each line's direction: ``learned`` (the thesis'
        threshold from the labelled samples) or ``local`` (Otsu's threshold of each scan; beyond the thesis, for
        light the samples did not cover, e.g. dusk; bionav.spectral.scan.image_discriminant).
    """

    name: str = "contrast_scan"
    times: list[str] = field(default_factory=_scan_times)
    # one value, or a list with one value per time
    cloud_cover: Any = bounded([0.85, 0.9, 0.8, 0.85, 0.9, 0.75, 0.7, 0.8, 0.6, 0.45, 0.3, 0.2, 0.15, 0.1],
                               ge=0.0, le=1.0)
    cloud_optical_depth: Any = bounded([35, 40, 35, 45, 40, 35, 30, 35, 25, 20, 15, 12, 10, 10], ge=0.0, le=1000.0)
    turbidity: float = bounded(0.1, ge=0.0, le=100.0)
    cloud_seed: int = bounded(0, ge=0, le=2**32 - 1)
    scene_seed: int = bounded(0, ge=0, le=2**32 - 1)
    scan_minutes: float = bounded(20.0, ge=0.0, le=24 * 60.0)
    n_pan: int = bounded(113, ge=1, le=100_000)
    pan_step_deg: float = bounded(2.0, gt=0.0, le=360.0)
    pan_centre_deg: float = bounded(0.0, ge=-360.0, le=360.0)
    n_tilt: int = bounded(26, ge=1, le=100_000)
    tilt_step_deg: float = bounded(3.0, gt=0.0, le=180.0)
    tilt_start_deg: float = bounded(-45.0, ge=-90.0, le=90.0)
    plots: bool = True
    sigma: float = bounded(30.0, gt=0.0, le=1e6)
    separation: str = bounded("learned", choices=("learned", "local"))
    learn: LearnSamplesConfig = field(default_factory=LearnSamplesConfig)
