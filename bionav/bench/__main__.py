"""Time homing methods per home vector: ``python -m bionav.bench [--method ...] [--json]``.

The input is a ray-cast panorama of the pillar test room
(:mod:`bionav.testing.pillar_scene`) as snapshot and three current views at
known displacements and rotations. Per-image work (:meth:`prepare`) is timed
separately and excluded from the per-pair time (it is amortised over all pairs
in a grid run); the first calls (numba compilation, caches) are excluded as
warm-up.

Every measurement runs ``--batch`` home vectors on ``--threads`` worker
threads (the kernels are single-threaded and release the GIL, as in the grid
runner), reads the process CPU time (all threads) and the wall time, and
divides by the number of home vectors. The variants are interleaved
(``--repeat`` rounds of one batch per variant) so that changing load on a
shared machine affects all alike; reported are the median and the minimum over
the rounds, and the 1-minute load average of the machine.

``--background-load N`` starts ``N`` busy processes for the duration of the
run (to check that parallel work is not slower than serial on a loaded
machine); they are stopped at the end.

``--grid DB`` times grid homing instead (the all-pairs runner of
``experiment=grid_homing``, :func:`bionav.evaluation.pairs.home_vector_matrix`)
on ``--grid-snapshots`` snapshots of database ``DB`` against all its cells,
with 1 worker and with ``--threads`` workers in alternate rounds (per-image
work done once beforehand and excluded); each line adds ``workers_speedup``,
the median over the rounds of (wall time with 1 worker) / (wall time with
``--threads`` workers).

``--method sift`` times SIFT homing over a whole grid instead (thesis 5.1,
table 5.3: the stand-in ``--db`` rendered at ``--sift-size``, 1122 x 162 by
default, all pairs, the average-vector combiner): per variant (``plain``,
``histeq`` = histogram equalisation before SIFT) the per-image work (SIFT
features, no cache) and the all-pairs home vectors (the grid runner's batch
path on ``--threads`` worker threads) are timed in CPU and wall time; the
rendering or loading of the database is reported separately (cached on disk
after the first run). It is not part of ``--method all``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from bionav.errors import UserError

METHODS = ("minwarping", "warping2d", "warping1d", "hiss")
#: timed over a whole grid (``--method sift``), not per pair of the pillar room; not part of ``all``
GRID_METHODS = ("sift",)
SIFT_VARIANTS = ("plain", "histeq")

#: min-warping variants: (name, plugin options)
MINWARPING_VARIANTS = (
    ("single", {}),
    ("double_fine", {"double_search": True, "fine_search": True}),
    ("compass", {"compass_acceleration": True}),
    ("compass_double_fine", {"compass_acceleration": True, "double_search": True, "fine_search": True}),
)
WARPING2D_VARIANTS = (("single", {}), ("compass", {"compass_acceleration": True}))

#: current views: (position in metres, heading in radians); the snapshot is at the origin
POSES = (((0.5, 0.3), 0.5), ((-0.6, 0.2), -1.0), ((0.2, -0.6), 2.5))


def _variants(name: str):
    if name == "minwarping":
        return MINWARPING_VARIANTS
    if name == "warping2d":
        return WARPING2D_VARIANTS
    return (("single", {}),)


def _plugin(name: str, options: dict, args, geometry):
    from bionav.plugins.homing.hiss import HissHoming
    from bionav.plugins.homing.warping import MinWarping, Warping1D, Warping2D

    if name == "hiss":
        return HissHoming(HissHoming.Config(), geometry=geometry), "-"
    if name == "warping1d":
        cfg = Warping1D.Config(image_size=list(args.size))
        return Warping1D(cfg, geometry=geometry), f"{cfg.n_alpha}x{cfg.n_psi}x{cfg.n_rho}"
    cls = MinWarping if name == "minwarping" else Warping2D
    cfg = cls.Config(image_size=list(args.size), n_alpha=args.steps, n_psi=args.steps,
                     compass_fraction=args.compass_fraction, **options)
    label = f"{args.steps}x{args.steps}" + (f"x{cfg.n_rho}" if name == "warping2d" else "")
    return cls(cfg, geometry=geometry), label


def _batch(pool, threads: int, method, pairs, n: int):
    """Run ``n`` home vectors on ``threads`` workers; return (cpu s, wall s)."""
    chunks = [range(t, n, threads) for t in range(threads)]

    def work(chunk):
        for i in chunk:
            s, c = pairs[i % len(pairs)]
            method.home_vector(s, c)

    c0, t0 = time.process_time(), time.perf_counter()
    list(pool.map(work, chunks))
    return time.process_time() - c0, time.perf_counter() - t0


def _grid_rows(args, load_procs_n: int) -> list[dict]:
    """Grid homing with 1 and ``args.threads`` workers, alternating; one row per variant and worker count."""
    from hydra.errors import HydraException

    from bionav.config import compose
    from bionav.evaluation.pairs import home_vector_matrix, prepare_images
    from bionav.experiments.common import load_configured_database

    try:
        cfg = compose([f"db={args.grid}"])
    except HydraException as exc:
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise UserError(f"--grid {args.grid}: no such database config ({first}); use a name of "
                        "bionav/conf/db, e.g. --grid sim_original") from None
    db = load_configured_database(cfg)
    n_snap = min(args.grid_snapshots, len(db))
    snapshots = np.linspace(0, len(db) - 1, n_snap).round().astype(int).tolist()
    counts = sorted({1, args.threads})
    runs = []
    for variant, options in MINWARPING_VARIANTS:
        method, steps = _plugin("minwarping", options, args, db.geometry)
        prepared = prepare_images(method, list(db.images), workers=args.threads)
        home_vector_matrix(method, db, snapshot_index=snapshots[:1], workers=args.threads,
                           prepared=(prepared, prepared))  # warm-up: compilation, templates
        runs.append({"variant": variant, "method": method, "prepared": prepared, "steps": steps,
                     "cpu": {w: [] for w in counts}, "wall": {w: [] for w in counts}, "n": 0})
    load = _start_load(load_procs_n)
    try:
        load_before = os.getloadavg()[0]
        for _ in range(args.grid_rounds):
            for run in runs:
                for w in counts:
                    c0, t0 = time.process_time(), time.perf_counter()
                    hv = home_vector_matrix(run["method"], db, snapshot_index=snapshots, workers=w,
                                            prepared=(run["prepared"], run["prepared"]))
                    cpu, wall = time.process_time() - c0, time.perf_counter() - t0
                    run["n"] = hv.n_pairs
                    run["cpu"][w].append(1e3 * cpu / hv.n_pairs)
                    run["wall"][w].append(1e3 * wall / hv.n_pairs)
        load_after = os.getloadavg()[0]
    finally:
        _stop_load(load)
    rows = []
    for run in runs:
        for w in counts:
            ratio = np.asarray(run["wall"][1]) / np.asarray(run["wall"][w])
            rows.append({
                "method": "minwarping",
                "variant": run["variant"],
                "threads": w,
                "cpu_ms_per_home_vector": round(float(np.median(run["cpu"][w])), 3),
                "wall_ms_per_home_vector": round(float(np.median(run["wall"][w])), 3),
                "cpu_ms_min": round(float(np.min(run["cpu"][w])), 3),
                "wall_ms_min": round(float(np.min(run["wall"][w])), 3),
                "workers_speedup": round(float(np.median(ratio)), 3),
                "experiment": "grid_homing",
                "db": db.name,
                "snapshots": len(snapshots),
                "home_vectors_per_round": run["n"],
                "image": "x".join(map(str, args.size)),
                "steps": run["steps"],
                "compass_fraction": args.compass_fraction if "compass" in run["variant"] else None,
                "rounds": args.grid_rounds,
                "background_load": load_procs_n,
                "loadavg_1min": [round(load_before, 2), round(load_after, 2)],
                "machine": f"{platform.machine()} {os.cpu_count()} cpus",
            })
    return rows


def _start_load(n: int) -> list[subprocess.Popen]:
    code = "import time\nend = time.monotonic() + 3600\nx = 0\nwhile time.monotonic() < end:\n    x += 1\n"
    return [subprocess.Popen([sys.executable, "-c", code]) for _ in range(n)]


def _stop_load(procs: list[subprocess.Popen]) -> None:
    for p in procs:
        p.terminate()
    for p in procs:
        try:
            p.wait(timeout=5)
        except subprocess.TimeoutExpired:  # pragma: no cover
            p.kill()


def _print_aligned(header, cells) -> None:
    """Print a Markdown table whose columns are padded to a common width (readable as plain text)."""
    widths = [max(len(h), *(len(c[i]) for c in cells)) for i, h in enumerate(header)]

    def line(cs):
        return "| " + " | ".join(c.ljust(w) for c, w in zip(cs, widths)) + " |"

    print(line(header))
    print("|" + "|".join("-" * (w + 2) for w in widths) + "|")
    for c in cells:
        print(line(c))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m bionav.bench",
        description="Time homing methods: CPU and wall ms per home vector (per-image work and "
                    "warm-up excluded), variants interleaved, median and minimum over the rounds.",
    )
    from bionav.bench.runs import RUN_METHODS, add_arguments, run_benchmark

    parser.add_argument("--method", choices=METHODS + GRID_METHODS + ("all",) + RUN_METHODS, default="minwarping",
                        help="method to time (default: minwarping; all = the pair methods, not sift); "
                             "sweep and cleaning time whole runs")
    parser.add_argument("--json", action="store_true",
                        help="print one JSON object per line instead of a table")
    parser.add_argument("--threads", type=int, default=1,
                        help="worker threads computing home vectors in parallel (default: 1)")
    parser.add_argument("--size", type=int, nargs=2, default=[288, 50], metavar=("W", "H"),
                        help="image size of the warping methods (default: 288 50)")
    parser.add_argument("--steps", type=int, default=96,
                        help="alpha and psi steps of min-warping and 2D-warping (default: 96)")
    parser.add_argument("--compass-fraction", type=float, default=0.3,
                        help="fraction of psi searched with compass acceleration (default: 0.3)")
    parser.add_argument("--repeat", type=int, default=None,
                        help="interleaved rounds (default: 15; 1 whole grid for --method sift)")
    parser.add_argument("--batch", type=int, default=None,
                        help="home vectors per round and variant (default: 6 per thread)")
    parser.add_argument("--background-load", type=int, default=0, metavar="N",
                        help="start N busy processes while measuring (default: 0)")
    parser.add_argument("--grid", metavar="DB", default=None,
                        help="time grid homing (min-warping) on database DB (e.g. sim_original) with 1 and "
                             "--threads workers instead of single pairs")
    parser.add_argument("--grid-snapshots", type=int, default=4,
                        help="snapshots of the grid run, each against every cell (default: 4)")
    parser.add_argument("--grid-rounds", type=int, default=3,
                        help="alternate rounds of the grid run (default: 3)")
    parser.add_argument("--pairs", type=int, default=len(POSES), choices=range(1, len(POSES) + 1),
                        metavar=f"1..{len(POSES)}",
                        help=f"current views (pairs with the snapshot) cycled through (default: {len(POSES)}; "
                             "1: the first pair only, as the reference driver of docs/performance.md)")
    parser.add_argument("--render-size", type=int, nargs=2, default=[576, 100], metavar=("W", "H"),
                        help="size of the rendered input panoramas (default: 576 100)")
    sift = parser.add_argument_group("--method sift (whole grid)")
    sift.add_argument("--db", default="sim_original",
                      help="stand-in database for --method sift (default: sim_original)")
    sift.add_argument("--sift-size", type=int, nargs=2, default=[1122, 162], metavar=("W", "H"),
                      help="image size the database is rendered at (default: 1122 162, the thesis')")
    sift.add_argument("--variants", default="plain,histeq",
                      help="comma-separated SIFT variants: plain, histeq (default: both)")
    sift.add_argument("--images", type=int, default=None, metavar="N",
                      help="use the first N images of the grid (default: all)")
    add_arguments(parser)
    args = parser.parse_args(argv)
    if args.method in RUN_METHODS:
        for row in run_benchmark(args):
            print(json.dumps(row) if args.json else "  ".join(f"{k}={v}" for k, v in row.items()))
        return 0
    if args.threads < 1 or args.threads > 64:
        parser.error("--threads must lie in 1..64")
    if args.repeat is None:
        args.repeat = 1 if args.method in GRID_METHODS else 15
    if args.repeat < 1:
        parser.error("--repeat must be >= 1")
    if not (0.0 < args.compass_fraction <= 1.0):
        parser.error("--compass-fraction must lie in (0, 1]")
    if args.background_load < 0:
        parser.error("--background-load must be >= 0")
    batch = args.batch if args.batch is not None else 6 * args.threads
    if batch < 1:
        parser.error("--batch must be >= 1")
    if args.grid is not None:
        if args.method != "minwarping":
            parser.error("--grid times min-warping only; drop --method or use --method minwarping")
        if args.grid_snapshots < 1 or args.grid_rounds < 1:
            parser.error("--grid-snapshots and --grid-rounds must be >= 1")
        try:
            rows = _grid_rows(args, args.background_load)
        except UserError as exc:
            parser.exit(2, f"error: {exc}\n")
        return _print_rows(rows, args)

    if args.method == "sift":
        variants = [v.strip() for v in args.variants.split(",") if v.strip()]
        bad = [v for v in variants if v not in SIFT_VARIANTS]
        if bad or not variants:
            parser.error(f"--variants must be a comma-separated list of {', '.join(SIFT_VARIANTS)}, not {args.variants!r}")
        if not (8 <= args.sift_size[0] <= 8192 and 8 <= args.sift_size[1] <= 8192):
            parser.error("--sift-size W H must lie in 8..8192")
        if args.images is not None and args.images < 2:
            parser.error("--images must be >= 2")
        return _print_sift(_sift_rows(args, variants), args)

    from bionav.testing.pillar_scene import render_pillar_panorama

    rw, rh = args.render_size
    snap, geometry = render_pillar_panorama((0.0, 0.0), width=rw, height=rh, supersample=2)
    currents = [render_pillar_panorama(p, heading=h, width=rw, height=rh, supersample=2)[0]
                for p, h in POSES[:args.pairs]]

    names = METHODS if args.method == "all" else (args.method,)
    runs = []
    for name in names:
        for variant, options in _variants(name):
            method, steps = _plugin(name, options, args, geometry)
            t0 = time.process_time()
            s = method.prepare(snap)
            prep_ms = 1e3 * (time.process_time() - t0)
            pairs = [(s, method.prepare(c)) for c in currents]
            runs.append({"method": name, "variant": variant, "obj": method, "pairs": pairs, "steps": steps,
                         "prepare_cpu_ms": prep_ms, "cpu": [], "wall": []})

    load = _start_load(args.background_load)
    try:
        with ThreadPoolExecutor(args.threads) as pool:
            for run in runs:  # warm-up: compilation, templates, caches
                _batch(pool, args.threads, run["obj"], run["pairs"], max(args.threads, 2))
            load_before = os.getloadavg()[0]
            for _ in range(args.repeat):
                for run in runs:
                    cpu, wall = _batch(pool, args.threads, run["obj"], run["pairs"], batch)
                    run["cpu"].append(1e3 * cpu / batch)
                    run["wall"].append(1e3 * wall / batch)
            load_after = os.getloadavg()[0]
    finally:
        _stop_load(load)

    rows = []
    for run in runs:
        rows.append({
            "method": run["method"],
            "variant": run["variant"],
            "threads": args.threads,
            "cpu_ms_per_home_vector": round(float(np.median(run["cpu"])), 3),
            "wall_ms_per_home_vector": round(float(np.median(run["wall"])), 3),
            "cpu_ms_min": round(float(np.min(run["cpu"])), 3),
            "wall_ms_min": round(float(np.min(run["wall"])), 3),
            "prepare_cpu_ms_per_image": round(run["prepare_cpu_ms"], 3),
            "image": "x".join(map(str, args.size if run["method"] != "hiss" else args.render_size)),
            "steps": run["steps"],
            "compass_fraction": args.compass_fraction if "compass" in run["variant"] else None,
            "rounds": args.repeat,
            "home_vectors_per_round": batch,
            "pairs": args.pairs,
            "background_load": args.background_load,
            "loadavg_1min": [round(load_before, 2), round(load_after, 2)],
            "machine": f"{platform.machine()} {os.cpu_count()} cpus",
        })
    return _print_rows(rows, args)


def _print_rows(rows: list[dict], args) -> int:
    if args.json:
        for row in rows:
            print(json.dumps(row))
        return 0
    last, key = (("workers speedup", "workers_speedup") if args.grid is not None
                 else ("prepare CPU ms/image", "prepare_cpu_ms_per_image"))
    header = ("method", "variant", "image", "steps", "threads", "CPU ms/hv (median)", "CPU ms (min)",
              "wall ms/hv (median)", "wall ms (min)", last)
    cells = [(r["method"], r["variant"], r["image"], r["steps"], str(r["threads"]),
              f"{r['cpu_ms_per_home_vector']:.2f}", f"{r['cpu_ms_min']:.2f}",
              f"{r['wall_ms_per_home_vector']:.2f}", f"{r['wall_ms_min']:.2f}",
              f"{r[key]:.2f}") for r in rows]
    _print_aligned(header, cells)
    print(f"load average (1 min) {rows[0]['loadavg_1min'][0]} -> {rows[0]['loadavg_1min'][1]}, "
          f"background load {args.background_load}, {rows[0]['machine']}")
    return 0


def _sift_rows(args, variants) -> list[dict]:
    """Time SIFT homing over a grid per variant: per-image work and all pairs, CPU and wall time."""
    from bionav.config import compose
    from bionav.errors import UserError
    from bionav.evaluation.pairs import home_vector_matrix, prepare_images
    from bionav.experiments.common import load_configured_database
    from bionav.plugins.homing.sift import SiftConfig, SiftHoming

    w_img, h_img = args.sift_size
    rows = []
    load = _start_load(args.background_load)
    try:
        for variant in variants:
            overrides = ["experiment=grid_homing", "homing=sift", f"db={args.db}", f"db.image_size=[{w_img},{h_img}]",
                         f"preprocess={'he' if variant == 'histeq' else 'none'}"]
            try:
                cfg = compose(overrides)
            except Exception as exc:  # an unknown database name
                raise SystemExit(f"python -m bionav.bench: error: --db {args.db!r}: {exc}") from None
            t0 = time.perf_counter()
            try:
                db = load_configured_database(cfg)
            except UserError as exc:
                raise SystemExit(f"python -m bionav.bench: error: {exc}") from None
            load_s = time.perf_counter() - t0
            if args.images is not None:
                db = db.subset(range(min(args.images, len(db))))
            method = SiftHoming(SiftConfig(), geometry=db.geometry)
            loadavg = [os.getloadavg()[0]]
            c0, t0 = time.process_time(), time.perf_counter()
            prepared = prepare_images(method, list(db.images), workers=args.threads)
            prep_cpu, prep_wall = time.process_time() - c0, time.perf_counter() - t0
            keypoints = np.array([len(p.xy) for p in prepared])
            home_vector_matrix(method, db, workers=args.threads, prepared=(prepared, prepared),
                               snapshot_index=[0, 1])  # warm-up: compiled kernels
            counts = sorted({1, args.threads})
            cpu = {w: [] for w in counts}
            wall = {w: [] for w in counts}
            for _ in range(args.repeat):  # 1 worker and --threads workers alternately
                for w in counts:
                    c0, t0 = time.process_time(), time.perf_counter()
                    hv = home_vector_matrix(method, db, workers=w, prepared=(prepared, prepared))
                    cpu[w].append(time.process_time() - c0)
                    wall[w].append(time.perf_counter() - t0)
            loadavg.append(os.getloadavg()[0])
            n = hv.n_pairs
            for w in counts:
                rows.append({
                    "method": "sift",
                    "variant": variant,
                    "threads": w,
                    "cpu_ms_per_home_vector": round(1e3 * float(np.median(cpu[w])) / n, 4),
                    "wall_ms_per_home_vector": round(1e3 * float(np.median(wall[w])) / n, 4),
                    "cpu_ms_min": round(1e3 * float(np.min(cpu[w])) / n, 4),
                    "wall_ms_min": round(1e3 * float(np.min(wall[w])) / n, 4),
                    "workers_speedup": round(float(np.median(np.asarray(wall[1]) / np.asarray(wall[w]))), 3),
                    "pairs_cpu_s": round(float(np.median(cpu[w])), 6),
                    "pairs_wall_s": round(float(np.median(wall[w])), 6),
                    "prepare_threads": args.threads,
                    "prepare_cpu_ms_per_image": round(1e3 * prep_cpu / len(db), 3),
                    "prepare_wall_s": round(prep_wall, 3),
                    "grid_cpu_s": round(prep_cpu + float(np.median(cpu[w])), 3),
                    "grid_wall_s": round(prep_wall + float(np.median(wall[w])), 3),
                    "db_load_s": round(load_s, 3),
                    "db": args.db,
                    "image": f"{w_img}x{h_img}",
                    "n_images": len(db),
                    "n_pairs": n,
                    "keypoints_per_image": {"mean": round(float(keypoints.mean()), 1), "min": int(keypoints.min()),
                                            "max": int(keypoints.max())},
                    "search_radius": method.config.search_radius,
                    "combine": method.config.combine,
                    "rounds": args.repeat,
                    "background_load": args.background_load,
                    "loadavg_1min": [round(v, 2) for v in loadavg],
                    "machine": f"{platform.machine()} {os.cpu_count()} cpus",
                })
    finally:
        _stop_load(load)
    return rows


def _print_sift(rows: list[dict], args) -> int:
    if args.json:
        for row in rows:
            print(json.dumps(row))
        return 0
    header = ("variant", "image", "images", "keypoints/image", "threads", "grid wall s", "grid CPU s",
              "SIFT CPU ms/image", "pairs wall s", "pairs CPU s", "CPU ms/hv", "speedup", "db load s")
    cells = [(r["variant"], r["image"], str(r["n_images"]), f"{r['keypoints_per_image']['mean']:.0f}",
              str(r["threads"]), f"{r['grid_wall_s']:.1f}", f"{r['grid_cpu_s']:.1f}",
              f"{r['prepare_cpu_ms_per_image']:.1f}", f"{r['pairs_wall_s']:.1f}", f"{r['pairs_cpu_s']:.1f}",
              f"{r['cpu_ms_per_home_vector']:.3f}", f"{r['workers_speedup']:.2f}", f"{r['db_load_s']:.1f}")
             for r in rows]
    _print_aligned(header, cells)
    print(f"sift on {rows[0]['db']}: {rows[0]['n_pairs']} home vectors per grid; load average (1 min) "
          f"{rows[0]['loadavg_1min'][0]} -> {rows[-1]['loadavg_1min'][-1]}, background load {args.background_load}, "
          f"{rows[0]['machine']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
