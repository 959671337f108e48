"""Config of the cleaning robot: ``experiment=cleaning`` (its ``layout=`` group is
:class:`bionav.robot.layout.LayoutConfig`).

Units: metres as named; angles in degrees only in keys ending ``_deg``. Checked by the runner before
the run (:func:`bionav.experiments.settings.experiment_config`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

from omegaconf import II

from bionav.validation import bounded


@dataclass
class CleaningCameraConfig:
    """The robot's panoramic camera (thesis 7.2: unfolded images of 335 x 40).

    height_m : camera height above the floor. horizon_row : None = the middle row (square pixels).
    noise : pixel noise std before 8-bit quantisation (seeded per run and capture).
    """

    width: int = bounded(335, ge=8, le=8192)
    height: int = bounded(40, ge=2, le=8192)
    height_m: float = bounded(0.30, gt=0.0, le=100.0)
    horizon_row: Optional[float] = bounded(None, ge=-100_000.0, le=100_000.0)
    noise: float = bounded(0.01, ge=0.0, le=1.0)


@dataclass
class CleaningOracleConfig:
    """``vision=oracle``: home vectors from the true geometry plus Gaussian noise."""

    angle_noise_deg: float = bounded(5.0, ge=0.0, le=180.0)
    compass_noise_deg: float = bounded(3.0, ge=0.0, le=180.0)


@dataclass
class CleaningConfig:
    """``experiment=cleaning`` (thesis chapter 7; Gerstmayr et al. 2009): the lane controller.

    runs : runs per configuration (the top-level ``runs`` is a shortcut).
    vision : ``render`` (panoramas rendered at the true pose, homing with ``cfg.homing``) or ``oracle``.
    wheel_error : static wheel-speed error, +e left / -e right for the first half of the runs, swapped after.
    track_width, robot_radius, robot_height : wheel distance, footprint radius, height (m).
    start_position_std, start_heading_std_deg : manual placement at the start.
    dt : control period (s). time_limit_factor : a run ends after this multiple of the ideal meander's time.
    raster_cell, raster_margin : coverage raster (m) and how far it extends beyond the target area.
    log_images : also log every grabbed image (lossless) to run.mcap.
    """

    name: str = "cleaning"
    runs: int = bounded(II("runs"), ge=1, le=100_000)
    vision: str = bounded("render", choices=("render", "oracle"))
    world: str = "apartment"
    world_seed: int = bounded(0, ge=0, le=2**32 - 1)
    camera: CleaningCameraConfig = field(default_factory=CleaningCameraConfig)
    oracle: CleaningOracleConfig = field(default_factory=CleaningOracleConfig)
    wheel_error: float = bounded(0.05, ge=-0.5, le=0.5)
    track_width: float = bounded(0.30, gt=0.0, le=5.0)
    robot_radius: float = bounded(0.17, gt=0.0, le=5.0)
    robot_height: float = bounded(0.35, gt=0.0, le=10.0)
    start_position_std: float = bounded(0.01, ge=0.0, le=10.0)
    start_heading_std_deg: float = bounded(1.0, ge=0.0, le=180.0)
    dt: float = bounded(0.1, gt=0.0, le=10.0)
    time_limit_factor: float = bounded(3.0, gt=0.0, le=1000.0)
    raster_cell: float = bounded(0.01, ge=0.001, le=1.0)
    raster_margin: float = bounded(0.5, ge=0.0, le=100.0)
    log_images: bool = False

    def unused_keys(self) -> tuple[list[str], tuple[str, ...]]:
        """``camera`` is not used with ``vision=oracle``, ``oracle`` not with ``vision=render``
        (called by :func:`bionav.validation.typed_config`)."""
        import dataclasses

        other = {"render": "oracle", "oracle": "camera"}[self.vision]
        default = {"oracle": CleaningOracleConfig(), "camera": CleaningCameraConfig()}[other]
        used = tuple(f for f in self.__dataclass_fields__ if f != other)
        given = getattr(self, other)
        return [f"{other}.{f.name}" for f in dataclasses.fields(default)
                if getattr(given, f.name) != getattr(default, f.name)], used
