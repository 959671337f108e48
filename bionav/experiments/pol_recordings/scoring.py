"""Scoring of ``experiment=pol_recordings``: every decoder on every session under both named rules.

Every error is ``wrap(heading - yaw - c)`` (:mod:`bionav.polcompass.references`). Two rules are always
reported, each named in every output:

* ``logged`` -- the logged yaw with one offset per session: the rule by which Gkanias et al. (2023,
  doi:10.1038/s44172-023-00132-w) scored the published decoders (their analysis aligns the IMU yaw once
  per session and scores every rotation against it), so the one to set beside their numbers;
* ``stitched`` -- the logged yaw repaired at its odometry restarts from the counts alone, one offset per
  session: what the compass itself gets wrong, without the logger's unlogged turns.

The default-named keys (``heading_mae_deg``, ``<condition>_mae_deg``, ``sessions.csv`` ``mae_deg``) follow
``recordings.reference`` (default ``session``, i.e. ``logged``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from bionav.polcompass.recordings_config import CONDITIONS
from bionav.polcompass.references import RULES, reference_errors
from bionav.polcompass.sessions import SessionData, decode_session

#: the groups of every table, in order; ``unknown``: sessions whose path names no condition
GROUPS = CONDITIONS + ("unknown",)
#: what each named rule is, for ``metrics.json`` and ``summary.md``
RULE_TEXT = {
    "logged": "logged yaw, one offset per session: the published rule (Gkanias et al. 2023), comparable with "
              "their numbers",
    "stitched": "logged yaw repaired at its odometry restarts from the counts alone, one offset per session: "
                "bionav's rule, not comparable with published numbers",
    "yaw_run": "logged yaw, one offset per run between its restarts (a diagnostic)",
    "rotation": "logged yaw, one offset per rotation file (a lower bound)",
}
SESSION_TOPIC = "/pol_recordings/session"
ROTATION_TOPIC = "/pol_recordings/rotation"


def rule_name(reference: str) -> str:
    """The outputs' name of a ``recordings.reference`` (``session`` is the ``logged`` rule)."""
    return {"session": "logged"}.get(reference, reference)


def scored_rules(reference: str) -> list[str]:
    """The rules a run reports: ``logged``, ``stitched``, and the chosen reference's if it is another."""
    rules = list(RULES)
    return rules + ([rule_name(reference)] if rule_name(reference) not in rules else [])


def _reference_of(rule: str) -> str:
    return RULES.get(rule, rule)


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


class Tally:
    """Rows, errors (radians) and flags gathered over the sessions: per rule, decoder and condition, and of the chosen
    decoder (``default``: the rule of ``recordings.reference``)."""

    def __init__(self, names, reference: str):
        self.names = list(names)
        self.default = rule_name(reference)
        self.rules = scored_rules(reference)
        self.errors = {r: {n: {g: [] for g in GROUPS} for n in self.names} for r in self.rules}
        self.chosen_res = []
        self.res_by_group, self.valid_by_group = {g: [] for g in GROUPS}, {g: [] for g in GROUPS}
        self.sim_err = {g: [] for g in GROUPS}
        self.per_session_plot, self.decode_times, self.session_rows, self.fault_rows = [], [], [], []
        self.n_rotations = 0

    def chosen_errors(self, rule: str, chosen: str, group=None) -> list:
        """The chosen decoder's error arrays under ``rule`` (all groups, or one)."""
        by = self.errors[rule][chosen]
        return list(by[group]) if group else [e for g in GROUPS for e in by[g]]


def _record_rotations(ctx, data: SessionData, name: str, heading, err, resolved) -> None:
    session = data.session
    for r in range(len(session.rotations)):
        sel = data.rotation_index == r
        ctx.log.write(ROTATION_TOPIC, {
            "session": session.name, "file": session.rotations[r].path.name, "decoder": name,
            "yaw": data.yaw[sel].tolist(),
            "heading": [float(v) if np.isfinite(v) else None for v in heading[sel]],
            "error": err[sel].tolist(), "resolved": resolved[sel].tolist(),
            "yaw_shift": float(data.yaw_shift[sel][0]),
            "sun_azimuth": float(np.mean(data.sun_azimuth[sel]))},
            schema_name="bionav.PolRecordingRotation")


def _rule_columns(rule: str, err, decoded, c) -> dict:
    stats = error_stats(err)
    return {f"mae_deg_{rule}": stats["mae_deg"], f"rmse_deg_{rule}": stats["rmse_deg"],
            f"within_5_{rule}": stats["within_5"], f"mae_decoded_deg_{rule}": error_stats(err[decoded])["mae_deg"],
            f"offset_deg_{rule}": float(np.degrees(c))}


def score_session(ctx, exp, tally: Tally, data: SessionData, sim_runs, decoders, chosen, base, tilt=None) -> None:
    """Decode one (calibrated) session with every decoder and add its rows and errors (every rule) to ``tally``."""
    for name, dec in decoders.items():
        heading, resolved, seconds = decode_session(dec, data, tilt)
        decoded = np.isfinite(heading)
        by_rule = {r: reference_errors(heading, data, _reference_of(r)) for r in tally.rules}
        err, c = by_rule[tally.default]
        row = {**base, "decoder": name, **error_stats(err),
               "decoded_fraction": float(np.mean(decoded)),
               "mae_decoded_deg": error_stats(err[decoded])["mae_deg"],
               "resolved_fraction": float(np.mean(resolved)),
               "offset_deg": float(np.degrees(c)),
               "decode_ms": 1000.0 * seconds}
        for rule in RULES:
            row.update(_rule_columns(rule, by_rule[rule][0], decoded, by_rule[rule][1]))
        for rule, (e, _c) in by_rule.items():
            tally.errors[rule][name][data.period].append(e)
        if name == chosen:
            tally.decode_times.append(seconds)
            tally.chosen_res.append(resolved)
            tally.res_by_group[data.period].append(resolved)
            tally.valid_by_group[data.period].append(decoded)
            tally.per_session_plot.append((data.session, data, {r: e for r, (e, _c) in by_rule.items()}, decoded))
            if sim_runs:  # every repeat its own simulated device (gains) and cloud draw, errors pooled; no restarts
                s_err = np.concatenate([reference_errors(decode_session(dec, sd)[0], sd, "session")[0]
                                        for sd in sim_runs])
                s_stats = error_stats(s_err)
                row["sim_mae_deg"] = s_stats["mae_deg"]
                row["sim_rmse_deg"] = s_stats["rmse_deg"]
                tally.sim_err[data.period].append(s_err)
            if exp.record_samples:
                _record_rotations(ctx, data, name, heading, err, resolved)
        tally.session_rows.append(row)
        ctx.log.write(SESSION_TOPIC, row, schema_name="bionav.PolRecordingSession")


def pooled_rows(tally: Tally) -> list[dict]:
    """One row per rule, decoder and group (and ``all``)."""
    rows = []
    for rule in tally.rules:
        for name in tally.names:
            by = tally.errors[rule][name]
            for g in GROUPS:
                if by[g]:
                    rows.append({"rule": rule, "decoder": name, "group": g, **error_stats(np.concatenate(by[g]))})
            all_e = [e for g in GROUPS for e in by[g]]
            if all_e:
                rows.append({"rule": rule, "decoder": name, "group": "all", **error_stats(np.concatenate(all_e))})
    return rows


def _group_stats(group: str, errors, decoded, suffix: str) -> dict:
    stats = error_stats(errors)
    return {f"{group}_mae_deg{suffix}": stats["mae_deg"], f"{group}_rmse_deg{suffix}": stats["rmse_deg"],
            f"{group}_mae_valid_deg{suffix}": error_stats(errors[decoded])["mae_deg"]}


def _condition_metrics(tally: Tally, chosen) -> dict:
    """``<condition>_*`` keys of the chosen decoder: default-named (``recordings.reference``) and per named rule."""
    metrics = {}
    for g in GROUPS:
        if not tally.valid_by_group[g]:
            continue
        ok = np.concatenate(tally.valid_by_group[g])
        metrics[f"{g}_resolved_fraction"] = float(np.mean(np.concatenate(tally.res_by_group[g])))
        # the decoder's per-sample valid flag: a heading was given (enough units above the noise floor);
        # <group>_mae_deg counts the others as 90 degrees, <group>_mae_valid_deg leaves them out
        metrics[f"{g}_valid_fraction"] = float(np.mean(ok))
        e = np.concatenate(tally.chosen_errors(tally.default, chosen, g))
        metrics.update(_group_stats(g, e, ok, ""))
        # the eq. 4.6 pair chosen right: the error is less than a quarter turn (undecoded samples count as wrong)
        metrics[f"{g}_correct_side_fraction"] = float(np.mean(np.abs(e) < np.pi / 2.0 - 1e-9))
        for rule in RULES:
            metrics.update(_group_stats(g, np.concatenate(tally.chosen_errors(rule, chosen, g)), ok, f"_{rule}"))
    return metrics


def _sim_metrics(exp, tally: Tally) -> dict:
    """The simulation's parameters and ``sim_<condition>_mae_deg``."""
    metrics = {"sim_repeats": exp.sim_repeats}
    for key in ("sim_gain_sigma", "sim_angle_sigma_deg", "sim_noise", "sim_canopy_cover", "sim_max_degree",
                "sim_view_sigma", "sim_view_shared", "sim_gain_shared", "sim_tilt_sigma_deg", "sim_azimuth_sigma_deg"):
        metrics[key] = getattr(exp, key)
    for g in GROUPS:
        if tally.sim_err[g]:
            metrics[f"sim_{g}_mae_deg"] = error_stats(np.concatenate(tally.sim_err[g]))["mae_deg"]
    return metrics


def run_metrics(rc, exp, tally: Tally, chosen, n_bad: int) -> dict[str, Any]:
    """``metrics.json`` of the run: the contract's keys under ``recordings.reference``, then each named rule."""
    stats = error_stats(np.concatenate(tally.chosen_errors(tally.default, chosen)))
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
        "rule": tally.default,
        "rules": {r: RULE_TEXT[r] for r in tally.rules},
        "sun": rc.sun,
        "rotation_period_s": rc.rotation_period_s,
    }
    for rule in RULES:
        s = error_stats(np.concatenate(tally.chosen_errors(rule, chosen)))
        metrics[f"heading_mae_deg_{rule}"] = s["mae_deg"]
        metrics[f"heading_rmse_deg_{rule}"] = s["rmse_deg"]
    metrics.update(_condition_metrics(tally, chosen))
    if exp.simulate:
        metrics.update(_sim_metrics(exp, tally))
    return metrics
