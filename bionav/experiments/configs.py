"""Typed configs of the experiments: one dataclass per ``experiment=<name>``, defaults in one place.

Each dataclass is stored in Hydra's ConfigStore as ``experiment_schema/<name>``
(:func:`register`); the preset ``conf/experiment/<name>.yaml`` puts it under
``experiment`` first in its defaults list and then sets only what differs or
what refers to other keys. Hydra therefore rejects unknown keys and values of
the wrong type at composition; :func:`experiment_config` fills the defaults
for configs built without Hydra and checks every value against its range
(:func:`bionav.validation.check_config`), naming the key (``experiment.<key>``).

Units: metres and grid units as named; angles in degrees only in keys ending
``_deg``; times ISO 8601 with zone.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Optional

from omegaconf import II, DictConfig, OmegaConf

from bionav.validation import Range, bounded, check_config

_STEP = dict(gt=0.0, le=10.0)  # agent step length, grid units (thesis 3.2.3: 0.5)
_RADIUS = dict(gt=0.0, le=100.0)  # success radius, grid units (thesis: 1.0)
_LAT = Range(ge=-90.0, le=90.0)


# --------------------------------------------------------------------------- homing on grids
@dataclass
class GridHomingConfig:
    """``experiment=grid_homing``: every snapshot position against every other position.

    step_length, success_radius : agent step and success radius, grid units (thesis 3.2.3).
    n_quiver_plots : quiver plots of home-vector fields for this many snapshots.
    snapshots : only these snapshot indices (None = all); handy for quick looks.
    block : ``[i, n]``: only every n-th of those snapshots, starting at the i-th (0 <= i < n): one
        task of a run split into n; ``python -m bionav.experiments.merge`` joins the
        tasks into the unsplit run's files, with identical measures.
    """

    name: str = "grid_homing"
    step_length: float = bounded(0.5, **_STEP)
    success_radius: float = bounded(1.0, **_RADIUS)
    n_quiver_plots: int = bounded(4, ge=0, le=1000)
    snapshots: Optional[list[int]] = bounded(None, length=(1, 1_000_000), item=Range(ge=0, le=10**8))
    block: Optional[list[int]] = bounded(None, length=(2, 2), item=Range(ge=0, le=10**6))


@dataclass
class CrossDbConfig:
    """``experiment=cross_db`` (thesis 5.1.4, fig. 5.6): snapshots from one database, current views from another.

    family : databases sharing one grid (``db.image_size``, ``db.seed``, ``db.noise`` apply to all).
    snapshot_stride : evaluate every k-th grid cell along x and y as snapshot (1 = all, as the thesis).
    block : ``[i, n]``: only every n-th of those snapshots, from the i-th, for every database pair:
        task i of a run split into n (``python -m bionav.experiments.merge`` joins them).
    """

    name: str = "cross_db"
    family: list[str] = bounded(
        ["sim_original", "sim_arboreal", "sim_chairs", "sim_day", "sim_doorlit", "sim_screen", "sim_twilight",
         "sim_winlit"], length=(2, 100))
    snapshot_stride: int = bounded(2, ge=1, le=1000)
    step_length: float = bounded(0.5, **_STEP)
    success_radius: float = bounded(1.0, **_RADIUS)
    block: Optional[list[int]] = bounded(None, length=(2, 2), item=Range(ge=0, le=10**6))


@dataclass
class ParamSweepConfig:
    """``experiment=param_sweep`` (thesis 5.2.1, tables 5.5-5.7), run as a multirun.

    grid : which sweep grid of ``grids`` the sweeper and the jobs use (``full`` = the thesis', ``ci`` = reduced).
    grids : named sweep grids: ``signature``, ``image_size``, ``preprocess`` (sweeper values) and
        ``rings``, ``n_coeffs`` (evaluated inside each job); the preset ``conf/experiment/param_sweep.yaml``
        holds ``full`` (the thesis') and ``ci`` next to the sweeper parameters that use them.
    rings, n_coeffs : the values each job evaluates (from the selected grid unless overridden).
    scope : ``job`` -- one signature x image size x preprocessing per run (the multirun's jobs);
        ``grid`` -- every signature x image size x preprocessing of the grid in one run on
        ``workers`` processes (``experiment=param_sweep_grid``).
    """

    name: str = "param_sweep"
    scope: str = bounded("job", choices=("job", "grid"))
    grid: str = "full"
    grids: dict[str, Any] = field(default_factory=dict)
    rings: list[int] = bounded(II("experiment.grids.${experiment.grid}.rings"), length=(1, 1000),
                               item=Range(ge=1, le=1000))
    n_coeffs: list[int] = bounded(II("experiment.grids.${experiment.grid}.n_coeffs"), length=(1, 1000),
                                  item=Range(ge=1, le=1000))
    step_length: float = bounded(0.5, **_STEP)
    success_radius: float = bounded(1.0, **_RADIUS)


# --------------------------------------------------------------------------- spectral / skyline
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
    step_length: float = bounded(0.5, **_STEP)
    success_radius: float = bounded(1.0, **_RADIUS)
    square_test: bool = True
    square_side_m: float = bounded(2.0, gt=0.0, le=1000.0)
    sigma: float = bounded(30.0, gt=0.0, le=1e6)
    separation: str = bounded("learned", choices=("learned", "local"))
    plots: bool = True
    learn: LearnSamplesConfig = field(default_factory=LearnSamplesConfig)


# --------------------------------------------------------------------------- polarized-light compass
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


# --------------------------------------------------------------------------- cleaning robot
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


# --------------------------------------------------------------------------- compass on real skies
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
    calibration_parts : which parts to apply: ``gains`` (photodiode gains), ``angles`` (polarizer offsets).
        Default ``[angles]``: on the recordings the estimated gains made every decoder worse (docs/polcompass.md).
    calibration_solver : ``pol_op`` (the POL-OP chain, each pair at its mean calibrated orientation) or
        ``stokes`` (every photodiode at its own angle, linear least squares).
    """

    path: Optional[str] = None
    exclude_units: Any = bounded("auto")  # auto | none | [unit, ...]: checked in pol_recordings.excluded_units
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
    calibration_parts: list[str] = bounded(["angles"], length=(1, 2), item=Range(choices=("gains", "angles")))
    calibration_solver: str = bounded("pol_op", choices=("pol_op", "stokes"))


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
        ``sim_canopy_cover`` = 0.1 is fitted so that simulated canopy sessions score like the real ones
        (cover 0.5 gave 2-21 degrees depending on the cloud draw against 3.2 real). ``sim_repeats``: each
        session is simulated that many times (each its own device and cloud draw), errors pooled.
    sim_view_sigma : each photodiode's own smooth departure from the shared sky ring (log counts, world frame;
        ``pol_recordings.view_field``); 0.1 is *fitted* on the counts, not on heading errors: the self-calibration's
        ring residual of the 18 daylight sessions has a median of 0.087 (0.081-0.101 leaving one day out), and the
        simulation's residual is about 0.9 ``sim_view_sigma``. ``sim_tilt_sigma_deg``, ``sim_azimuth_sigma_deg``:
        unit pointing tolerances (0: tilts up to 6 degrees gave ring residuals of 0.01-0.08 only).
    record_samples : every decoded sample of the chosen decoder into run.mcap.
    """

    name: str = "pol_recordings"
    compare: list[str] = field(
        default_factory=lambda: ["sky_fit", "two_unit", "sol", "four_zeros", "eigenvector", "mean_vector"])
    simulate: bool = True
    sim_noise: float = bounded(0.01, ge=0.0, le=1.0)
    sim_gain_sigma: float = bounded(0.1, ge=0.0, le=1.0)
    sim_canopy_cover: float = bounded(0.1, ge=0.0, le=1.0)
    sim_repeats: int = bounded(4, ge=1, le=100)
    sim_angle_sigma_deg: float = bounded(2.0, ge=0.0, le=45.0)
    sim_max_degree: float = bounded(0.5, gt=0.0, le=1.0)
    sim_tilt_sigma_deg: float = bounded(0.0, ge=0.0, le=45.0)
    sim_azimuth_sigma_deg: float = bounded(0.0, ge=0.0, le=45.0)
    sim_view_sigma: float = bounded(0.1, ge=0.0, le=2.0)
    record_samples: bool = True


@dataclass
class LayoutConfig:
    """``layout=<name>`` of ``experiment=cleaning`` (``bionav/conf/layout/*.yaml``: thesis fig. 7.2).

    n_lanes, lane_length, spacing : the meander's lanes (m); unit_width : cleaning width (m).
    turn : side of the next lane seen from the first lane. wall_offset : first lane's distance from the
    wall on its right (m). start, start_heading_deg : ``[x, y]`` in the world (m) and heading; None:
    placed along a wall automatically.
    """

    name: str = "long_lanes"
    n_lanes: int = bounded(7, ge=1, le=1000)
    lane_length: float = bounded(4.0, gt=0.0, le=1000.0)
    spacing: float = bounded(0.30, gt=0.0, le=100.0)
    unit_width: float = bounded(0.30, gt=0.0, le=100.0)
    turn: str = bounded("left", choices=("left", "right"))
    wall_offset: float = bounded(0.25, ge=0.0, le=100.0)
    start: Optional[list[float]] = bounded(None, length=2, item=Range(ge=-1e4, le=1e4))
    start_heading_deg: Optional[float] = bounded(None, ge=-360.0, le=360.0)


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


#: other option groups with a typed schema: group -> dataclass (checked by :func:`check_group_nodes`)
GROUP_CONFIGS: dict[str, type] = {"layout": LayoutConfig, "data": DataConfig}


def typed_node(node: Any, schema: type, *, prefix: str, what: str) -> DictConfig:
    """``node`` merged onto ``schema``: unknown keys and wrong types named, every value range-checked.

    Parameters
    ----------
    node : DictConfig or Mapping
        The (resolved) config node.
    schema : type
        Its dataclass.
    prefix : str
        The key users type for the node (``layout``).
    what : str
        Said in messages (``layout=short_lanes``).
    """
    from omegaconf.errors import OmegaConfBaseException

    from bionav.config import unknown_key_message
    from bionav.errors import UserError

    plain = OmegaConf.to_container(node, resolve=True) if isinstance(node, DictConfig) else dict(node)
    try:
        typed = OmegaConf.merge(OmegaConf.structured(schema), plain)
        instance = OmegaConf.to_object(typed)
    except OmegaConfBaseException as exc:
        key = str(getattr(exc, "full_key", "") or "")
        if type(exc).__name__ in ("ConfigKeyError", "ConfigAttributeError") and key:
            parent, bad = key.rsplit(".", 1) if "." in key else ("", key)
            where = OmegaConf.select(OmegaConf.structured(schema), parent) if parent else OmegaConf.structured(schema)
            valid = [str(k) for k in where.keys()] if isinstance(where, DictConfig) else []
            full_parent = f"{prefix}.{parent}" if parent else prefix
            raise UserError(unknown_key_message(full_parent, bad, valid, what=what)) from None
        if type(exc).__name__ == "MissingMandatoryValue" and key:
            raise UserError(f"{prefix}.{key} has no value ({what} needs it); add {prefix}.{key}=<value> "
                            "on the command line.") from None
        raise UserError(
            f"bad value for {prefix}.{key or '<key>'} ({what}): {str(exc).splitlines()[0]}. "
            f"Give it a value of the declared type (see {schema.__name__} in bionav/experiments/configs.py)."
        ) from None
    check_config(instance, prefix=prefix)
    return typed


def check_group_nodes(cfg: DictConfig) -> None:
    """Check the ``layout`` and ``data`` nodes (when present) against :data:`GROUP_CONFIGS`."""
    for group, schema in GROUP_CONFIGS.items():
        node = cfg.get(group) if isinstance(cfg, DictConfig) else None
        if node is not None:
            typed_node(node, schema, prefix=group, what=f"{group}={node.get('name', '?')}")


# --------------------------------------------------------------------------- top-level run settings
# --------------------------------------------------------------------------- routes in mesh worlds
ROUTE_METHODS = ("perfect_memory", "windowed", "zernike", "homing")
ROUTE_PROTOCOLS = ("bionav", "ardin2016")


@dataclass
class RouteHomingConfig:
    """``experiment=route_homing``: following real ant routes (docs/worlds.md).

    routes : route names (``Ant<a>_Route<r>``); empty = ``db.route`` (``bionav``) or Route1 of Ant1..Ant15 (``ardin2016``).
    methods : subset of ``perfect_memory``, ``windowed``, ``zernike``, ``homing``.
    offsets_m : lateral offsets of the open-loop test points, metres (left positive); must include 0.
    test_stride : every k-th route view is a test point.
    error_threshold_deg : heading error below which a test point is inside the route's catchment.
    window : snapshots ahead of the last match searched by ``windowed`` (and by ``homing`` to track progress).
    lookahead : ``homing`` targets the snapshot this many views ahead of the best match.
    test_step_m : test-step length of methods with test steps, metres.
    closed_loop : run the simulated agent from a displaced start.
    start_offset_m, agent_step_m, success_radius_m, give_up_m : the agent's start displacement (left
        positive), step (null: the protocol's, 0.05 for ``bionav``, 0.1 for ``ardin2016``), success radius
        around the route's end and give-up distance from the route, metres.
    max_steps_factor : step budget = factor x route length / agent step.
    zernike_order : highest Zernike-moment order of the ``zernike`` method.
    protocol : ``bionav`` (the tests above: open loop at lateral offsets, closed loop from a displaced
        start with a full 360-degree choice of heading; harder) or ``ardin2016`` (the published test of
        Ardin et al. 2016, doi:10.1371/journal.pcbi.1004683: start on the route, scan
        ``+-scan_half_deg`` in ``scan_step_deg`` around the current heading, step ``agent_step_m``,
        put back on the nearest route view and count an error beyond ``putback_m``).
    agents : ``ardin2016``: route agents (``bionav.route_agents``: ``perfect_memory``,
        ``windowed_memory``, ``infomax``, ``mushroom_body``) and homing methods (``bionav.homing``
        names, e.g. ``minwarping``, ``mfdid``, ``sift``, ``parameter``) following the route by homing
        to the view ``lookahead`` after the best match.
    agent_params : ``ardin2016``: ``{agent: {parameter: value}}`` overrides of the agents' configs
        (command line: ``+experiment.agent_params.mushroom_body.n_kc=5000``).
    seeds : ``ardin2016``: noise seeds (camera noise, position jitter, random networks); one run each.
    position_jitter_m : ``ardin2016``: Gaussian position noise added after each step, metres (std per axis).
    scan_half_deg, scan_step_deg : ``ardin2016``: the scan around the current heading, degrees.
    putback_m : ``ardin2016``: distance from the route beyond which the agent is put back (an error),
        and the radius around the nest that ends the run, metres.
    view_size : ``ardin2016``: ``[W, H]`` of the agents' views (the paper's 36 x 10).
    training_heading : ``ardin2016``: the training views face the direction of travel to the next route
        view (``travel``) or the ant's recorded heading there (``recorded``); the put-back faces the same.
    supersample : ``ardin2016``: rays per 4-degree pixel along each axis (1: one ray at the pixel centre;
        2, 4: the mean of 2 x 2 or 4 x 4 rays, area pixels as the reference renderer's rasterised patches).
    """

    name: str = "route_homing"
    routes: list[str] = bounded([], length=(0, 1000))
    methods: list[str] = bounded(list(ROUTE_METHODS), length=(1, 4), item=Range(choices=ROUTE_METHODS))
    offsets_m: list[float] = bounded([-0.4, -0.2, -0.1, 0.0, 0.1, 0.2, 0.4], length=(1, 100),
                                     item=Range(ge=-5.0, le=5.0))
    test_stride: int = bounded(5, ge=1, le=10_000)
    error_threshold_deg: float = bounded(45.0, gt=0.0, le=180.0)
    window: int = bounded(10, ge=1, le=10_000)
    lookahead: int = bounded(2, ge=1, le=1000)
    test_step_m: float = bounded(0.05, gt=0.0, le=1.0)
    closed_loop: bool = True
    start_offset_m: float = bounded(0.2, ge=-5.0, le=5.0)
    agent_step_m: Optional[float] = bounded(None, gt=0.0, le=1.0)
    success_radius_m: float = bounded(0.2, gt=0.0, le=5.0)
    give_up_m: float = bounded(1.0, gt=0.0, le=20.0)
    max_steps_factor: float = bounded(2.0, ge=1.0, le=20.0)
    zernike_order: int = bounded(16, ge=1, le=40)
    plots: bool = True
    protocol: str = bounded("bionav", choices=ROUTE_PROTOCOLS)
    agents: list[str] = bounded(["perfect_memory", "windowed_memory", "infomax", "mushroom_body"], length=(1, 50))
    agent_params: dict[str, Any] = field(default_factory=dict)
    seeds: list[int] = bounded([0], length=(1, 100), item=Range(ge=0, le=2**32 - 1))
    position_jitter_m: float = bounded(0.0, ge=0.0, le=1.0)
    scan_half_deg: float = bounded(60.0, gt=0.0, le=180.0)
    scan_step_deg: int = bounded(2, choices=(1, 2, 4))
    putback_m: float = bounded(0.2, gt=0.0, le=5.0)
    view_size: list[int] = bounded([36, 10], length=2, item=Range(ge=2, le=74))
    training_heading: str = bounded("travel", choices=("travel", "recorded"))
    supersample: int = bounded(4, choices=(1, 2, 4))


@dataclass
class RunSettings:
    """Top-level keys of every run (``conf/config.yaml``): ``seed=``, ``workers=``."""

    seed: int = bounded(0, ge=0, le=2**32 - 1)
    workers: int = bounded(2, ge=1, le=1024)


def check_run_settings(cfg: DictConfig) -> None:
    """Check the top-level ``seed`` and ``workers`` against :class:`RunSettings` (key, value, range)."""
    from bionav.errors import UserError

    values = {}
    for f in ("seed", "workers"):
        value = cfg.get(f) if isinstance(cfg, DictConfig) else None
        if value is None:
            continue
        if isinstance(value, bool) or not isinstance(value, int):
            raise UserError(f"bad value {f}={value}: it must be an integer; allowed: "
                            f"{RunSettings.__dataclass_fields__[f].metadata['range'].describe(integer=True)}.")
        values[f] = value
    check_config(RunSettings(**values), prefix="")


#: experiment name -> its config dataclass
EXPERIMENT_CONFIGS: dict[str, type] = {
    "grid_homing": GridHomingConfig,
    "cross_db": CrossDbConfig,
    "param_sweep": ParamSweepConfig,
    "contrast_lda": ContrastLdaConfig,
    "contrast_scan": ContrastScanConfig,
    "skyline_homing": SkylineHomingConfig,
    "pol_compass": PolCompassConfig,
    "cleaning": CleaningConfig,
    "pol_recordings": PolRecordingsConfig,
    "route_homing": RouteHomingConfig,
}


def register(store=None) -> None:
    """Store every experiment's dataclass as ``experiment_schema/<name>`` in Hydra's ConfigStore."""
    from hydra.core.config_store import ConfigStore

    store = store or ConfigStore.instance()
    for name, cls in EXPERIMENT_CONFIGS.items():
        store.store(group="experiment_schema", name=name, node=cls, provider="bionav")
    # the top-level recordings.* node of experiment=pol_recordings
    store.store(name="recordings_schema", node=RecordingsConfig, provider="bionav")


def experiment_config(cfg: DictConfig, name: str | None = None) -> DictConfig:
    """The run's ``experiment`` node typed by its dataclass, defaults filled, every value checked.

    Parameters
    ----------
    cfg : DictConfig
        The whole run config (``experiment.name`` selects the dataclass;
        interpolations such as ``${seed}`` resolve against it, ``seed``
        defaulting to 0).
    name : str, optional
        The experiment to assume when the node has no ``name`` (an experiment
        module passes its own).

    Returns
    -------
    DictConfig
        A structured node (attribute access, ``.get``, typed assignment) of
        :data:`EXPERIMENT_CONFIGS` ``[name]``; an experiment without a
        dataclass gets its node back unchanged.

    Raises
    ------
    UserError
        An unknown key (the message lists the valid ones and the closest), a
        value of the wrong type, or a value outside its range (key, value and
        allowed range named).
    """
    from omegaconf.errors import OmegaConfBaseException

    from bionav.config import unknown_key_message
    from bionav.errors import UserError

    node = cfg.get("experiment") if isinstance(cfg, DictConfig) else None
    if node is not None and node.get("name") is not None:
        name = str(node.get("name"))
    schema = EXPERIMENT_CONFIGS.get(name or "")
    if schema is None:
        return node
    try:
        root = OmegaConf.merge(OmegaConf.create({"seed": 0, "experiment": OmegaConf.structured(schema)}), cfg)
        exp = root.experiment
        instance = OmegaConf.to_object(exp)
    except OmegaConfBaseException as exc:
        key = str(getattr(exc, "full_key", "") or "")
        kind = type(exc).__name__
        if kind in ("ConfigKeyError", "ConfigAttributeError") and key:
            parent, bad = key.rsplit(".", 1) if "." in key else ("", key)
            where = OmegaConf.select(OmegaConf.structured(schema), parent.partition(".")[2]) if "." in parent \
                else OmegaConf.structured(schema)
            valid = [str(k) for k in where.keys()] if isinstance(where, DictConfig) else []
            raise UserError(unknown_key_message(parent, bad, valid, what=f"experiment={name}")) from None
        if kind == "MissingMandatoryValue" and key:
            raise UserError(f"{key} has no value (experiment={name} needs it); add {key}=<value> "
                            "on the command line.") from None
        raise UserError(
            f"bad value for {key or 'experiment'} (experiment={name}): {str(exc).splitlines()[0]}. "
            f"Give it a value of the declared type (see {schema.__name__} in bionav/experiments/configs.py)."
        ) from None
    check_config(instance, prefix="experiment")
    return exp
