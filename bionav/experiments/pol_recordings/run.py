"""``experiment=pol_recordings``: the polarized-light compass on real skies.

Decodes field recordings of a real POL-OP compass (Gkanias et al. 2023,
doi:10.1038/s44172-023-00132-w: eight units tilted 45 degrees, four
photodiodes each, on a robot turning in place; loader and format in
:mod:`bionav.polcompass.recordings`) with every decoder plugin
(``bionav.decoders``) and scores every sample::

    error = wrap(decoded heading - yaw - c)

with ``c`` one constant per session, the circular mean of ``decoded - yaw``
over the session's rotations (the IMU yaw has an arbitrary zero). Each sample is
decoded against the sun at its own time (``recordings.sun=sample``,
:mod:`bionav.polcompass.timebase`) and only from the units read at that moment;
units found faulty from the session's counts are dropped with
``recordings.exclude_units=auto``. Two rules are always reported, each named
(:mod:`bionav.experiments.pol_recordings.scoring`): ``logged`` (the logged yaw,
the published rule) and ``stitched`` (the logged yaw repaired at its odometry
restarts from the counts alone); the default-named values follow
``recordings.reference`` (default ``session``, the logged yaw).

Outputs: ``metrics.json`` (the chosen ``decoder=``: ``heading_mae_deg``,
``heading_rmse_deg``, ``n_samples``, ``n_rotations``,
``ambiguity_resolved_fraction``, the same per rule ``heading_mae_deg_logged``,
``heading_mae_deg_stitched``, ..., plus pooled values per condition),
``sessions.csv`` (one row per session and decoder), ``pooled.csv`` (per rule),
``faults.csv``, ``summary.md``, ``run.mcap`` and ``plots/``. With
``experiment.simulate=true`` each session is also simulated in bionav's sky
model (same array, times, place, yaw samples, excluded units; clouds for canopy
sessions) and decoded the same way: the sim-to-real gap.
"""

from __future__ import annotations

import logging
from typing import Any

import numpy as np

from bionav.errors import UserError
from bionav.experiments.pol_recordings.calibration import calibration_for
from bionav.experiments.pol_recordings.config import PolRecordingsConfig
from bionav.experiments.pol_recordings.outputs import write_outputs
from bionav.experiments.pol_recordings.scoring import Tally, pooled_rows, run_metrics, score_session
from bionav.polcompass.recordings_config import RecordingsConfig
from bionav.polcompass.references import yaw_runs
from bionav.polcompass.sessions import SessionData, calibrated, prepared_sessions, simulate_session

log = logging.getLogger(__name__)

FAULT_TOPIC = "/pol_recordings/faults"


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


def _reference_runs(data: SessionData) -> tuple[int, str]:
    """The runs of the logged yaw between its restarts and their stitching shifts (degrees)."""
    runs = yaw_runs(data.yaw, data.rotation_index)
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


def _score_all(ctx, exp, rc, prepared, calibration_of, decoders, chosen) -> Tally:
    tally = Tally(list(decoders), rc.reference)
    rng_sim = ctx.rng.spawn(1)[0]
    for data in ctx.progress(prepared, desc="sessions", total=len(prepared)):
        session = data.session
        cal, parts, cal_label = calibration_of(session.day, data.period)
        tally.n_rotations += len(session.rotations)
        for f in data.faults:
            tally.fault_rows.append({"session": session.name, **f.to_dict()})
        ctx.log.write(FAULT_TOPIC, {"session": session.name, "excluded": data.excluded,
                                    "units": [f.to_dict() for f in data.faults]}, schema_name="bionav.PolOpFaults")
        sim_runs = [simulate_session(data, exp, rng_sim) for _ in range(exp.sim_repeats)] if exp.simulate else []
        data = calibrated(data, cal, parts, rc.calibration_solver)
        tilt = cal.mount_tilt if cal is not None and "tilt" in parts else None
        score_session(ctx, exp, tally, data, sim_runs, decoders, chosen, _session_base(data, cal_label), tilt)
    return tally


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
        from bionav.polcompass.transfer import load_pol_calibration

        load_pol_calibration(rc.calibration)
    prepared, bad_files = prepared_sessions(rc, progress=ctx.progress)
    tally = _score_all(ctx, exp, rc, prepared, calibration_for(prepared, rc, ctx, decoders[chosen], chosen), decoders,
                       chosen)
    if not tally.session_rows:
        raise UserError(" ".join(m for _p, m in bad_files) or f"No usable recordings in {rc.path}.")
    pooled = pooled_rows(tally)
    write_outputs(ctx, exp, tally, pooled, chosen, rc.reference)
    metrics = run_metrics(rc, exp, tally, chosen, len(bad_files))
    if bad_files and rc.on_bad_file == "error":
        listed = " ".join(m for _p, m in bad_files[:3])
        more = f" ({len(bad_files) - 3} more, see the log)" if len(bad_files) > 3 else ""
        raise UserError(
            f"{len(bad_files)} recording file(s) or session(s) are unusable; the other {tally.n_rotations} rotations were "
            f"scored and sessions.csv is written. {listed}{more} Set recordings.on_bad_file=skip to only warn."
        )
    return metrics
