"""Configs of the polarized-light compass: ``experiment=pol_compass`` and ``experiment=pol_recordings``
(its top-level ``recordings.*`` node).

Units: metres and grid units as named; angles in degrees only in keys ending ``_deg``; times ISO 8601
with zone. Checked by :func:`bionav.experiments.configs.experiment_config`.
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


@dataclass
class RecordingsConfig:
    """``recordings.*`` of ``experiment=pol_recordings``: where the recordings are, how the hardware reads.

    path : folder of sessions (``<HH-MM>__<Day>_<dd-mm-yy>/<n>.json``), one session folder, or one file.
    exclude_units : ``auto`` (faults detected from each session's counts), ``none``, or a list of unit
        numbers (checked against the recordings' units).
    saturation_counts : counts at or above: saturated or overflowing (the recorded sensor plateaus near
        11,300 and overflows at 32,768). dark_counts : counts below: no light (1: a zero count has no log ratio; how
        much light is enough is the decoder's business, ``decoder.noise_counts``).
    imbalance_decades : POL-OP light imbalance beyond which a reading (per sample) or a unit (median
        over the session) is bad. blind_fraction : share of identical orthogonal readings that makes a
        unit polarization-blind.
    tilt_deg, azimuth_sign, photodiode_angles_deg, pairs : array geometry (file azimuths clockwise:
        ``azimuth_sign=-1``; photodiode angles in the unit frame in file order; POL-OPs as index pairs).
    latitude_deg, longitude_deg, utc_offset_hours : the site and the folder names' time zone.
    dusk_elevation_deg : time-of-day sessions with the sun lower count as ``tod_dusk``.
    on_bad_file : ``error`` (score the good files, then stop naming the bad ones) or ``skip`` (warn).
    calibration : ``none`` (nominal gains and polarizer angles), ``auto`` (self-calibration from the
        recordings' daylight rotations, each day decoded with the calibration of the other days:
        leave one day out; ``calibration.json`` of all days in the run folder) or the path of such a file.
    calibration_parts : which parts to apply: ``gains`` (photodiode gains), ``angles`` (polarizer offsets), ``tilt``
        (the sensor's first-order mount tilt, learned from the daylight rotations with the chosen decoder).
        Default ``[angles]``: on the recordings the estimated gains made every decoder worse (docs/polcompass.md).
    calibration_conditions : the session conditions (``tod_daylight``, ``tod_dusk``, ``canopy``) a calibration is
        applied to; the others are decoded uncalibrated (``sessions.csv`` column ``calibration`` says why).
        Default: all three (docs/polcompass.md "Self-calibration": what leaving canopy out does, and why that is
        not the default).
    calibration_solver : ``pol_op`` (the POL-OP chain, each pair at its mean calibrated orientation) or
        ``stokes`` (every photodiode at its own angle, linear least squares).
    reference : the heading reference the errors are taken against (the same for every decoder), always one
        offset per session unless said: ``stitched`` (default: the yaw's runs between odometry restarts,
        :func:`bionav.polcompass.recordings.yaw_restarts`, turned into the first run's reference by the counts'
        sky ring alone), ``session`` (the logged yaw as it is; the authors align it once per session),
        ``yaw_run`` (one offset per run) or ``rotation`` (one per file; a lower bound). docs/polcompass.md,
        "The reference: the logged yaw restarts".
    """

    path: Optional[str] = None
    exclude_units: Any = bounded("auto")  # auto | none | [unit, ...]: checked in validate()
    saturation_counts: float = bounded(11000.0, gt=0.0, le=1e12)
    dark_counts: float = bounded(1.0, ge=0.0, le=1e12)
    imbalance_decades: float = bounded(0.15, gt=0.0, le=3.0)
    blind_fraction: float = bounded(0.5, gt=0.0, le=1.0)
    tilt_deg: float = bounded(45.0, ge=0.0, le=90.0)
    azimuth_sign: float = bounded(-1.0, choices=(-1.0, 1.0))
    photodiode_angles_deg: list[float] = bounded([-45.0, 45.0, 0.0, 90.0], length=(1, 16), item=Range(ge=-360.0, le=360.0))
    pairs: list[list[int]] = bounded([[2, 3], [1, 0]], length=(1, 8), item=Range(length=2, item=Range(ge=0, le=15)))
    latitude_deg: float = bounded(39.2, ge=-90.0, le=90.0)
    longitude_deg: float = bounded(9.1, ge=-180.0, le=180.0)
    utc_offset_hours: float = bounded(2.0, ge=-14.0, le=14.0)
    dusk_elevation_deg: float = bounded(10.0, ge=-90.0, le=90.0)
    on_bad_file: str = bounded("error", choices=("error", "skip"))
    calibration: str = "none"
    calibration_parts: list[str] = bounded(["angles", "tilt"], length=(1, 3), item=Range(choices=("gains", "angles", "tilt")))
    calibration_solver: str = bounded("pol_op", choices=("pol_op", "stokes"))
    calibration_conditions: list[str] = bounded(
        ["tod_daylight", "tod_dusk", "canopy"], length=(0, 3), item=Range(choices=("tod_daylight", "tod_dusk", "canopy")))
    reference: str = bounded("stitched", choices=("stitched", "session", "yaw_run", "rotation"))

    def validate(self) -> None:
        """``exclude_units`` is ``auto``, ``none`` or a list of unit numbers (called by ``typed_config``)."""
        ex = self.exclude_units
        ok = ex in ("auto", "none") if isinstance(ex, str) else (
            isinstance(ex, (list, tuple)) and all(isinstance(u, int) and not isinstance(u, bool) for u in ex))
        if not ok:
            from bionav.errors import UserError

            raise UserError(f"bad value recordings.exclude_units={ex}: allowed: auto, none or a list of unit "
                            "numbers such as [5,7].")


@dataclass
class PolRecordingsConfig:
    """``experiment=pol_recordings`` (issue 15): decode recorded POL-OP rotations, score every sample.

    compare : decoders scored in ``sessions.csv`` besides ``decoder=``.
    simulate : also decode each session simulated in the sky model (the sim-to-real gap), with
        ``sim_noise`` (count noise, fraction), ``sim_gain_sigma`` (photodiode gain spread),
        ``sim_canopy_cover`` (cloud-map cover standing in for canopy gaps), ``sim_max_degree``.
        ``sim_gain_sigma`` = 0.1 is measured: the standard deviation of the self-calibrated log photodiode
        gains of the recorded sensor's healthy units (``recordings.calibration=auto``: 0.096; docs/polcompass.md),
        ``sim_angle_sigma_deg`` = 2 that of their polarizer offsets (2.1 degrees);
        ``sim_canopy_cover`` = 0 is fitted (with the view field, seeds 0-3, canopy sessions only) as the cover whose
        simulated canopy sessions score closest to the real ones: with the cloud map a snapshot of a ``CloudLayer``,
        covers 0 / 0.01 / 0.02 / 0.05 gave 3.65 / 3.73 / 3.75 / 3.92 degrees against 2.87 real, so no cover above 0
        helps (docs/polcompass.md). ``sim_repeats``: each
        session is simulated that many times (each its own device and cloud draw), errors pooled.
    sim_view_sigma : each photodiode's own smooth departure from the shared sky ring (log counts, world frame;
        ``pol_recordings_session.view_field``); 0.1 is *fitted* on the counts, not on heading errors: the self-calibration's
        ring residual of the 18 daylight sessions has a median of 0.087 (0.081-0.101 leaving one day out), and the
        simulation's residual is about 0.9 ``sim_view_sigma``. ``sim_view_shared``: the fraction of that field's
        variance a unit's photodiodes have in common (it cancels in a POL-OP's log ratio; the ring residual cannot
        tell it): 0.8 is *fitted* on the daylight heading MAE (0 / 0.5 / 0.8 / 0.95 over seeds 0-3: simulated 4.7 /
        4.1 / 3.6 / 3.3 degrees against 3.6 real, means of the seeds) and checked on dusk and canopy (docs/polcompass.md).
        With the gain split below and ``recordings.reference=stitched`` it still matches (2.77 simulated against
        2.73 real by day). ``sim_gain_shared``: the fraction of the log-gain variance a unit's photodiodes have in
        common (it cancels in a POL-OP's log ratio); 0.5 is *measured* on the counts: the healthy units'
        self-calibrated log gains spread by 0.096, the log ratios of their POL-OP pairs by 0.094 rms, so each
        photodiode's own part is 0.094 / sqrt(2) = 0.066 and the unit's common part 0.070 (a share of 0.53).
        ``sim_tilt_sigma_deg``, ``sim_azimuth_sigma_deg``:
        unit pointing tolerances (0: tilts up to 6 degrees gave ring residuals of 0.01-0.08 only).
    record_samples : every decoded sample of the chosen decoder into run.mcap.
    """

    name: str = "pol_recordings"
    compare: list[str] = field(
        default_factory=lambda: ["sky_fit", "two_unit", "sol", "four_zeros", "eigenvector", "mean_vector"])
    simulate: bool = True
    sim_noise: float = bounded(0.01, ge=0.0, le=1.0)
    sim_gain_sigma: float = bounded(0.1, ge=0.0, le=1.0)
    sim_canopy_cover: float = bounded(0.0, ge=0.0, le=1.0)
    sim_repeats: int = bounded(4, ge=1, le=100)
    sim_angle_sigma_deg: float = bounded(2.0, ge=0.0, le=45.0)
    sim_max_degree: float = bounded(0.5, gt=0.0, le=1.0)
    sim_tilt_sigma_deg: float = bounded(0.0, ge=0.0, le=45.0)
    sim_azimuth_sigma_deg: float = bounded(0.0, ge=0.0, le=45.0)
    sim_view_sigma: float = bounded(0.1, ge=0.0, le=2.0)
    sim_view_shared: float = bounded(0.8, ge=0.0, le=1.0)
    sim_gain_shared: float = bounded(0.5, ge=0.0, le=1.0)
    record_samples: bool = True
