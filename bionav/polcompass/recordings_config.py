"""The ``recordings.*`` node of ``experiment=pol_recordings``: where the recordings are, how the hardware reads.

Read by the session pipeline (:mod:`bionav.polcompass.sessions`) and checked, as every config node,
by :func:`bionav.validation.typed_config` before a run starts. Angles in degrees only in keys
ending ``_deg``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Optional

from bionav.validation import Range, bounded, typed_config

#: the conditions of a recording session, in the order of every table (``sessions.csv``, ``summary.md``)
CONDITIONS = ("tod_daylight", "tod_dusk", "canopy")


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
    calibration_conditions: list[str] = bounded(list(CONDITIONS), length=(0, 3), item=Range(choices=CONDITIONS))
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


def recordings_config(node: Any) -> RecordingsConfig:
    """A ``recordings`` node (mapping, OmegaConf node or None for the defaults) as a checked :class:`RecordingsConfig`."""
    return typed_config(node, RecordingsConfig, key="recordings", what="experiment=pol_recordings")
