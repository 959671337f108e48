"""Config of ``experiment=skyline_homing`` (beyond thesis 6.5).

Units: metres and grid units as named; angles in degrees only in keys ending ``_deg``; times ISO 8601
with zone. Checked by the runner before the run (:func:`bionav.experiments.settings.experiment_config`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from bionav.experiments.ranges import RADIUS, STEP
from bionav.spectral.sample_config import LearnSamplesConfig
from bionav.validation import Range, bounded


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
