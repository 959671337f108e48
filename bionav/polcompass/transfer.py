"""What of a self-calibration transfers to which condition, decided on the days it was learned from.

A calibration learned on clear daylight rotations (:mod:`bionav.polcompass.array_calibration`, the mount
tilt of :func:`bionav.polcompass.sessions.mount_tilt`) may not help under other skies: on the recordings of
Gkanias et al. (2023, doi:10.1038/s44172-023-00132-w) the polarizer offsets lower the daylight error and
raise the canopy error. So every calibration carries a *transfer rule* per condition, learned on its own
training days only, by nested leave-one-day-out:

* for each training day ``d`` and each candidate set of parts ``S`` (the non-empty subsets of
  ``recordings.calibration_parts``), the calibration learned on the *other* training days with the parts
  ``S`` (the mount tilt learned through ``S``'s other parts) is applied to ``d``'s sessions of each
  condition, and their MAE (every sample, against the stitched yaw: the yaw the calibration repairs
  itself, whatever rule scores the run) is set beside the uncalibrated MAE of the same sessions;
* a condition gets the parts ``S`` only if ``S`` lowered the MAE on *every* training day that has sessions
  of that condition (at least one); of several such sets the one with the lowest mean MAE. A condition
  without such evidence -- none of its sessions among the training days, or no set that helped on each
  day -- is decoded uncalibrated, as are sessions whose condition is ``unknown``.

The rule is a sign test over days, not a tuned threshold: it needs no constant, and it can only keep a
condition at its uncalibrated error where the training days gave no evidence that a part helps there.
With one or two training days per condition it is weak evidence (docs/polcompass.md says how far it can
be trusted). The decision, the per-day evidence and what the calibration was learned on are written to
``calibration.json`` (additive keys ``transfer`` and ``learned_on``; files without them apply every part
wherever ``recordings.calibration_conditions`` allows, as before).
"""

from __future__ import annotations

import datetime as _dt
import itertools
import json
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from bionav.polcompass.recordings_config import CONDITIONS


@dataclass(frozen=True)
class Transfer:
    """Per condition, the calibration parts applied and the mount tilt that goes with them.

    Attributes
    ----------
    parts : dict
        Condition -> tuple of parts (``()``: decoded uncalibrated).
    mount_tilt : dict
        Condition -> ``(2,)`` radians (learned through that condition's other parts) or None.
    evidence : dict
        Condition -> ``{"days": [...], "none": [MAE per day], "<parts>": [MAE per day], ...}`` (degrees).
    """

    parts: dict
    mount_tilt: dict = field(default_factory=dict)
    evidence: dict = field(default_factory=dict)

    def for_condition(self, condition: str) -> tuple:
        return tuple(self.parts.get(condition, ()))

    def to_dict(self) -> dict:
        tilt = {c: None if t is None else np.degrees(t).round(4).tolist() for c, t in self.mount_tilt.items()}
        return {"rule": "nested leave-one-day-out on the training days: a condition gets a set of parts only if it "
                        "lowered the MAE (stitched yaw) on every training day with sessions of that condition",
                "conditions": {c: {"parts": list(self.parts.get(c, ())), "mount_tilt_deg": tilt.get(c)}
                               for c in CONDITIONS},
                "evidence_mae_deg": self.evidence}

    @classmethod
    def from_dict(cls, data: dict) -> "Transfer":
        conds = data.get("conditions", {})
        parts = {c: tuple(v.get("parts", ())) for c, v in conds.items()}
        tilt = {c: None if v.get("mount_tilt_deg") is None else np.deg2rad(np.asarray(v["mount_tilt_deg"], float))
                for c, v in conds.items()}
        return cls(parts, tilt, dict(data.get("evidence_mae_deg", {})))


def candidate_parts(parts) -> list[tuple]:
    """The non-empty subsets of ``parts`` (in their order), largest first."""
    parts = list(dict.fromkeys(parts))
    out = [s for n in range(len(parts), 0, -1) for s in itertools.combinations(parts, n)]
    return out


def _label(parts) -> str:
    return "+".join(parts) if parts else "none"


class CalibrationLearner:
    """Calibrations learned on sets of days and their transfer rules, with every decode cached.

    ``datas``: the prepared sessions; ``estimates``: :func:`bionav.polcompass.sessions.self_calibrate`'s
    per-session estimates; ``decoder``: the decoder plugin that judges (the run's chosen one).
    """

    def __init__(self, datas, rc, estimates, decoder):
        self.datas, self.rc, self.estimates, self.decoder = datas, rc, estimates, decoder
        self._cal, self._mae = {}, {}

    def calibration(self, days, parts):
        """The calibration pooled over ``days``' sessions, its mount tilt learned through ``parts`` (None: nothing
        to learn from)."""
        from bionav.polcompass.array_calibration import combine_sessions
        from bionav.polcompass.sessions import mount_tilt

        key = (frozenset(days), tuple(parts))
        if key not in self._cal:
            chosen = {n: e for n, (d, e) in self.estimates.items() if d in key[0]}
            cal = combine_sessions(list(chosen.values()), sorted(chosen)) if chosen else None
            if cal is not None and "tilt" in parts:
                cal = replace(cal, mount_tilt=mount_tilt(self.datas, self.rc, cal, self.decoder, days=key[0],
                                                         parts=parts))
            self._cal[key] = cal
        return self._cal[key]

    def _session_errors(self, data, days, parts):
        from bionav.polcompass.references import session_errors
        from bionav.polcompass.sessions import calibrated, decode_session

        key = (data.session.name, frozenset(days), tuple(parts))
        if key not in self._mae:
            cal = self.calibration(days, parts) if parts else None
            dc = calibrated(data, cal, parts, self.rc.calibration_solver)
            tilt = cal.mount_tilt if cal is not None and "tilt" in parts else None
            self._mae[key] = session_errors(decode_session(self.decoder, dc, tilt)[0], dc.stitched_yaw)[0]
        return self._mae[key]

    def _day_mae(self, day, condition, days, parts):
        errs = [self._session_errors(d, days, parts) for d in self.datas
                if d.session.day == day and d.period == condition]
        return float(np.degrees(np.mean(np.abs(np.concatenate(errs))))) if errs else None

    def transfer(self, days) -> Transfer:
        """The transfer rule learned on ``days`` by nested leave-one-day-out (module docstring)."""
        days = sorted(set(days))
        candidates = candidate_parts(self.rc.calibration_parts)
        evidence = {c: {"days": [], "none": [], **{_label(s): [] for s in candidates}} for c in CONDITIONS}
        for day in days:
            train = [d for d in days if d != day]
            if not any(d in train for d, _e in self.estimates.values()):
                continue  # nothing to learn from without this day
            for c in CONDITIONS:
                base = self._day_mae(day, c, (), ())
                if base is None:
                    continue
                evidence[c]["days"].append(day)
                evidence[c]["none"].append(round(base, 4))
                for s in candidates:
                    evidence[c][_label(s)].append(round(self._day_mae(day, c, train, s), 4))
        parts, tilt = {}, {}
        for c in CONDITIONS:
            ev = evidence[c]
            helped = [s for s in candidates if ev["days"] and all(m < b for m, b in zip(ev[_label(s)], ev["none"]))]
            best = min(helped, key=lambda s: np.mean(ev[_label(s)]), default=())
            parts[c] = best
            cal = self.calibration(days, best) if best else None
            tilt[c] = cal.mount_tilt if cal is not None and "tilt" in best else None
        return Transfer(parts, tilt, {c: v for c, v in evidence.items() if v["days"]})


def learned_on(datas, estimates, rc, decoder_name: str, days) -> dict:
    """What a calibration was learned on (``calibration.json`` key ``learned_on``)."""
    from bionav import __version__

    used = sorted(n for n, (d, _e) in estimates.items() if d in set(days))
    return {
        "days": sorted(set(days)),
        "sessions": used,
        "conditions": sorted({d.period for d in datas if d.session.name in used}),
        "evidence_conditions": sorted({d.period for d in datas if d.session.day in set(days)}),
        "recordings": str(rc.path),
        "decoder": decoder_name,
        "calibration_parts": list(rc.calibration_parts),
        "calibration_solver": rc.calibration_solver,
        "yaw": "stitched (the logged yaw repaired at its odometry restarts), against the sky of each session's "
               "first sample",
        "sun": rc.sun,
        "rotation_period_s": rc.rotation_period_s,
        "bionav_version": __version__,
        "written": _dt.datetime.now(_dt.timezone.utc).replace(microsecond=0).isoformat(),
    }


def save_pol_calibration(path, calibration, transfer: Transfer | None = None, provenance: dict | None = None) -> None:
    """Write ``calibration.json``: :meth:`ArrayCalibration.to_dict` plus the additive keys ``transfer`` and
    ``learned_on`` (schema ``bionav.pol_array_calibration/1`` unchanged; older readers ignore them)."""
    data = calibration.to_dict()
    if transfer is not None:
        data["transfer"] = transfer.to_dict()
    if provenance is not None:
        data["learned_on"] = provenance
    Path(path).write_text(json.dumps(data, indent=2))


def load_pol_calibration(path):
    """``(ArrayCalibration, Transfer or None, learned_on or None)`` from a calibration file."""
    from bionav.errors import UserError
    from bionav.files import user_path
    from bionav.polcompass.array_calibration import ArrayCalibration

    cal = ArrayCalibration.load(path)  # size-capped, every field checked: what follows reads a valid file again
    data = json.loads(user_path(path).read_text())
    transfer = None
    if isinstance(data.get("transfer"), dict):
        try:
            transfer = Transfer.from_dict(data["transfer"])
        except (TypeError, ValueError, AttributeError) as exc:
            raise UserError(f"The file {path} has a malformed 'transfer' entry ({exc}); recalibrate with "
                            "recordings.calibration=auto or delete the entry to apply every part.") from None
    return cal, transfer, data.get("learned_on")


__all__ = ["CalibrationLearner", "Transfer", "candidate_parts", "learned_on", "load_pol_calibration", "save_pol_calibration"]
