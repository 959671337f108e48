"""``experiment=pol_recordings``: the polarized-light compass on real skies.

Decodes field recordings of a real POL-OP compass (Gkanias et al. 2023,
doi:10.1038/s44172-023-00132-w: eight units tilted 45 degrees, four
photodiodes each, on a robot turning in place; loader and format in
:mod:`bionav.polcompass.recordings`) with every decoder plugin
(``bionav.decoders``) and scores every sample::

    error = wrap(decoded heading - yaw - c)

with ``c`` one constant per session, the circular mean of ``decoded - yaw``
over the session's rotations (the IMU yaw has an arbitrary zero, the sun moves
little within a session). By default (``recordings.reference=stitched``) the
runs of the logged yaw between odometry restarts are first turned into one
reference by the counts' sky ring; ``session`` takes the logged yaw as it is,
``yaw_run`` fits one ``c`` per run, ``rotation`` one per rotation file
(:func:`bionav.polcompass.recordings.yaw_restarts`). Each sample is decoded only from the units read at
that moment; units found faulty from the session's counts are dropped with
``recordings.exclude_units=auto``.

Outputs: ``metrics.json`` (the chosen ``decoder=``: ``heading_mae_deg``,
``heading_rmse_deg``, ``n_samples``, ``n_rotations``,
``ambiguity_resolved_fraction``, plus pooled values per condition),
``sessions.csv`` (one row per session and decoder), ``pooled.csv``,
``faults.csv``, ``summary.md``, ``run.mcap`` and ``plots/``. With
``experiment.simulate=true`` each session is also simulated in bionav's sky
model (same array, time, place, yaw samples, excluded units; clouds for canopy
sessions) and decoded the same way: the sim-to-real gap.
"""

from __future__ import annotations

import logging
from pathlib import Path
from typing import Any

import numpy as np

from bionav.errors import UserError
from bionav.experiments.pol_recordings.config import PolRecordingsConfig
from bionav.polcompass.recordings_config import CONDITIONS, RecordingsConfig
from bionav.polcompass.sessions import (
    SessionData,
    calibrated,
    decode_session,
    leave_one_day_out,
    mount_tilt,
    prepared_sessions,
    self_calibrate,
    session_errors,
    simulate_session,
    yaw_runs,
)

log = logging.getLogger(__name__)

GROUPS = CONDITIONS  # the session conditions, in the tables' order
SESSION_TOPIC = "/pol_recordings/session"
ROTATION_TOPIC = "/pol_recordings/rotation"
FAULT_TOPIC = "/pol_recordings/faults"


# ---------------------------------------------------------------------------
# scoring
# ---------------------------------------------------------------------------
def error_stats(errors_rad) -> dict:
    """MAE, RMSE (degrees) and fractions within 5 and 15 degrees."""
    e = np.abs(np.degrees(np.asarray(errors_rad, float)))
    if e.size == 0:
        return {"n_samples": 0, "mae_deg": None, "rmse_deg": None, "within_5": None, "within_15": None}
    return {
        "n_samples": int(e.size),
        "mae_deg": float(np.mean(e)),
        "rmse_deg": float(np.sqrt(np.mean(e**2))),
        "within_5": float(np.mean(e <= 5.0)),
        "within_15": float(np.mean(e <= 15.0)),
    }


# ---------------------------------------------------------------------------
# files
# ---------------------------------------------------------------------------
def _cell(value):
    if value is None:
        return ""
    return f"{value:.4g}" if isinstance(value, float) else value


def _write_csv(path: Path, rows: list[dict]) -> None:
    """Rows of dicts through the one CSV writer (columns in order of first appearance; empty file for no rows)."""
    from bionav.files import write_atomic, write_csv_atomic

    if not rows:
        write_atomic(path, "")
        return
    keys = list(rows[0])
    for r in rows[1:]:
        keys += [k for k in r if k not in keys]
    write_csv_atomic(path, keys, ([_cell(r.get(k)) for k in keys] for r in rows))


def _fmt(v, digits=1):
    return "-" if v is None else f"{v:.{digits}f}"


def summary_markdown(session_rows, pooled_rows, decoders, *, reference: str) -> str:
    """Per-session and pooled MAE tables (degrees) as Markdown; ``reference``: ``recordings.reference``."""
    lines = [f"Heading reference: `recordings.reference={reference}`", "",
             "Per session: MAE / RMSE (degrees) per decoder", ""]
    lines.append("| session | condition | sun elev. (deg) | " + " | ".join(decoders) + " | sim (" + decoders[0] + ") |")
    lines.append("|" + "---|" * (4 + len(decoders)))
    by = {}
    for r in session_rows:
        by.setdefault(r["session"], {})[r["decoder"]] = r
    for name, rows in by.items():
        first = next(iter(rows.values()))
        cells = [f"{_fmt(rows[d]['mae_deg'])} / {_fmt(rows[d]['rmse_deg'])}" if d in rows else "-" for d in decoders]
        sim = rows.get(decoders[0], {}).get("sim_mae_deg")
        lines.append(f"| {first['day']} {first['time_of_day']} | {first['period']} | {_fmt(first['sun_elevation_deg'])} | "
                     + " | ".join(cells) + f" | {_fmt(sim)} |")
    lines += ["", "Pooled: MAE / RMSE (degrees), fraction within 5 degrees", ""]
    lines.append("| decoder | " + " | ".join(GROUPS) + " |")
    lines.append("|" + "---|" * (1 + len(GROUPS)))
    pooled = {(r["decoder"], r["group"]): r for r in pooled_rows}
    for d in decoders:
        cells = []
        for g in GROUPS:
            r = pooled.get((d, g))
            cells.append("-" if r is None or r["mae_deg"] is None else
                         f"{_fmt(r['mae_deg'])} / {_fmt(r['rmse_deg'])} ({r['within_5']:.2f})")
        lines.append(f"| {d} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------------------
# run
# ---------------------------------------------------------------------------
def _decoder(ctx, cfg, name):
    node = cfg.decoder if cfg.get("decoder") is not None and cfg.decoder.get("name") == name else {"name": name}
    return ctx.plugin("decoder", node)


def _decoders(cfg, ctx, exp) -> tuple[str, dict]:
    """The chosen decoder's name and every decoder to score, chosen first (after the run's config checks)."""
    if cfg.get("decoder") is None or not cfg.decoder.get("name"):
        raise UserError(
            "experiment=pol_recordings needs a decoder; choose one with decoder=<name> (python -m bionav.plugins lists them)."
        )
    chosen = str(cfg.decoder.name)
    names = [chosen] + [n for n in exp.compare if n != chosen]
    return chosen, {n: _decoder(ctx, cfg, n) for n in names}


def _calibration_for(prepared, rc, ctx, decoder):
    """``calibration(day, period) -> (ArrayCalibration or None, label)`` for ``recordings.calibration``.

    ``auto`` self-calibrates the daylight sessions, writes ``calibration.json`` pooled over all days and
    gives each day the calibration of the others (with ``tilt`` in ``calibration_parts`` also the mount tilt
    learned on the others with ``decoder``) in the conditions of ``recordings.calibration_conditions``; a file
    is loaded once and applied in those conditions; ``none`` gives none.
    """
    from dataclasses import replace

    how = rc.calibration
    tilt = "tilt" in rc.calibration_parts
    if how == "auto":
        estimates = self_calibrate(prepared, rc, progress=ctx.progress)
        if estimates:
            from bionav.polcompass.array_calibration import combine_sessions

            pooled = combine_sessions([e for _d, e in estimates.values()], sorted(estimates))
            if tilt:
                pooled = replace(pooled, mount_tilt=mount_tilt(prepared, rc, pooled, decoder))
            pooled.save(ctx.dir / "calibration.json")
        cache = {}

        def for_day(day, period):
            if day not in cache:
                cal, label = leave_one_day_out(estimates, day)
                if tilt and cal is not None:
                    cal = replace(cal, mount_tilt=mount_tilt(prepared, rc, cal, decoder, leave_out_day=day))
                    label += " + mount tilt"
                cache[day] = (cal, label)
            cal, label = cache[day]
            skip = _not_applied(rc, period) if cal is not None else None
            return (None, skip) if skip else (cal, label)

        return for_day
    fixed = None
    if how != "none":
        from bionav.polcompass.array_calibration import ArrayCalibration

        fixed = ArrayCalibration.load(how)
        if tilt and fixed.mount_tilt is None:
            log.warning("recordings.calibration_parts has tilt but %s holds no mount tilt; none is applied", how)
    label = "none" if fixed is None else f"file {how}"

    def for_file(day, period):
        skip = _not_applied(rc, period) if fixed is not None else None
        return (None, skip) if skip else (fixed, label)

    return for_file


def _not_applied(rc, period):
    """Why the calibration is not applied to ``period`` (a label), or None where it is."""
    return None if period in rc.calibration_conditions else f"none ({period} not in recordings.calibration_conditions)"


class _Tally:
    """Rows, errors (radians) and flags gathered over the sessions: per decoder and condition, and of the chosen decoder."""

    def __init__(self, names):
        self.names = list(names)
        self.errors = {n: {g: [] for g in GROUPS} for n in self.names}
        self.chosen_err, self.chosen_res = [], []
        self.res_by_group, self.valid_by_group = {g: [] for g in GROUPS}, {g: [] for g in GROUPS}
        self.sim_err, self.real_err = {g: [] for g in GROUPS}, {g: [] for g in GROUPS}
        self.per_session_plot, self.decode_times, self.session_rows, self.fault_rows = [], [], [], []
        self.n_rotations = 0


def _reference_runs(data: SessionData) -> tuple[int, str]:
    """Runs a session is scored over (with one offset each, or stitched into one) and the stitching shifts (degrees)."""
    if data.reference_run is not None:
        return int(np.unique(data.reference_run).size), ""
    if data.yaw_shift is None:
        return 1, ""
    runs = yaw_runs(data)
    shifts = [float(np.degrees(data.yaw_shift[runs == r][0])) for r in range(int(runs.max()) + 1)]
    return len(shifts), " ".join(f"{v:.2f}" for v in shifts)


def _session_base(data: SessionData, cal_label: str) -> dict:
    session = data.session
    runs, shifts = _reference_runs(data)
    return {
        "session": session.name,
        "day": session.day,
        "time_of_day": session.time_of_day,
        "condition": session.condition,
        "period": data.period,
        "sun_elevation_deg": float(np.degrees(data.sun.elevation)),
        "sun_azimuth_deg": float(np.degrees(data.sun.azimuth)),
        "n_rotations": len(session.rotations),
        "reference_runs": runs,
        "yaw_run_shifts_deg": shifts,
        "excluded_units": " ".join(str(u) for u in data.excluded),
        "calibration": cal_label,
    }


def _record_rotations(ctx, data: SessionData, name: str, heading, err, resolved) -> None:
    session = data.session
    for r in range(len(session.rotations)):
        sel = data.rotation_index == r
        ctx.log.write(ROTATION_TOPIC, {
            "session": session.name, "file": session.rotations[r].path.name, "decoder": name,
            "yaw": data.yaw[sel].tolist(),
            "heading": [float(v) if np.isfinite(v) else None for v in heading[sel]],
            "error": err[sel].tolist(), "resolved": resolved[sel].tolist(),
            "yaw_shift": 0.0 if data.yaw_shift is None else float(data.yaw_shift[sel][0])},
            schema_name="bionav.PolRecordingRotation")


def _score_session(ctx, exp, tally: _Tally, data: SessionData, sim_runs, decoders, chosen, base, tilt=None) -> None:
    """Decode one (calibrated) session with every decoder and add its rows and errors to ``tally``."""
    for name, dec in decoders.items():
        heading, resolved, seconds = decode_session(dec, data, tilt)
        err, c = session_errors(heading, data.yaw, runs=data.reference_run)
        decoded = np.isfinite(heading)
        row = {**base, "decoder": name, **error_stats(err),
               "decoded_fraction": float(np.mean(decoded)),
               "mae_decoded_deg": error_stats(err[decoded])["mae_deg"],
               "resolved_fraction": float(np.mean(resolved)),
               "offset_deg": float(np.degrees(c)),
               "decode_ms": 1000.0 * seconds}
        tally.errors[name][data.period].append(err)
        if name == chosen:
            tally.decode_times.append(seconds)
            tally.chosen_err.append(err)
            tally.chosen_res.append(resolved)
            tally.res_by_group[data.period].append(resolved)
            tally.valid_by_group[data.period].append(decoded)
            tally.real_err[data.period].append(err)
            tally.per_session_plot.append((data.session, data, err, decoded))
            if sim_runs:  # every repeat its own simulated device (gains) and cloud draw, errors pooled
                s_err = np.concatenate([session_errors(decode_session(dec, sd)[0], sd.yaw, runs=sd.reference_run)[0]
                                        for sd in sim_runs])
                s_stats = error_stats(s_err)
                row["sim_mae_deg"] = s_stats["mae_deg"]
                row["sim_rmse_deg"] = s_stats["rmse_deg"]
                tally.sim_err[data.period].append(s_err)
            if exp.record_samples:
                _record_rotations(ctx, data, name, heading, err, resolved)
        tally.session_rows.append(row)
        ctx.log.write(SESSION_TOPIC, row, schema_name="bionav.PolRecordingSession")


def _score_all(ctx, exp, rc, prepared, calibration_for, decoders, chosen) -> _Tally:
    tally = _Tally(list(decoders))
    rng_sim = ctx.rng.spawn(1)[0]
    for data in ctx.progress(prepared, desc="sessions", total=len(prepared)):
        session = data.session
        cal, cal_label = calibration_for(session.day, data.period)
        tally.n_rotations += len(session.rotations)
        for f in data.faults:
            tally.fault_rows.append({"session": session.name, **f.to_dict()})
        ctx.log.write(FAULT_TOPIC, {"session": session.name, "excluded": data.excluded,
                                    "units": [f.to_dict() for f in data.faults]}, schema_name="bionav.PolOpFaults")
        sim_runs = [simulate_session(data, exp, rng_sim) for _ in range(exp.sim_repeats)] if exp.simulate else []
        data = calibrated(data, cal, rc.calibration_parts, rc.calibration_solver)
        tilt = cal.mount_tilt if cal is not None and "tilt" in rc.calibration_parts else None
        _score_session(ctx, exp, tally, data, sim_runs, decoders, chosen, _session_base(data, cal_label), tilt)
    return tally


def _pooled_rows(tally: _Tally) -> list[dict]:
    rows = []
    for name in tally.names:
        for g in GROUPS:
            if tally.errors[name][g]:
                rows.append({"decoder": name, "group": g, **error_stats(np.concatenate(tally.errors[name][g]))})
        all_e = [e for g in GROUPS for e in tally.errors[name][g]]
        rows.append({"decoder": name, "group": "all", **error_stats(np.concatenate(all_e))})
    return rows


def _write_outputs(ctx, exp, tally: _Tally, pooled_rows, chosen, reference: str) -> None:
    from bionav.experiments.pol_recordings import plots

    _write_csv(ctx.dir / "sessions.csv", tally.session_rows)
    _write_csv(ctx.dir / "pooled.csv", pooled_rows)
    _write_csv(ctx.dir / "faults.csv", tally.fault_rows)
    (ctx.dir / "summary.md").write_text(summary_markdown(tally.session_rows, pooled_rows, tally.names,
                                                                 reference=reference))
    plot_dir = ctx.plots
    plots.error_vs_time_of_day(plot_dir / "error_vs_time_of_day.png", tally.session_rows, tally.names)
    plots.session_distributions(plot_dir / "session_errors.png", tally.per_session_plot, chosen)
    first = tally.per_session_plot[0]
    plots.raw_rotation(plot_dir / "raw_unit_responses.png", first[0], first[1])
    plots.clear_vs_canopy(plot_dir / "clear_vs_canopy.png", tally.real_err, chosen)
    plots.yaw_reference(plot_dir / "yaw_reference.png", tally.per_session_plot, chosen, reference)
    if exp.simulate:
        plots.sim_vs_real(plot_dir / "sim_vs_real.png", tally.real_err, tally.sim_err, chosen)


def _condition_metrics(tally: _Tally, pooled_rows, chosen) -> dict:
    """``<condition>_*`` keys of the chosen decoder."""
    metrics = {}
    for g in GROUPS:
        if tally.real_err[g]:
            e = np.concatenate(tally.real_err[g])
            metrics[f"{g}_resolved_fraction"] = float(np.mean(np.concatenate(tally.res_by_group[g])))
            # the eq. 4.6 pair chosen right: the error is less than a quarter turn (undecoded samples count as wrong)
            metrics[f"{g}_correct_side_fraction"] = float(np.mean(np.abs(e) < np.pi / 2.0 - 1e-9))
            # the decoder's per-sample valid flag: a heading was given (enough units above the noise floor);
            # <group>_mae_deg counts the others as 90 degrees, <group>_mae_valid_deg leaves them out
            ok = np.concatenate(tally.valid_by_group[g])
            metrics[f"{g}_valid_fraction"] = float(np.mean(ok))
            metrics[f"{g}_mae_valid_deg"] = error_stats(e[ok])["mae_deg"]
    for r in pooled_rows:
        if r["decoder"] == chosen and r["group"] in GROUPS:
            metrics[f"{r['group']}_mae_deg"] = r["mae_deg"]
            metrics[f"{r['group']}_rmse_deg"] = r["rmse_deg"]
    return metrics


def _sim_metrics(exp, tally: _Tally) -> dict:
    """The simulation's parameters and ``sim_<condition>_mae_deg``."""
    metrics = {"sim_repeats": exp.sim_repeats}
    for key in ("sim_gain_sigma", "sim_angle_sigma_deg", "sim_noise", "sim_canopy_cover", "sim_max_degree",
                "sim_view_sigma", "sim_view_shared", "sim_gain_shared", "sim_tilt_sigma_deg", "sim_azimuth_sigma_deg"):
        metrics[key] = getattr(exp, key)
    for g in GROUPS:
        if tally.sim_err[g]:
            metrics[f"sim_{g}_mae_deg"] = error_stats(np.concatenate(tally.sim_err[g]))["mae_deg"]
    return metrics


def _metrics(rc, exp, tally: _Tally, pooled_rows, chosen, n_bad: int) -> dict[str, Any]:
    stats = error_stats(np.concatenate(tally.chosen_err))
    how = rc.calibration
    metrics: dict[str, Any] = {
        "decoder": chosen,
        "heading_mae_deg": stats["mae_deg"],
        "heading_rmse_deg": stats["rmse_deg"],
        "n_samples": stats["n_samples"],
        "n_rotations": int(tally.n_rotations),
        "n_sessions": len({r["session"] for r in tally.session_rows}),
        "ambiguity_resolved_fraction": float(np.mean(np.concatenate(tally.chosen_res))),
        "decode_ms_per_session_median": float(1000.0 * np.median(tally.decode_times)),
        "decode_ms_per_session_max": float(1000.0 * max(tally.decode_times)),
        "n_bad_files": n_bad,
        "calibration": how if how in ("auto", "none") else "file",
        "calibration_parts": rc.calibration_parts,
        "reference": rc.reference,
    }
    metrics.update(_condition_metrics(tally, pooled_rows, chosen))
    if exp.simulate:
        metrics.update(_sim_metrics(exp, tally))
    return metrics


def run(exp: PolRecordingsConfig, ctx) -> dict[str, Any]:
    """Run ``experiment=pol_recordings`` with the checked ``exp`` and ``recordings`` node (``ctx.nodes``)."""
    cfg = ctx.cfg
    rc = ctx.nodes.get("recordings") or RecordingsConfig()
    if not rc.path:
        raise UserError(
            "experiment=pol_recordings needs recordings.path=DIR, a folder of POL-OP recordings "
            "(e.g. recordings.path=../shared/data/celestial-compass)."
        )
    chosen, decoders = _decoders(cfg, ctx, exp)
    if rc.calibration not in ("none", "auto"):  # a bad calibration file is refused before the recordings load
        from bionav.polcompass.array_calibration import ArrayCalibration

        ArrayCalibration.load(rc.calibration)
    prepared, bad_files = prepared_sessions(rc, progress=ctx.progress)
    calibration_for = _calibration_for(prepared, rc, ctx, decoders[chosen])
    tally = _score_all(ctx, exp, rc, prepared, calibration_for, decoders, chosen)
    if not tally.session_rows:
        raise UserError(" ".join(m for _p, m in bad_files) or f"No usable recordings in {rc.path}.")
    pooled_rows = _pooled_rows(tally)
    _write_outputs(ctx, exp, tally, pooled_rows, chosen, rc.reference)
    metrics = _metrics(rc, exp, tally, pooled_rows, chosen, len(bad_files))
    if bad_files and rc.on_bad_file == "error":
        listed = " ".join(m for _p, m in bad_files[:3])
        more = f" ({len(bad_files) - 3} more, see the log)" if len(bad_files) > 3 else ""
        raise UserError(
            f"{len(bad_files)} recording file(s) or session(s) are unusable; the other {tally.n_rotations} rotations were "
            f"scored and sessions.csv is written. {listed}{more} Set recordings.on_bad_file=skip to only warn."
        )
    return metrics
