"""The modes of ``experiment=pol_compass`` (``mode=<name>``) on an opened
:class:`~bionav.experiments.pol_compass.session.CompassSession`.

``rotation`` and ``filter_test`` (:func:`rotation_mode`), ``vs_em_compass`` (:func:`vs_em_mode`),
``evector_scan`` (:func:`evector_scan_mode`) and ``partial_sky`` (:func:`partial_sky_mode`); the
processing after the ADC is shared by simulated, real and replayed sessions. Angles in radians
inside, degrees in keys and columns ending ``_deg``; azimuths counter-clockwise from east.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from bionav.errors import UserError
from bionav.experiments.pol_compass.session import CALIBRATION_TOPIC, CompassSession, cloud_field, sky_model
from bionav.files import write_csv_atomic
from bionav.polcompass.compass import evector_from_compass_counts
from bionav.polcompass.headings import pose_headings


# ---------------------------------------------------------------------------
# processing shared by simulated, real and replayed sessions (after the ADC)
# ---------------------------------------------------------------------------
def counts_of(readings: list[dict]) -> np.ndarray:
    """ADC counts of recorded compass readings, shape ``(N, K)``."""
    return np.asarray([r["counts"] for r in readings], dtype=float)


def summarize(errors, *, axial: bool, n: int) -> dict[str, Any]:
    """The contract's metrics from a :class:`~bionav.polcompass.HeadingErrors`."""
    return {"heading_rmse_deg": errors.rmse_deg, "heading_mae_deg": errors.mae_deg, "n_samples": int(n), "axial": bool(axial)}


def sensor_calibration(sensor) -> dict | None:
    """The calibration message of the sensor: the file ``sensor.calibration`` names, or the one a replayed run recorded.

    Returns ``None`` where ``experiment.calibration`` decides (``sensor.calibration=none``, or a replay of a
    run without a sensor calibration). The message follows
    :data:`~bionav.experiments.pol_compass.session.CALIBRATION_SCHEMA`.
    """
    if hasattr(sensor, "recorded"):  # sensor=replay: what the recorded run applied
        messages = sensor.recorded(CALIBRATION_TOPIC)
        return dict(messages[-1]) if messages else None
    cal = getattr(sensor, "calibration", None)
    if cal is None or not hasattr(cal, "center_v"):
        return None
    return {"kind": "units", "source": str(sensor.config.calibration), "calibration": cal.to_dict(), "array_config": None}


def _calibration(exp, volts, pans, tilts, *, unit_angles, out_dir, fixed=None):
    from bionav.polcompass import UnitCalibration, calibrate_from_rotation

    nominal = UnitCalibration.nominal(unit_angles)
    how = exp.calibration
    if fixed is not None:  # sensor.calibration=FILE (or a replay of such a run) replaces experiment.calibration
        if fixed.get("kind") != "units" or not fixed.get("calibration"):
            raise UserError(f"The compass calibration {fixed.get('source')!r} is not a per-unit calibration of the "
                            "thesis compass; use the calibration.json of an experiment=pol_compass rotation run.")
        cal = UnitCalibration.from_dict(fixed["calibration"])
        if len(cal.unit_angles) != len(unit_angles):
            raise UserError(f"The compass calibration {fixed.get('source')} has {len(cal.unit_angles)} units, the "
                            f"compass {len(unit_angles)} (experiment.unit_angles_deg); use a calibration of this compass.")
        how = "sensor_file"
        if out_dir is not None:
            cal.save(out_dir / "calibration.json")
        return cal, how
    if how == "auto":
        how = "rotation" if np.all(np.abs(tilts) < 1e-12) else "nominal"
    if how == "nominal":
        cal = nominal
    elif how == "rotation":
        cal = calibrate_from_rotation(volts, pans, nominal=nominal)
    else:  # "file" (experiment.calibration's declared choices)
        if not exp.calibration_path:
            raise UserError("experiment.calibration=file needs experiment.calibration_path=<calibration.json of a rotation run>.")
        cal = UnitCalibration.load(exp.calibration_path, units=len(unit_angles))
    if out_dir is not None:
        cal.save(out_dir / "calibration.json")
    return cal, how


def _pan_grid(session: CompassSession, exp, step_deg: float):
    lo, hi, tlo, thi = session.pantilt.limits()
    rng = exp.pan_range_deg
    if rng is not None:
        lo, hi = max(lo, np.deg2rad(rng[0])), min(hi, np.deg2rad(rng[1]))
    step = np.deg2rad(step_deg)
    n = int(np.floor((hi - lo) / step + 1e-9)) + 1
    return lo + step * np.arange(n), (tlo, thi)


def _check_tilt(tilt: float, limits) -> None:
    if not limits[0] - 1e-12 <= tilt <= limits[1] + 1e-12:
        raise UserError(
            f"tilt {np.degrees(tilt):.1f} deg is outside the pan-tilt unit's range "
            f"[{np.degrees(limits[0]):.1f}, {np.degrees(limits[1]):.1f}] deg; change experiment.tilt_deg / the scan's tilts_deg."
        )


def _scan(session: CompassSession, poses, samples: int, *, desc: str | None, with_reference: bool = False):
    """Visit poses ``[(pan, tilt), ...]``, take ``samples`` readings at each; all recorded.

    ``desc=None`` draws no progress bar.
    """
    pans, tilts, readings, refs, index = [], [], [], [], []
    visit = poses if desc is None else session.progress(poses, desc=desc, total=len(poses))
    for k, (pan, tilt) in enumerate(visit):
        state = session.move(pan, tilt)
        for _ in range(samples):
            readings.append(session.read())
            if with_reference:
                refs.append(session.read_reference())
            pans.append(state["pan"])
            tilts.append(state["tilt"])
            index.append(k)
    return np.asarray(pans), np.asarray(tilts), readings, refs, np.asarray(index)


# ---------------------------------------------------------------------------
# modes
# ---------------------------------------------------------------------------
def rotation_mode(session: CompassSession, exp, *, unit_angles, plots=None, out_dir=None, filter_test=False) -> dict:
    """``rotation`` and ``filter_test``: turn the compass through the pan range."""
    from bionav.experiments.pol_compass import plots as plots_mod
    from bionav.polcompass import CompassOptics, EvectorPredictor, counts_to_volts, heading_errors

    tilt = 0.0 if filter_test else np.deg2rad(exp.tilt_deg)
    pans_cmd, tilt_limits = _pan_grid(session, exp, exp.step_deg)
    _check_tilt(tilt, tilt_limits)
    pans, tilts, readings, _, index = _scan(
        session, [(p, tilt) for p in pans_cmd], exp.samples_per_step, desc="filter test" if filter_test else "rotation"
    )
    counts = counts_of(readings)
    volts = counts_to_volts(counts)
    cal, how = _calibration(exp, volts, pans, tilts, unit_angles=unit_angles, out_dir=out_dir,
                            fixed=session.fixed_calibration)
    angle, degree, x = evector_from_compass_counts(counts, cal, solver=exp.solver)
    predictor = EvectorPredictor(sky_model(exp.sky, session.sun), CompassOptics(unit_angles=tuple(cal.unit_angles)))
    heading, resolved = pose_headings(
        angle, x, tilts, sun=session.sun, predictor=predictor, unit_angles=cal.unit_angles, margin=exp.ambiguity_margin
    )
    axial = bool(filter_test or not np.all(resolved))
    errors = heading_errors(heading, pans, axial=axial)
    metrics = summarize(errors, axial=axial, n=len(readings))
    metrics.update(
        resolved_fraction=float(np.mean(resolved)),
        heading_offset_deg=float(np.degrees(errors.offset)),
        mean_degree=float(np.mean(degree)),
        calibration=how,
    )
    if plots is not None:
        steps = np.unique(index)
        mean_v = np.stack([volts[index == k].mean(axis=0) for k in steps])
        step_pan = np.array([pans[index == k][0] for k in steps])
        if filter_test:
            plots_mod.plot_unit_voltages(plots / "fig4_2_unit_voltages.png", np.degrees(-step_pan), mean_v,
                                         xlabel="filter angle relative to the compass (deg, CCW)")
        else:
            plots_mod.plot_unit_voltages(plots / "unit_voltages.png", np.degrees(step_pan), mean_v, xlabel="pan (deg)")
        plots_mod.plot_rotation(plots / "heading_vs_pan.png", pans, heading - errors.offset, errors.errors, axial=axial)
    return metrics


def vs_em_mode(session: CompassSession, exp, *, unit_angles, plots=None, out_dir=None) -> dict:
    """``vs_em_compass``: the polarized-light compass against the TCM2 (figs. 4.4, 4.5)."""
    from bionav.experiments.pol_compass import plots as plots_mod
    from bionav.geometry import compass_to_azimuth
    from bionav.polcompass import counts_to_volts, heading_errors, zenith_heading

    lo, hi, tlo, thi = session.pantilt.limits()
    rng = exp.pan_range_deg
    if rng is not None:
        lo, hi = max(lo, np.deg2rad(rng[0])), min(hi, np.deg2rad(rng[1]))
    positions = np.linspace(lo, hi, exp.vs_em.positions)
    pans, tilts, readings, refs, index = _scan(
        session, [(p, 0.0) for p in positions], exp.vs_em.samples, desc="vs TCM2", with_reference=True
    )
    counts = counts_of(readings)
    cal, how = _calibration(exp, counts_to_volts(counts), pans, tilts, unit_angles=unit_angles, out_dir=out_dir,
                            fixed=session.fixed_calibration)
    angle, _, _ = evector_from_compass_counts(counts, cal, solver=exp.solver)
    pol = np.asarray(zenith_heading(angle, sun_azimuth=session.sun.azimuth))
    tcm2 = np.asarray(compass_to_azimuth(np.deg2rad([r["heading_deg"] for r in refs])))
    errors = heading_errors(pol, tcm2, axial=True)
    metrics = summarize(errors, axial=True, n=len(readings))
    # Averaged per position (fig. 4.4): circular means (axial for the polarized-light compass).
    steps = np.unique(index)
    pol_avg = np.array([np.angle(np.mean(np.exp(2j * pol[index == k]))) / 2 for k in steps])
    tcm2_avg = np.array([np.angle(np.mean(np.exp(1j * tcm2[index == k]))) for k in steps])
    avg_errors = heading_errors(pol_avg, tcm2_avg, axial=True)
    metrics.update(
        heading_offset_deg=float(np.degrees(errors.offset)),
        averaged_rmse_deg=avg_errors.rmse_deg,
        n_positions=int(len(steps)),
        calibration=how,
    )
    if plots is not None:
        plots_mod.plot_vs_em(plots / "fig4_4_averaged.png", pol_avg - avg_errors.offset, tcm2_avg, averaged=True)
        plots_mod.plot_vs_em(plots / "fig4_5_raw.png", pol - errors.offset, tcm2, averaged=False)
    return metrics


def _scan_poses(session: CompassSession, node, *, pan_step_deg: float):
    lo, hi, tlo, thi = session.pantilt.limits()
    step = np.deg2rad(pan_step_deg)
    pans = lo + step * np.arange(int(np.floor((hi - lo) / step + 1e-9)) + 1)
    tilts = np.deg2rad(np.asarray(node.tilts_deg, float))
    for t in tilts:
        _check_tilt(t, (tlo, thi))
    return [(p, t) for t in tilts for p in pans]


def evector_scan_mode(session: CompassSession, exp, *, unit_angles, plots=None, out_dir=None) -> dict:
    """``evector_scan``: a pan/tilt grid over the sky (fig. 4.6) against the sky model."""
    from bionav.experiments.pol_compass import plots as plots_mod
    from bionav.geometry import wrap_axial
    from bionav.polcompass import CompassOptics, EvectorPredictor, fit_scan_heading

    poses = _scan_poses(session, exp.scan, pan_step_deg=exp.scan.pan_step_deg)
    cal = _rotation_calibration(session, exp, unit_angles=unit_angles, out_dir=out_dir)
    pans, tilts, readings, _, index = _scan(session, poses, exp.scan.samples, desc="e-vector scan")
    angle, degree, _ = evector_from_compass_counts(counts_of(readings), cal, solver=exp.solver)
    predictor = EvectorPredictor(sky_model(exp.sky, session.sun), CompassOptics(unit_angles=tuple(cal.unit_angles)))
    fit = fit_scan_heading(angle, degree, pans, tilts, predictor=predictor, min_degree=exp.min_degree)
    model_angle, model_degree = predictor.at(fit.heading + pans, tilts)
    residual = wrap_axial(angle - model_angle)
    rmse = float(np.degrees(np.sqrt(np.mean(residual**2))))
    metrics = {
        "heading_rmse_deg": rmse,
        "heading_mae_deg": float(np.degrees(np.mean(np.abs(residual)))),
        "n_samples": len(readings),
        "axial": True,
        "fitted_heading_deg": float(np.degrees(fit.heading)),
        "resolved_fraction": float(fit.resolved),
        "mean_degree": float(np.mean(degree)),
    }
    if session.true_mount_heading is not None:  # simulated (or a replay of a simulated session)
        from bionav.geometry import wrap_angle

        metrics["fitted_heading_error_deg"] = float(np.degrees(wrap_angle(fit.heading - session.true_mount_heading)))
    if plots is not None:
        steps = np.unique(index)
        first = np.array([np.flatnonzero(index == k)[0] for k in steps])
        mean_angle = np.array([np.angle(np.mean(np.exp(2j * angle[index == k]))) / 2 for k in steps])
        mean_degree = np.array([degree[index == k].mean() for k in steps])
        plots_mod.plot_evector_field(
            plots / "fig4_6_evector_field.png",
            pans[first],
            tilts[first],
            mean_angle,
            mean_degree,
            model_angle[first],
            model_degree[first],
        )
    return metrics


def _rotation_calibration(session: CompassSession, exp, *, unit_angles, out_dir):
    """Calibrate the units from one zenith rotation (one reading per pan step, recorded) before a scan.

    ``experiment.calibration``: ``auto``/``rotation`` rotate, ``nominal`` and
    ``file`` do not.
    """
    from bionav.polcompass import UnitCalibration, counts_to_volts

    how = exp.calibration
    if session.fixed_calibration is not None:
        return _calibration(exp, None, None, None, unit_angles=unit_angles, out_dir=out_dir,
                            fixed=session.fixed_calibration)[0]
    if how == "nominal":
        return UnitCalibration.nominal(unit_angles)
    if how == "file":
        return _calibration(exp, None, None, None, unit_angles=unit_angles, out_dir=out_dir)[0]
    pans_cmd, _ = _pan_grid(session, exp, exp.step_deg)
    pans, tilts, readings, _, _ = _scan(session, [(p, 0.0) for p in pans_cmd], 1, desc=None)
    return _calibration(exp, counts_to_volts(counts_of(readings)), pans, tilts, unit_angles=unit_angles, out_dir=out_dir)[0]


def partial_sky_mode(session: CompassSession, exp, *, unit_angles, rng_scene, plots=None, out_dir=None) -> dict:
    """``partial_sky`` (thesis 9.1): heading error against clear-sky fraction and sun elevation."""
    from bionav.experiments.pol_compass import plots as plots_mod
    from bionav.geometry import wrap_angle, wrap_axial
    from bionav.light import SunPosition
    from bionav.polcompass import CompassOptics, EvectorPredictor, fit_scan_heading, zenith_heading

    if session.scene is None:
        raise UserError(
            "mode=partial_sky is a simulation experiment: use sensor=polcompass_sim pantilt=sim "
            "(or sensor=replay pantilt=replay with the log of such a run)."
        )
    node = exp.partial
    poses = _scan_poses(session, node, pan_step_deg=node.pan_step_deg)
    session.scene.source = sky_model(exp.sky, session.sun)  # calibrate under the configured (clear) sky
    cal = _rotation_calibration(session, exp, unit_angles=unit_angles, out_dir=out_dir)
    optics = CompassOptics(unit_angles=tuple(cal.unit_angles))
    rows = []
    conditions = [(e, c) for e in node.sun_elevations_deg for c in node.cloud_covers]
    trials = node.trials
    for elevation_deg, cover in session.progress(conditions, desc="partial sky", total=len(conditions)):
        sun = SunPosition(np.deg2rad(exp.sky.sun_azimuth_deg), np.deg2rad(elevation_deg))
        predictor = EvectorPredictor(sky_model(exp.sky, sun), optics)
        for trial in range(trials):
            clouds = cloud_field(exp.sky, rng_scene, cover=cover)
            session.scene.source = sky_model(exp.sky, sun, clouds=clouds)
            session.scene.mount_heading = float(rng_scene.uniform(-np.pi, np.pi))
            clear = 1.0 if clouds is None else clouds.clear_fraction()
            pans, tilts, readings, _, _ = _scan(session, poses, node.samples, desc=None)
            angle, degree, _ = evector_from_compass_counts(counts_of(readings), cal, solver=exp.solver)
            fit = fit_scan_heading(angle, degree, pans, tilts, predictor=predictor, min_degree=exp.min_degree)
            zen = np.abs(tilts) < 1e-12
            zen_heading = zenith_heading(angle[zen], sun_azimuth=sun.azimuth) - pans[zen]
            zen_err = np.abs(wrap_axial(zen_heading - session.scene.mount_heading))
            rows.append(
                {
                    "sun_elevation_deg": elevation_deg,
                    "cloud_cover": cover,
                    "clear_fraction": clear,
                    "trial": trial,
                    "mount_heading_deg": float(np.degrees(session.scene.mount_heading)),
                    "scan_error_deg": float(np.degrees(abs(wrap_angle(fit.heading - session.scene.mount_heading))))
                    if np.isfinite(fit.heading)
                    else float("nan"),
                    "scan_resolved": bool(fit.resolved),
                    "scan_points_used": int(fit.n_used),
                    "zenith_error_deg": float(np.degrees(np.sqrt(np.mean(zen_err**2)))) if zen.any() else float("nan"),
                }
            )
    errs = np.array([r["scan_error_deg"] for r in rows])
    failed = ~np.isfinite(errs)
    errs_f = np.where(failed, 180.0, errs)  # no usable patch at all: count as a half-turn error
    metrics = {
        "heading_rmse_deg": float(np.sqrt(np.mean(errs_f**2))),
        "heading_mae_deg": float(np.mean(errs_f)),
        "n_samples": len(rows),
        "axial": False,
        "resolved_fraction": float(np.mean([r["scan_resolved"] for r in rows])),
        "zenith_rmse_deg": float(np.sqrt(np.nanmean(np.array([r["zenith_error_deg"] for r in rows]) ** 2))),
    }
    if out_dir is not None:
        header = list(rows[0])
        write_csv_atomic(out_dir / "partial_sky.csv", header, ([r.get(c, "") for c in header] for r in rows))
    if plots is not None:
        plots_mod.plot_partial_sky(plots / "partial_sky.png", rows)
    return metrics


