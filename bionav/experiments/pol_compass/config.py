"""Config of the polarized-light compass experiment ``experiment=pol_compass`` (thesis chapter 4).

Angles in degrees only in keys ending ``_deg``, azimuths counter-clockwise from east; times ISO 8601
with zone. Checked by the runner before the run (:func:`bionav.experiments.settings.experiment_config`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Optional

from bionav.validation import Range, bounded


@dataclass
class PolSkyConfig:
    """Simulated sky, and the sun the compass assumes (azimuths counter-clockwise from east).

    time : ISO-8601 time (or ``now``): sun from time and place via ephem; None: the angles below.
    turbidity : Preetham turbidity; sets the maximum degree of polarization with ``parameters=thesis``
        (``max_degree`` overrides it).
    parameters : ``fitted`` (default): the maximum degree of polarization fitted on the real POL-OP recordings
        (0.5: the simulated units then read the measured median degree, docs/polcompass.md "Sim-to-real");
        ``thesis``: from ``turbidity`` (``0.946 / T``).
    neutral_point_separation_deg : > 0: Berry et al. (2004) model with four neutral points.
    mount_heading_deg : simulated heading of the pan-tilt mount at pan 0.
    """

    time: Optional[str] = None
    latitude_deg: float = bounded(52.03, ge=-90.0, le=90.0)
    longitude_deg: float = bounded(8.53, ge=-180.0, le=360.0)
    sun_elevation_deg: float = bounded(30.0, ge=-90.0, le=90.0)
    sun_azimuth_deg: float = bounded(0.0, ge=-360.0, le=360.0)
    turbidity: float = bounded(1.25, ge=1.0, le=100.0)
    max_degree: Optional[float] = bounded(None, ge=0.0, le=1.0)
    parameters: str = bounded("fitted", choices=("fitted", "thesis"))
    neutral_point_separation_deg: float = bounded(0.0, ge=0.0, le=90.0)
    cloud_cover: float = bounded(0.0, ge=0.0, le=1.0)
    cloud_correlation_deg: float = bounded(15.0, gt=0.0, le=180.0)
    mount_heading_deg: float = bounded(20.0, ge=-360.0, le=360.0)
    magnetic_declination_deg: float = bounded(0.0, ge=-180.0, le=180.0)


@dataclass
class PolFilterConfig:
    """``filter_test``: the extra polarizer over unpolarized light."""

    axis_deg: float = bounded(0.0, ge=-360.0, le=360.0)
    efficiency: float = bounded(0.99, ge=0.0, le=1.0)


@dataclass
class PolVsEmConfig:
    """``vs_em_compass``: positions and samples per position."""

    positions: int = bounded(18, ge=1, le=100_000)
    samples: int = bounded(100, ge=1, le=1_000_000)


@dataclass
class PolScanConfig:
    """``evector_scan`` grid."""

    pan_step_deg: float = bounded(20.0, gt=0.0, le=360.0)
    tilts_deg: list[float] = bounded([-45.0, -30.0, -15.0, 0.0, 15.0, 30.0], length=(1, 10_000),
                                     item=Range(ge=-90.0, le=90.0))
    samples: int = bounded(5, ge=1, le=1_000_000)


@dataclass
class PolPartialConfig:
    """``partial_sky`` conditions (simulation)."""

    sun_elevations_deg: list[float] = bounded([15.0, 30.0, 45.0, 60.0], length=(1, 10_000),
                                              item=Range(ge=-90.0, le=90.0))
    cloud_covers: list[float] = bounded([0.0, 0.3, 0.5, 0.7, 0.85, 0.95], length=(1, 10_000),
                                        item=Range(ge=0.0, le=1.0))
    trials: int = bounded(4, ge=1, le=100_000)
    pan_step_deg: float = bounded(45.0, gt=0.0, le=360.0)
    tilts_deg: list[float] = bounded([-45.0, -30.0, -15.0, 0.0, 15.0, 30.0], length=(1, 10_000),
                                     item=Range(ge=-90.0, le=90.0))
    samples: int = bounded(1, ge=1, le=1_000_000)


@dataclass
class PolCompassConfig:
    """``experiment=pol_compass`` (thesis chapter 4); ``mode=<name>`` picks the sub-experiment.

    samples_per_step, step_deg : readings per pan position and pan step (rotation, filter_test).
    pan_range_deg : ``[min, max]``; None = the pan-tilt unit's whole range.
    tilt_deg : rotation: 0 looks at the zenith (axial result); tilted views resolve the pair.
    solver : ``least_squares`` (three units) or ``two_unit`` (eqs. 4.4-4.6 on units 1 and 2).
    calibration : ``auto`` (from the rotation at tilt 0, else nominal), ``rotation``, ``nominal``,
        ``file`` (``calibration_path``: calibration.json of an earlier rotation run).
    unit_angles_deg : nominal polarizer angles of the POL-OP units.
    ambiguity_margin : error-function difference needed to call the candidate pair resolved.
    min_degree : scans: readings with a lower degree of polarization (clouds) are ignored.
    fake_devices : serve fake devices on pseudo-terminals for the serial plugins (demo/tests).
    reference : vs_em_compass: the electromagnetic compass, a sensor plugin node (``name`` and its parameters).
    """

    name: str = "pol_compass"
    mode: str = bounded("rotation", choices=("filter_test", "rotation", "vs_em_compass", "evector_scan",
                                             "partial_sky"))
    samples_per_step: int = bounded(10, ge=1, le=1_000_000)
    step_deg: float = bounded(3.0, gt=0.0, le=360.0)
    pan_range_deg: Optional[list[float]] = bounded(None, length=2, item=Range(ge=-360.0, le=360.0))
    tilt_deg: float = bounded(0.0, ge=-90.0, le=90.0)
    solver: str = bounded("least_squares", choices=("least_squares", "two_unit"))
    calibration: str = bounded("auto", choices=("auto", "rotation", "nominal", "file"))
    calibration_path: Optional[str] = None
    unit_angles_deg: list[float] = bounded([0.0, 60.0, 120.0], length=(2, 8), item=Range(ge=-360.0, le=360.0))
    ambiguity_margin: float = bounded(1.0e-4, ge=0.0, le=1.0)
    min_degree: float = bounded(0.05, ge=0.0, le=1.0)
    fake_devices: bool = False
    sky: PolSkyConfig = field(default_factory=PolSkyConfig)
    filter: PolFilterConfig = field(default_factory=PolFilterConfig)
    reference: dict[str, Any] = field(default_factory=lambda: {"name": "tcm2_sim"})
    vs_em: PolVsEmConfig = field(default_factory=PolVsEmConfig)
    scan: PolScanConfig = field(default_factory=PolScanConfig)
    partial: PolPartialConfig = field(default_factory=PolPartialConfig)
