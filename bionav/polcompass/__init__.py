"""The polarized-light compass (thesis chapter 4): sensor chain, compass algorithms, calibration."""

from bionav.polcompass.calibration import UnitCalibration, calibrate_from_rotation
from bionav.polcompass.compass import (
    HeadingErrors,
    candidate_pair,
    choose_candidate,
    delogarithmise,
    evector_from_compass_counts,
    heading_errors,
    least_squares_evector,
    two_unit_evector,
    volts_to_decades,
    zenith_heading,
)
from bionav.polcompass.electronics import (
    ChainParameters,
    ChannelMismatch,
    adc_counts,
    counts_to_volts,
    log_ratio_voltage,
    sample_mismatch,
)
from bionav.polcompass.headings import EvectorPredictor, fit_scan_heading, pose_headings, solve_pose
from bionav.polcompass.optics import CompassOptics, cone_samples, sensor_frame
from bionav.polcompass.simulation import CompassScene, SimulatedCompassHardware

__all__ = [
    "ChainParameters",
    "ChannelMismatch",
    "CompassOptics",
    "CompassScene",
    "EvectorPredictor",
    "HeadingErrors",
    "SimulatedCompassHardware",
    "UnitCalibration",
    "adc_counts",
    "calibrate_from_rotation",
    "candidate_pair",
    "choose_candidate",
    "cone_samples",
    "counts_to_volts",
    "delogarithmise",
    "evector_from_compass_counts",
    "fit_scan_heading",
    "heading_errors",
    "least_squares_evector",
    "log_ratio_voltage",
    "pose_headings",
    "sample_mismatch",
    "sensor_frame",
    "solve_pose",
    "two_unit_evector",
    "volts_to_decades",
    "zenith_heading",
]
