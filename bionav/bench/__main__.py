"""Time homing methods per home vector: ``python -m bionav.bench [--method ...]``.

The input is a pair of ray-cast panoramas of the pillar test room
(:mod:`bionav.testing.pillar_scene`) at a known displacement and rotation.
Per-image work (:meth:`prepare`) is timed separately and excluded from the
per-pair time (it is amortised over all pairs in a grid run); the first calls
(numba compilation, caches) are excluded as warm-up. Reported: the median and
the minimum wall time of one home vector over ``--repeat`` calls.
"""

from __future__ import annotations

import argparse
import sys
import time
from functools import partial

import numpy as np

METHODS = ("minwarping", "warping2d", "warping1d", "hiss")


def _plugin(name: str, size, steps: int, compass: bool, geometry):
    from bionav.plugins.homing.hiss import HissHoming
    from bionav.plugins.homing.warping import MinWarping, Warping1D, Warping2D

    if name == "hiss":
        return HissHoming(HissHoming.Config(), geometry=geometry), "-"
    if name == "warping1d":
        cfg = Warping1D.Config(image_size=list(size))
        return Warping1D(cfg, geometry=geometry), f"{cfg.n_alpha}x{cfg.n_psi}x{cfg.n_rho}"
    cls = MinWarping if name == "minwarping" else Warping2D
    cfg = cls.Config(image_size=list(size), n_alpha=steps, n_psi=steps, compass_acceleration=compass)
    label = f"{steps}x{steps}" + (f"x{cfg.n_rho}" if name == "warping2d" else "")
    return cls(cfg, geometry=geometry), label


def _time(fn, repeat: int, warmup: int = 2):
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return 1e3 * float(np.median(times)), 1e3 * float(np.min(times))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m bionav.bench",
        description="Time homing methods (ms per home vector, per-image work excluded, warm-up excluded).",
    )
    parser.add_argument("--method", choices=METHODS + ("all",), default="minwarping",
                        help="method to time (default: minwarping)")
    parser.add_argument("--size", type=int, nargs=2, default=[288, 50], metavar=("W", "H"),
                        help="image size of the warping methods (default: 288 50)")
    parser.add_argument("--steps", type=int, default=96,
                        help="alpha and psi steps of min-warping and 2D-warping (default: 96)")
    parser.add_argument("--compass-fraction", type=float, default=0.25,
                        help="fraction of psi searched with compass acceleration (default: 0.25)")
    parser.add_argument("--repeat", type=int, default=30, help="timed calls per row (default: 30)")
    parser.add_argument("--threads", type=int, default=None,
                        help="numba threads (default: numba's default, all cores)")
    parser.add_argument("--render-size", type=int, nargs=2, default=[576, 100], metavar=("W", "H"),
                        help="size of the rendered input panoramas (default: 576 100)")
    args = parser.parse_args(argv)

    import numba

    from bionav.testing.pillar_scene import render_pillar_panorama

    if args.threads is not None:
        if not (1 <= args.threads <= numba.config.NUMBA_NUM_THREADS):
            parser.error(f"--threads must lie in 1..{numba.config.NUMBA_NUM_THREADS}")
        numba.set_num_threads(args.threads)
    rw, rh = args.render_size
    snap, geometry = render_pillar_panorama((0.0, 0.0), width=rw, height=rh, supersample=2)
    cur, _ = render_pillar_panorama((0.5, 0.3), heading=0.5, width=rw, height=rh, supersample=2)

    rows = []
    methods = METHODS if args.method == "all" else (args.method,)
    for name in methods:
        variants = [False, True] if name in ("minwarping", "warping2d") else [False]
        for compass in variants:
            method, steps = _plugin(name, args.size, args.steps, compass, geometry)
            if compass:
                method.config.compass_fraction = args.compass_fraction
            prep_ms, _ = _time(partial(method.prepare, snap), max(3, args.repeat // 5), warmup=1)
            s, c = method.prepare(snap), method.prepare(cur)
            med, best = _time(partial(method.home_vector, s, c), args.repeat)
            size = "x".join(map(str, args.size)) if name != "hiss" else "x".join(map(str, args.render_size))
            rows.append((name, size, steps, f"{args.compass_fraction:g}" if compass else "no",
                         f"{med:.2f}", f"{best:.2f}", f"{prep_ms:.2f}", str(numba.get_num_threads())))
    header = ("method", "image", "steps", "compass acc.", "ms/home vector (median)", "ms (min)",
              "prepare ms/image", "threads")
    widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(header)]
    line = lambda cells: "| " + " | ".join(c.ljust(w) for c, w in zip(cells, widths)) + " |"  # noqa: E731
    print(line(header))
    print("|" + "|".join("-" * (w + 2) for w in widths) + "|")
    for r in rows:
        print(line(r))
    return 0


if __name__ == "__main__":
    sys.exit(main())
