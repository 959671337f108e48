"""Time the POL-OP decoders on one session: ``python -m bionav.bench.decoders [--decoder NAME]``.

The input is a simulated session of the recorded 8-unit fan
(:meth:`bionav.polcompass.array.PolArray.fan8`): ``--rotations`` x
``--samples`` readings under the model sky (sun 35 degrees high), one unit
dropped as on the real sensor. Timed: one ``decode`` of the whole session
(the e-vectors are computed once per session, like in
``experiment=pol_recordings``), the first call (tables, caches) excluded as
warm-up. Printed: one JSON object per decoder with ``decoder``, ``n_samples``,
``cpu_ms_per_session`` and ``wall_ms_per_session`` (medians over
``--repeat`` calls) and ``evectors_ms`` (counts to e-vectors, wall).
"""

from __future__ import annotations

import json
import time

import numpy as np

DECODERS = ("sky_fit", "two_unit", "sol", "four_zeros", "eigenvector", "mean_vector")
#: readings per session at most (rotations x samples; about 0.3 kB of memory each)
MAX_READINGS = 200_000


def _session(rotations: int, samples: int, seed: int):
    from bionav.light import SkyModel, SunPosition
    from bionav.polcompass.array import PolArray, counts_from_stokes, evectors_from_counts, stokes_from_sky

    rng = np.random.default_rng(seed)
    array = PolArray.fan8()
    yaw = np.tile(np.linspace(-np.pi, np.pi, samples, endpoint=False), rotations)
    sky = SkyModel(SunPosition(0.3, np.deg2rad(35.0)), max_degree=0.5)
    inten, q, u = stokes_from_sky(sky, array, yaw)
    counts = counts_from_stokes(3000.0 * inten, q, u, array) * (1.0 + 0.01 * rng.standard_normal((yaw.size, 8, 4)))
    t0 = time.perf_counter()
    ev = evectors_from_counts(counts, array)
    ev_ms = 1e3 * (time.perf_counter() - t0)
    valid = np.ones(ev.angle.shape, bool)
    valid[:, 7] = False
    return array, ev, valid, ev_ms


def main(argv=None) -> int:
    from bionav import registry
    from bionav.bench._cli import BenchParser, bounded_int

    parser = BenchParser(prog="python -m bionav.bench.decoders",
                                     description="Time POL-OP decoders per session (CPU and wall ms, warm-up excluded).")
    parser.add_argument("--decoder", choices=DECODERS + ("all",), default="all", help="decoder to time (default: all)")
    parser.add_argument("--rotations", type=int, default=12, help="rotations per session (default: 12)")
    parser.add_argument("--samples", type=int, default=412, help="samples per rotation (default: 412)")
    parser.add_argument("--repeat", type=int, default=5, help="timed calls (default: 5)")
    args = parser.parse_args(argv)
    bounded_int(parser, "--rotations", args.rotations, 1, 1000)
    bounded_int(parser, "--samples", args.samples, 8, MAX_READINGS)
    bounded_int(parser, "--repeat", args.repeat, 1, 1000)
    if args.rotations * args.samples > MAX_READINGS:
        parser.error(f"--rotations {args.rotations} x --samples {args.samples} = {args.rotations * args.samples} "
                     f"readings is more than {MAX_READINGS} per session; lower --samples or --rotations "
                     f"(e.g. --samples {max(8, MAX_READINGS // args.rotations)})")
    array, ev, valid, ev_ms = _session(args.rotations, args.samples, 0)
    names = DECODERS if args.decoder == "all" else (args.decoder,)
    for name in names:
        cls = registry.load_plugin("decoder", name)
        dec = cls(cls.Config())
        dec.decode(ev, valid, array=array, sun_elevation=np.deg2rad(35.0))  # warm-up
        wall, cpu = [], []
        for _ in range(args.repeat):
            w0, c0 = time.perf_counter(), time.process_time()
            dec.decode(ev, valid, array=array, sun_elevation=np.deg2rad(35.0))
            wall.append(time.perf_counter() - w0)
            cpu.append(time.process_time() - c0)
        print(json.dumps({"decoder": name, "n_samples": int(ev.angle.shape[0]),
                          "cpu_ms_per_session": round(1e3 * float(np.median(cpu)), 2),
                          "wall_ms_per_session": round(1e3 * float(np.median(wall)), 2),
                          "evectors_ms": round(ev_ms, 2)}))
    return 0


if __name__ == "__main__":
    from bionav.bench._cli import run

    run(main, "python -m bionav.bench.decoders")
