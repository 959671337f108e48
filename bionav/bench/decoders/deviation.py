"""Does a deviation curve help on held-out days? ``python -m bionav.bench.decoders.deviation --recordings DIR``.

Compass swinging on the real-sky recordings (:mod:`bionav.polcompass.deviation`): every session of
``DIR`` is read and checked as ``experiment=pol_recordings`` does (default ``recordings.*``, no array
calibration) and decoded with ``--decoder`` (default ``sky_fit``); for each day a Fourier deviation
curve in the solar azimuth of the device frame (``--harmonics``) is learned from the clear-sky
daylight sessions of the *other* days (errors against the logged yaw, one constant per session,
per-session fits pooled by the median) and removed from that day's headings. Printed: one JSON
object per condition (``tod_daylight``, ``tod_dusk``, ``canopy``) with the pooled MAE in degrees
before and after (undecoded samples count 90 degrees, as in ``experiment=pol_recordings``), then
one with the curve learned from all days (``D(phi)`` coefficients in degrees, ``[a1, b1, a2, ...]``).
"""

from __future__ import annotations

import json

import numpy as np

from bionav.experiments.pol_recordings import GROUPS


def _decoded(path: str, decoder: str):
    from omegaconf import OmegaConf

    from bionav import registry
    from bionav.experiments import pol_recordings as pr
    from bionav.polcompass.decoders import heading_from_sun

    rc = pr.recordings_config(OmegaConf.create({"recordings": {"path": path}}))
    prepared, _bad = pr._prepared_sessions(rc)
    cls = registry.load_plugin("decoder", decoder)
    dec = cls(cls.Config())
    out = []
    for d in prepared:
        est = dec.decode(d.evectors, d.valid, array=d.array, sun_elevation=float(d.sun.elevation))
        heading = heading_from_sun(est.azimuth, d.sun.azimuth)
        out.append((d, heading, est.azimuth, pr.session_errors(heading, d.yaw)[0]))
    return out


def _learn(decoded, n_harmonics: int, *, leave_out_day=None):
    from bionav.polcompass.deviation import deviation_from_errors, pooled_deviation

    return pooled_deviation([deviation_from_errors(phi, err, n_harmonics=n_harmonics)
                             for d, _h, phi, err in decoded
                             if d.period == "tod_daylight" and d.session.day != leave_out_day])


def main(argv=None) -> int:
    from bionav.bench._cli import BenchParser, bounded_int
    from bionav.experiments.pol_recordings import session_errors
    from bionav.polcompass.deviation import corrected_heading

    parser = BenchParser(prog="python -m bionav.bench.decoders.deviation",
                         description="Held-out effect of a deviation curve on the real-sky recordings.")
    parser.add_argument("--recordings", required=True, help="folder of POL-OP recordings (e.g. ../shared/data/celestial-compass)")
    parser.add_argument("--decoder", default="sky_fit", help="decoder plugin (default: sky_fit)")
    parser.add_argument("--harmonics", type=int, default=2, help="harmonics of the curve (default: 2)")
    args = parser.parse_args(argv)
    bounded_int(parser, "--harmonics", args.harmonics, 1, 8)
    decoded = _decoded(args.recordings, args.decoder)
    before = {g: [] for g in GROUPS}
    after = {g: [] for g in GROUPS}
    curves = {}
    for d, heading, phi, err in decoded:
        day = d.session.day
        if day not in curves:
            curves[day] = _learn(decoded, args.harmonics, leave_out_day=day)
        before[d.period].append(err)
        after[d.period].append(session_errors(corrected_heading(heading, phi, curves[day]), d.yaw)[0])
    for g in GROUPS:
        if before[g]:
            print(json.dumps({"condition": g, "decoder": args.decoder, "harmonics": args.harmonics,
                              "n_samples": int(sum(e.size for e in before[g])),
                              "mae_deg": round(float(np.degrees(np.mean(np.abs(np.concatenate(before[g]))))), 3),
                              "mae_deviation_removed_deg": round(
                                  float(np.degrees(np.mean(np.abs(np.concatenate(after[g]))))), 3)}))
    every = _learn(decoded, args.harmonics)
    print(json.dumps({"curve_all_days_deg": None if every is None else np.round(np.degrees(every), 3).tolist(),
                      "days": sorted(curves)}))
    return 0


if __name__ == "__main__":
    from bionav.bench._cli import run

    run(main, "python -m bionav.bench.decoders.deviation")
