"""Which calibration each session of ``experiment=pol_recordings`` is decoded through (``recordings.calibration``).

``auto`` self-calibrates the daylight sessions on their stitched yaw (:func:`bionav.polcompass.sessions.self_calibrate`),
writes ``calibration.json`` learned on all days (with its transfer rule and what it was learned on,
:mod:`bionav.polcompass.transfer`) and decodes each day through the calibration of the *other* days, applied in
each condition as that calibration's own transfer rule (learned on those other days only) says. A file is loaded
once and applied as its transfer rule says (a file without one: every part, as before). ``none``: none.
``recordings.calibration_conditions`` limits every rule; sessions whose condition is ``unknown`` are never
calibrated.
"""

from __future__ import annotations

import logging
from dataclasses import replace

log = logging.getLogger(__name__)


def _not_applied(rc, period):
    """Why no calibration is applied to ``period`` whatever the rule (a label), or None."""
    if period == "unknown":
        return "none (condition unknown: the path names neither canopy nor tod)"
    return None if period in rc.calibration_conditions else f"none ({period} not in recordings.calibration_conditions)"


def applied(rc, cal, transfer, period: str, label: str):
    """``(calibration or None, parts applied, label)`` for a session of ``period``."""
    if cal is None:
        return None, (), label
    skip = _not_applied(rc, period)
    if skip:
        return None, (), skip
    if transfer is None:
        return cal, tuple(rc.calibration_parts), label
    parts = tuple(p for p in transfer.for_condition(period) if p in rc.calibration_parts)
    if not parts:
        return None, (), f"{label}: none for {period} (no evidence on its days that a part helps there)"
    return replace(cal, mount_tilt=transfer.mount_tilt.get(period)), parts, f"{label}: {'+'.join(parts)}"


def _auto(prepared, rc, ctx, decoder, decoder_name: str):
    from bionav.polcompass.sessions import self_calibrate
    from bionav.polcompass.transfer import CalibrationLearner, learned_on, save_pol_calibration

    estimates = self_calibrate(prepared, rc, progress=ctx.progress)
    learner = CalibrationLearner(prepared, rc, estimates, decoder)
    days = sorted({d.session.day for d in prepared})
    evidence = rc.calibration_transfer == "evidence"
    if estimates:
        cal = learner.calibration(days, rc.calibration_parts)
        save_pol_calibration(ctx.dir / "calibration.json", cal, learner.transfer(days) if evidence else None,
                         learned_on(prepared, estimates, rc, decoder_name, days))
    cache = {}

    def for_day(day, period):
        if day not in cache:
            train = [d for d in days if d != day]
            label = "auto (other days)"
            if estimates and not any(d in train for d, _e in estimates.values()):
                log.warning("only one day of daylight sessions: day %s is decoded with its own self-calibration", day)
                train, label = days, "auto (same day)"
            if not estimates:
                cache[day] = (None, None, "none (no daylight session to calibrate from)")
            else:
                cache[day] = (learner.calibration(train, rc.calibration_parts),
                              learner.transfer(train) if evidence else None, label)
        return applied(rc, *cache[day][:2], period, cache[day][2])

    return for_day


def calibration_for(prepared, rc, ctx, decoder, decoder_name: str):
    """``calibration(day, period) -> (ArrayCalibration or None, parts, label)`` for ``recordings.calibration``."""
    if rc.calibration == "auto":
        return _auto(prepared, rc, ctx, decoder, decoder_name)
    if rc.calibration == "none":
        return lambda day, period: (None, (), "none")
    from bionav.polcompass.transfer import load_pol_calibration

    cal, transfer, _learned = load_pol_calibration(rc.calibration)
    if rc.calibration_transfer == "all" or transfer is None:
        transfer = None
        if "tilt" in rc.calibration_parts and cal.mount_tilt is None:
            log.warning("recordings.calibration_parts has tilt but %s holds no mount tilt; none is applied",
                        rc.calibration)
    label = f"file {rc.calibration}"
    return lambda day, period: applied(rc, cal, transfer, period, label)
