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


ARRAY_KEYS = ("photodiodes", "tilt_deg", "azimuth_sign", "photodiode_angles_deg", "pairs", "saturation_counts",
              "dark_counts", "imbalance_decades", "calibration")


def array_message(sensor_config, source: str, calibration: dict | None) -> dict:
    """The ``/pol_compass/calibration`` message of a recorded-array run: the calibration applied and the array keys.

    ``calibration`` is the file's JSON object (``source`` a path), the self-calibration's ``to_dict()``
    (``source="auto"``) or ``None`` (``source="none"``); ``array_config`` the ``sensor.*`` keys that say how
    the recorded array reads, so that ``sensor=replay`` decodes the replayed counts the same way.
    """
    config = {k: getattr(sensor_config, k) for k in ARRAY_KEYS if hasattr(sensor_config, k)}
    config = {k: (list(v) if isinstance(v, (list, tuple)) else v) for k, v in config.items()}
    config["pairs"] = [list(p) for p in config.get("pairs", [])]
    return {"kind": "array", "source": source, "calibration": calibration, "array_config": config}


def recorded_array_config(message: dict | None):
    """The :class:`~bionav.plugins.sensors.recording.RecordingConfig` a recorded run read its array with (defaults
    for a log without one)."""
    from bionav.plugins.sensors.recording import RecordingConfig

    config = RecordingConfig()
    for key, value in ((message or {}).get("array_config") or {}).items():
        if key in ARRAY_KEYS:
            setattr(config, key, value)
    return config


def _calibrated_array(array, how: str, counts, yaw, valid, *, recorded: dict | None = None):
    """``sensor.calibration``: ``none``, ``auto`` (self-calibrated from these samples) or a calibration file.

    ``recorded``: the calibration message of a replayed run, applied instead (``auto`` is recomputed from the
    replayed counts, which are the recorded ones). Returns the calibrated array and the message to record.
    """
    from bionav.polcompass.array_calibration import ArrayCalibration, calibrate_session, combine_sessions

    how = str(how or "none")
    raw = None
    if recorded is not None:
        how, raw = str(recorded.get("source") or "none"), recorded.get("calibration")
    if how == "none":
        return array, "none", None
    if how == "auto":
        cal = combine_sessions([calibrate_session(counts, yaw, valid, array)])
        raw = cal.to_dict()
    else:
        if raw is None:
            from bionav.files import read_json_file

            raw = read_json_file(how, what="The POL-OP calibration", fix=(
                "Point sensor.calibration at a calibration.json written by experiment=pol_recordings "
                "recordings.calibration=auto, or use sensor.calibration=auto or none."), max_bytes=16 * 2**20)
        cal = ArrayCalibration.from_dict(raw, source=f"The calibration {how}")
    # gains made the recorded compass worse (docs/polcompass.md): polarizer angle offsets only
    return cal.apply(array, gains=False, azimuths=False), how, raw


def recorded_rotation_mode(session, exp, *, sensor_config, decoder, plots=None) -> dict:
    """Read every recorded sample, decode it, and score it against the recorded yaw.

    Parameters
    ----------
    session : bionav.experiments.pol_compass.session.CompassSession
        ``session.read()`` records each reading; ``session.sun`` is the sun.
    exp : DictConfig
        ``cfg.experiment``.
    sensor_config : RecordingConfig
        How the array reads (geometry, saturation).
    decoder : Decoder plugin
    plots : Path, optional
    """
    from bionav.experiments.pol_compass import plots as plots_mod
    from bionav.polcompass import heading_errors
    from bionav.polcompass.array import PolArray, evectors_from_counts, masked_pol_ops
    from bionav.polcompass.decoders import heading_from_sun
    from bionav.polcompass.recordings import pol_op_validity, sample_validity

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
    from bionav.experiments.pol_compass.session import CALIBRATION_SCHEMA, CALIBRATION_TOPIC

    recorded = sensor.recorded(CALIBRATION_TOPIC) if hasattr(sensor, "recorded") else []
    array, how, raw = _calibrated_array(array, getattr(sensor_config, "calibration", "none"), counts, yaw, valid,
                                        recorded=recorded[-1] if recorded else None)
    session.write(CALIBRATION_TOPIC, array_message(sensor_config, how, raw), schema_name="bionav.PolCompassCalibration",
                  schema=CALIBRATION_SCHEMA)
    with np.errstate(invalid="ignore", divide="ignore"):
        ev = evectors_from_counts(counts, array)
    # a fault mask per POL-OP too: a unit with one saturated pair still gives one equation (sky_fit's fallback)
    ev = masked_pol_ops(ev, pol_op_validity(counts, array.pairs, saturation_counts=sensor_config.saturation_counts,
                                            dark_counts=sensor_config.dark_counts))
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
        "calibration": how if how in ("none", "auto") else "file",
    }
    if plots is not None:
        plots_mod.plot_rotation(plots / "heading_vs_pan.png", np.unwrap(yaw[ok]), heading[ok] - errors.offset, errors.errors,
                                axial=False, xlabel="robot yaw (deg, CCW, unwrapped)")
    return metrics
