"""Configs of the spectral experiments: ``experiment=contrast_lda`` (and its ``data=`` group),
``contrast_scan``, ``skyline_homing``.

Units: metres and grid units as named; angles in degrees only in keys ending ``_deg``; times ISO 8601
with zone. Checked by :func:`bionav.experiments.configs.experiment_config`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Optional

from omegaconf import II

from bionav.experiments.configs.ranges import RADIUS, STEP
from bionav.validation import Range, bounded


@dataclass
class LearnSamplesConfig:
    """Labelled samples the separation lines are learned on (thesis: the natural samples)."""

    name: str = bounded("sim_natural", choices=("sim_natural", "sim_artificial"))
    seed: int = bounded(II("seed"), ge=0, le=2**32 - 1)
    n_objects: int = bounded(239, ge=2, le=1_000_000)
    n_sky: int = bounded(233, ge=2, le=1_000_000)


@dataclass
class ContrastLdaConfig:
    """``experiment=contrast_lda`` (thesis 6.2-6.3): sky/object discrimination per spectral feature.

    sigma : receptor noise for J_sigma, ADC counts (thesis: 30).
    n_resamples : bootstrap data sets for the significance tables (0 = skip).
    """

    name: str = "contrast_lda"
    sigma: float = bounded(30.0, gt=0.0, le=1e6)
    n_resamples: int = bounded(10000, ge=0, le=10_000_000)
    plots: bool = True


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


@dataclass
class SkyConditionConfig:
    """One light condition of ``experiment=skyline_homing``."""

    name: str = "noon_overcast"
    time: str = "2009-06-17T12:00:00+02:00"
    cloud_cover: float = bounded(0.95, ge=0.0, le=1.0)
    cloud_optical_depth: float = bounded(40.0, ge=0.0, le=1000.0)


def _conditions() -> list[SkyConditionConfig]:
    return [SkyConditionConfig("noon_overcast", "2009-06-17T12:00:00+02:00", 0.95, 40),
            SkyConditionConfig("afternoon_broken", "2009-06-17T16:00:00+02:00", 0.5, 25),
            SkyConditionConfig("evening_clear", "2009-06-17T20:00:00+02:00", 0.1, 10)]


@dataclass
class SkylineHomingConfig:
    """``experiment=skyline_homing``: outdoor homing from five-channel images under changing light.

    world : ``garden`` (shrubs, trees, buildings, tree line) or ``campus`` (the sim_uni world in 5 bands).
    grid : grid cells (x, y) of the garden (the campus has its own 10 x 17 at 1 m).
    image_width, image_height : panorama columns (3 degrees each at 120) and rows from ``elevation_top_deg`` down.
    noise_counts : sensor noise per pixel, ADC counts.
    conditions : snapshots under one condition, current views under another.
    representations : single channels, dual contrasts, binary skylines (``skyline:<feature>``).
    snapshot_stride : every k-th cell along x and y is a snapshot.
    square_test, square_side_m : thesis 6.5.2, corners of a square.
    sigma : receptor noise of the J_sigma skyline lines.
    separation : class border of the skylines: ``learned`` (the samples' threshold) or ``local`` (Otsu's threshold
        of each panorama; bionav.spectral.scan.image_discriminant).
    """

    name: str = "skyline_homing"
    world: str = bounded("garden", choices=("garden", "campus"))
    world_seed: int = bounded(0, ge=0, le=2**32 - 1)
    grid: list[int] = bounded([9, 9], length=2, item=Range(ge=1, le=1000))
    spacing_m: float = bounded(0.5, gt=0.0, le=100.0)
    image_width: int = bounded(120, ge=8, le=8192)
    image_height: int = bounded(20, ge=2, le=8192)
    elevation_top_deg: float = bounded(45.0, gt=-90.0, le=90.0)
    noise_counts: float = bounded(4.0, ge=0.0, le=1e6)
    turbidity: float = bounded(0.1, ge=0.0, le=100.0)
    conditions: list[SkyConditionConfig] = field(default_factory=_conditions)
    representations: list[str] = field(default_factory=lambda: [
        "UV", "B", "G", "R", "IR", "UV-B", "UV-G", "UV-R", "UV-IR", "B-G", "B-R", "B-IR", "G-R", "G-IR", "R-IR",
        "skyline:UV", "skyline:UV-G", "skyline:UV-IR", "skyline:B-IR", "skyline:all"])
    snapshot_stride: int = bounded(2, ge=1, le=1000)
    step_length: float = bounded(0.5, **STEP)
    success_radius: float = bounded(1.0, **RADIUS)
    square_test: bool = True
    square_side_m: float = bounded(2.0, gt=0.0, le=1000.0)
    sigma: float = bounded(30.0, gt=0.0, le=1e6)
    separation: str = bounded("learned", choices=("learned", "local"))
    plots: bool = True
    learn: LearnSamplesConfig = field(default_factory=LearnSamplesConfig)

    def unused_keys(self) -> tuple[list[str], tuple[str, ...]]:
        """``grid`` and ``spacing_m`` are the garden's: the campus has its own 10 x 17 grid at 1 m
        (called by :func:`bionav.validation.typed_config`)."""
        import dataclasses

        fields = {f.name: f for f in dataclasses.fields(self)}
        own = () if self.world == "garden" else ("grid", "spacing_m")
        used = tuple(name for name in fields if name not in own)
        unused = [name for name in own if getattr(self, name) != (
            fields[name].default if fields[name].default is not dataclasses.MISSING else fields[name].default_factory())]
        return unused, used


@dataclass
class DataConfig:
    """``data=<name>`` of ``experiment=contrast_lda``: simulated labelled samples or a CSV file."""

    name: str = bounded("sim_natural", choices=("sim_natural", "sim_artificial", "csv"))
    path: Optional[str] = None
    seed: int = bounded(0, ge=0, le=2**32 - 1)
    n_objects: Optional[int] = bounded(None, ge=2, le=1_000_000)
    n_sky: int = bounded(233, ge=2, le=1_000_000)
    noise_counts: float = bounded(4.0, ge=0.0, le=1e6)
    n_average: int = bounded(10, ge=1, le=100_000)
