"""Does a deviation curve help on held-out days? ``python -m bionav.bench.decoders.deviation --recordings DIR``.

Compass swinging on the real-sky recordings (:mod:`bionav.polcompass.deviation`): every session of
``DIR`` is read and checked as ``experiment=pol_recordings`` does (default ``recordings.*``, no array
calibration, or ``--calibration auto``: each day through the self-calibration of the other days) and
decoded with ``--decoder`` (default ``sky_fit``); for each day a Fourier deviation
curve in the solar azimuth of the device frame (``--harmonics``; ``--form tilt``: times the tangent of
the sun's elevation, a mount tilt to first order) is learned from the clear-sky
daylight sessions of the *other* days (errors against the logged yaw, one constant per session,
per-session fits pooled by the median) and removed from that day's headings. Printed: one JSON
object per condition (``tod_daylight``, ``tod_dusk``, ``canopy``) with the pooled MAE in degrees
before and after (undecoded samples count 90 degrees, as in ``experiment=pol_recordings``), then
one with the curve learned from all days without array calibration (``D(phi)`` coefficients in degrees,
``[a1, b1, a2, ...]``).
"""

from __future__ import annotations

import json

import numpy as np

from bionav.polcompass.recordings_config import CONDITIONS as GROUPS


def _prepared(path: str):
    from bionav.polcompass import sessions as ps
    from bionav.polcompass.recordings_config import recordings_config

    rc = recordings_config({"path": path})
    return rc, ps.prepared_sessions(rc)[0]


def _decoded(prepared, dec, calibration=None):
    """``(session data, heading, sun azimuth in the device frame, errors)`` per session, through ``calibration``."""
    from bionav.polcompass import sessions as ps
    from bionav.polcompass.decoders import heading_from_sun

    out = []
    for d in prepared:
        d = ps.calibrated(d, calibration, ["angles"])
        est = dec.decode(d.evectors, d.valid, array=d.array, sun_elevation=float(d.sun.elevation))
        heading = heading_from_sun(est.azimuth, d.sun.azimuth)
        out.append((d, heading, est.azimuth, ps.session_errors(heading, d.yaw)[0]))
    return out


def _scale(d, form: str) -> float:
    return float(np.tan(d.sun.elevation)) if form == "tilt" else 1.0


def _learn(decoded, n_harmonics: int, form: str, *, leave_out_day=None):
    from bionav.polcompass.deviation import deviation_from_errors, pooled_deviation

    return pooled_deviation([deviation_from_errors(phi, err, n_harmonics=n_harmonics, scale=_scale(d, form))
                             for d, _h, phi, err in decoded
                             if d.period == "tod_daylight" and d.session.day != leave_out_day])


def main(argv=None) -> int:
    from bionav import registry
    from bionav.bench._cli import BenchParser, bounded_int
    from bionav.polcompass import sessions as ps
    from bionav.polcompass.deviation import corrected_heading

    parser = BenchParser(prog="python -m bionav.bench.decoders.deviation",
                         description="Held-out effect of a deviation curve on the real-sky recordings.")
    parser.add_argument("--recordings", required=True, help="folder of POL-OP recordings (e.g. ../shared/data/celestial-compass)")
    parser.add_argument("--decoder", default="sky_fit", help="decoder plugin (default: sky_fit)")
    parser.add_argument("--harmonics", type=int, default=2, help="harmonics of the curve (default: 2)")
    parser.add_argument("--calibration", choices=("none", "auto"), default="none",
                        help="array calibration as recordings.calibration: none, or auto (angles, leave one day out)")
    parser.add_argument("--form", choices=("plain", "tilt"), default="plain",
                        help="plain: D(phi); tilt: tan(sun elevation) D(phi), a mount tilt (default: plain)")
    args = parser.parse_args(argv)
    bounded_int(parser, "--harmonics", args.harmonics, 1, 8)
    rc, prepared = _prepared(args.recordings)
    cls = registry.load_plugin("decoder", args.decoder)
    dec = cls(cls.Config())
    estimates = ps.self_calibrate(prepared, rc) if args.calibration == "auto" else {}
    days = sorted({d.session.day for d in prepared})
    before = {g: [] for g in GROUPS}
    after = {g: [] for g in GROUPS}
    uncalibrated = _decoded(prepared, dec)
    for day in days:  # the day's array calibration (auto: of the other days) on every session, the curve of the others
        decoded = _decoded(prepared, dec, ps.leave_one_day_out(estimates, day)[0]) if estimates else uncalibrated
        curve = _learn(decoded, args.harmonics, args.form, leave_out_day=day)
        for d, heading, phi, err in decoded:
            if d.session.day == day:
                before[d.period].append(err)
                fixed = corrected_heading(heading, phi, curve, scale=_scale(d, args.form))
                after[d.period].append(ps.session_errors(fixed, d.yaw)[0])
    for g in GROUPS:
        if before[g]:
            print(json.dumps({"condition": g, "decoder": args.decoder, "harmonics": args.harmonics, "form": args.form,
                              "calibration": args.calibration,
                              "n_samples": int(sum(e.size for e in before[g])),
                              "mae_deg": round(float(np.degrees(np.mean(np.abs(np.concatenate(before[g]))))), 3),
                              "mae_deviation_removed_deg": round(
                                  float(np.degrees(np.mean(np.abs(np.concatenate(after[g]))))), 3)}))
    every = _learn(uncalibrated, args.harmonics, args.form)
    print(json.dumps({"curve_all_days_deg": None if every is None else np.round(np.degrees(every), 3).tolist(),
                      "days": days}))
    return 0


if __name__ == "__main__":
    from bionav.bench._cli import run

    run(main, "python -m bionav.bench.decoders.deviation")
