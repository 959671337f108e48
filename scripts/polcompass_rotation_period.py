"""Measure the recordings' rotation period ``T`` from the sky's brightness alone (``recordings.rotation_period_s``).

The rotation files hold no time stamps (:mod:`bionav.polcompass.timebase`). Around sunrise and sunset the sky
brightens or darkens steadily, so each rotation's brightness is a smooth function of its time. Each rotation's
brightness is the median natural log count of its lit, unsaturated photodiodes. Its time is placed at
``folder time + (r + 1/2) T``. For each candidate ``T`` a polynomial in time (``--degree``, default 3) is fitted
per day through all rotations of that day's low-sun sessions (sun below ``--max-elevation-deg`` at the start,
median count above ``--min-counts``), and the residuals are pooled. The ``T`` with the smallest pooled residual is
the measurement. No heading, decoder or yaw is used. Prints one JSON object per candidate and the best ``T`` per
day and pooled. Usage::

    python scripts/polcompass_rotation_period.py --recordings ../shared/data/celestial-compass
"""

from __future__ import annotations

import argparse
import json

import numpy as np


def _brightness(rotation, saturation: float) -> float:
    c = np.asarray(rotation.counts, float)
    lit = c[(c >= 1.0) & (c < saturation)]
    return float(np.median(np.log(lit))) if lit.size else float("nan")


def _low_sun_sessions(sessions, args):
    from bionav.light import sun_position

    out = []
    for s in sessions:
        when = s.time_utc(args.utc_offset_hours)
        if when is None or s.condition != "tod":
            continue
        sun = sun_position(when, latitude_deg=args.latitude_deg, longitude_deg=args.longitude_deg)
        b = np.array([_brightness(r, args.saturation_counts) for r in s.rotations])
        lit = np.median(np.concatenate([np.ravel(r.counts) for r in s.rotations])) >= args.min_counts
        if np.degrees(sun.elevation) < args.max_elevation_deg and lit and np.all(np.isfinite(b)):
            out.append((s.day, when.timestamp(), b))
    return out


def _residual(chosen, period: float, degree: int) -> dict:
    """Per day, ``(sum of squared residuals, number of rotations)`` of the polynomial fit."""
    out = {}
    for day in sorted({d for d, _t, _b in chosen}):
        t = np.concatenate([t0 + (np.arange(b.size) + 0.5) * period for d, t0, b in chosen if d == day])
        b = np.concatenate([b for d, _t, b in chosen if d == day])
        if b.size <= degree + 1:
            continue
        x = (t - t.mean()) / 3600.0
        coef = np.polyfit(x, b, degree)
        out[day] = (float(np.sum((np.polyval(coef, x) - b) ** 2)), int(b.size))
    return out


def main(argv=None) -> int:
    from bionav.polcompass.recordings import load_sessions

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--recordings", required=True, help="the celestial-compass folder (tod_data/, canopy_data/)")
    parser.add_argument("--degree", type=int, default=3, help="polynomial degree in time, per day")
    parser.add_argument("--max-elevation-deg", type=float, default=20.0, help="low-sun sessions: sun below this")
    parser.add_argument("--min-counts", type=float, default=5.0, help="lit sessions: median count at least this")
    parser.add_argument("--saturation-counts", type=float, default=11000.0)
    parser.add_argument("--utc-offset-hours", type=float, default=2.0)
    parser.add_argument("--latitude-deg", type=float, default=39.2)
    parser.add_argument("--longitude-deg", type=float, default=9.1)
    args = parser.parse_args(argv)
    sessions, _bad = load_sessions(args.recordings)
    chosen = _low_sun_sessions(sessions, args)
    if not chosen:
        parser.error("no lit low-sun time-of-day sessions found")
    periods = np.arange(30.0, 180.1, 6.0)
    table = {float(p): _residual(chosen, float(p), args.degree) for p in periods}
    for p, per_day in table.items():
        print(json.dumps({"period_s": p, "rms_by_day": {d: round(np.sqrt(s / n), 5) for d, (s, n) in per_day.items()},
                          "rms": round(float(np.sqrt(sum(s for s, _n in per_day.values())
                                                     / sum(n for _s, n in per_day.values()))), 5)}))
    days = sorted({d for per in table.values() for d in per})
    best = {d: min(table, key=lambda p: table[p][d][0] / table[p][d][1] if d in table[p] else np.inf) for d in days}
    pooled = min(table, key=lambda p: sum(s for s, _n in table[p].values()))
    print(json.dumps({"sessions": len(chosen), "best_period_s_by_day": best, "best_period_s": pooled}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
