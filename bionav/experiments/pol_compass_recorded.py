"""``experiment=pol_compass mode=rotation`` on recorded POL-OP counts (``sensor=recording``).

The recorded robot turns instead of a pan-tilt unit: every sample the
``recording`` sensor plays (or a replay of such a run plays back) is read and
recorded to ``run.mcap``, decoded by the POL-OP array chain
(:mod:`bionav.polcompass.array`) and a decoder plugin (``decoder=``, default
``sky_fit``), and compared with the recorded IMU yaw after removing one
constant offset. The sun comes from ``experiment.sky`` (``time``,
``latitude_deg``, ``longitude_deg``), like for the live compass.
"""

from __future__ import annotations

import numpy as np

from bionav.errors import UserError


def is_array_reading(message: dict) -> bool:
    """Whether a raw reading comes from a POL-OP array (photodiode counts per unit)."""
    return isinstance(message, dict) and "photodiodes" in message and "units" in message


def _calibrated_array(array, how: str, counts, yaw, valid):
    """``sensor.calibration``: ``none``, ``auto`` (self-calibrated from these samples) or a calibration file."""
    from bionav.polcompass.array_calibration import ArrayCalibration, calibrate_session, combine_sessions

    how = str(how or "none")
    if how == "none":
        return array
    if how == "auto":
        cal = combine_sessions([calibrate_session(counts, yaw, valid, array)])
    else:
        cal = ArrayCalibration.load(how)
    return cal.apply(array, gains=False, azimuths=False)  # gains made the recorded compass worse (docs/polcompass.md)


def recorded_rotation_mode(session, exp, *, sensor_config, decoder, plots=None) -> dict:
    """Read every recorded sample, decode it, and score it against the recorded yaw.

    Parameters
    ----------
    session : pol_compass_session.Session
        ``session.read()`` records each reading; ``session.sun`` is the sun.
    exp : DictConfig
        ``cfg.experiment``.
    sensor_config : RecordingConfig
        How the array reads (geometry, saturation).
    decoder : Decoder plugin
    plots : Path, optional
    """
    from bionav.experiments import pol_compass_plots as plots_mod
    from bionav.polcompass import heading_errors
    from bionav.polcompass.array import PolArray, evectors_from_counts
    from bionav.polcompass.decoders import heading_from_sun
    from bionav.polcompass.recordings import sample_validity

    sensor = session.sensor
    if hasattr(sensor, "remaining"):
        n = sensor.remaining()
    else:
        n = sum(1 for m in sensor.recorded("/sensor/raw") if is_array_reading(m))
    if n == 0:
        raise UserError("sensor=recording played no samples; check sensor.path.")
    readings = [session.read() for _ in session.progress(range(n), desc="recorded rotation", total=n)]
    k, p = int(readings[0]["units"]), int(readings[0]["photodiodes"])
    counts = np.asarray([r["counts"] for r in readings], float).reshape(n, k, p)
    yaw = np.asarray([r["yaw"] for r in readings], float)
    array = PolArray.fan(
        np.degrees(sensor_config.azimuth_sign * np.asarray(readings[0]["azimuths"], float)),
        tilt_deg=sensor_config.tilt_deg,
        photodiode_angles_deg=sensor_config.photodiode_angles_deg,
        pairs=sensor_config.pairs,
    )
    valid = sample_validity(counts, saturation_counts=sensor_config.saturation_counts,
                            dark_counts=sensor_config.dark_counts, imbalance_decades=sensor_config.imbalance_decades)
    array = _calibrated_array(array, getattr(sensor_config, "calibration", "none"), counts, yaw, valid)
    with np.errstate(invalid="ignore", divide="ignore"):
        ev = evectors_from_counts(counts, array)
    est = decoder.decode(ev, valid & np.isfinite(ev.angle), array=array, sun_elevation=float(session.sun.elevation))
    heading = heading_from_sun(est.azimuth, session.sun.azimuth)
    ok = np.isfinite(heading)
    if not ok.any():
        raise UserError("No recorded sample could be decoded (all units saturated, dark or faulty); check the recording.")
    errors = heading_errors(heading[ok], yaw[ok], axial=False)
    metrics = {
        "heading_rmse_deg": errors.rmse_deg,
        "heading_mae_deg": errors.mae_deg,
        "n_samples": int(n),
        "axial": False,
        "decoded_fraction": float(np.mean(ok)),
        "resolved_fraction": float(np.mean(est.resolved)),
        "heading_offset_deg": float(np.degrees(errors.offset)),
        "calibration": str(getattr(sensor_config, "calibration", "none")) if getattr(sensor_config, "calibration", "none")
        in ("none", "auto") else "file",
    }
    if plots is not None:
        plots_mod.plot_rotation(plots / "heading_vs_pan.png", np.unwrap(yaw[ok]), heading[ok] - errors.offset, errors.errors,
                                axial=False, xlabel="robot yaw (deg, CCW, unwrapped)")
    return metrics
