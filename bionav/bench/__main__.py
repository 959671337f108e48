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

import json
import os
import platform
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

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

    from bionav.bench.cpu import numba_target
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
                **numba_target(),
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


#: bounds checked before any work (memory and time of one run)
MAX_SIZE = (2048, 512)        #: --size W H (min-warping's window table grows with W x steps)
MAX_RENDER = (4096, 1024)     #: --render-size W H (ray-cast with 2 x 2 rays per pixel)
MAX_SIFT = (4096, 1024)       #: --sift-size W H
MAX_SIFT_PIXELS = 1 << 20     #: W x H of --sift-size (170 images of 1 Mpx in float32: about 0.7 GB)
MAX_STEPS = 1024
MAX_REPEAT = 1000
MAX_BATCH = 10_000
MAX_THREADS = 64
MAX_LOAD = 64
#: environment variable marking the fresh process of ``--cpu-name`` (its value: the CPU name)
_CHILD = "BIONAV_BENCH_CPU_CHILD"


def _parser():
    from bionav.bench._cli import BenchParser
    from bionav.bench.cpu import KNOWN_TARGETS
    from bionav.bench.runs import RUN_METHODS, add_arguments

    parser = BenchParser(
        prog="python -m bionav.bench",
        description="Time homing methods: CPU and wall ms per home vector (per-image work and "
                    "warm-up excluded), variants interleaved, median and minimum over the rounds.",
    )
    parser.add_argument("--method", choices=METHODS + GRID_METHODS + ("all",) + RUN_METHODS, default="minwarping",
                        help="method to time (default: minwarping; all = the pair methods, not sift); "
                             "sweep and cleaning time whole runs")
    parser.add_argument("--json", action="store_true",
                        help="print one JSON object per line instead of a table")
    parser.add_argument("--threads", type=int, default=1,
                        help=f"worker threads computing home vectors in parallel (default: 1; 1..{MAX_THREADS})")
    parser.add_argument("--size", type=int, nargs=2, default=[288, 50], metavar=("W", "H"),
                        help=f"image size of the warping methods (default: 288 50; at most {MAX_SIZE[0]} {MAX_SIZE[1]})")
    parser.add_argument("--steps", type=int, default=96,
                        help="alpha and psi steps of min-warping and 2D-warping (default: 96; 4..W)")
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
                             "1: the first pair only)")
    parser.add_argument("--render-size", type=int, nargs=2, default=[576, 100], metavar=("W", "H"),
                        help="size of the rendered input panoramas (default: 576 100; at least --size)")
    target = parser.add_argument_group("target CPU (every JSON row carries cpu and isa)")
    target.add_argument("--cpu-name", metavar="NAME", default=None,
                        help="time code compiled for CPU NAME (in a fresh process with NUMBA_CPU_NAME, the matching "
                             f"NUMBA_CPU_FEATURES and its own NUMBA_CACHE_DIR); known: {', '.join(KNOWN_TARGETS)}. "
                             "Refused where this CPU lacks one of NAME's features")
    target.add_argument("--cpu-features", metavar="FEATURES", default=None,
                        help="with --cpu-name: the LLVM feature string (e.g. +sse2,+avx2) for a name not known")
    target.add_argument("--reference", metavar="CMD", default=None,
                        help="min-warping only: after bionav's variants in every round run the external command "
                             "CMD DIR N (DIR: the 8-bit images both time, manifest.txt; N: home vectors) and "
                             "report its JSON lines ({\"variant\", \"cpu_ms_per_home_vector\"}) next to bionav's "
                             "(docs/performance.md)")
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
    return parser


def _check_args(parser, args) -> None:
    """Every numeric option against its bounds, before any work (one message naming the option)."""
    from bionav.bench._cli import bounded_int

    bounded_int(parser, "--threads", args.threads, 1, MAX_THREADS)
    bounded_int(parser, "--background-load", args.background_load, 0, MAX_LOAD)
    if args.repeat is not None:
        bounded_int(parser, "--repeat", args.repeat, 1, MAX_REPEAT)
    if args.batch is not None:
        bounded_int(parser, "--batch", args.batch, 1, MAX_BATCH)
    w, h = args.size
    if not (8 <= w <= MAX_SIZE[0] and 4 <= h <= MAX_SIZE[1]):
        parser.error(f"--size {w} {h} is out of range: W must lie in 8..{MAX_SIZE[0]} and H in 4..{MAX_SIZE[1]} "
                     "pixels; e.g. --size 288 50")
    bounded_int(parser, "--steps", args.steps, 4, min(w, MAX_STEPS),
                f" (at most the image width --size W = {w}, searches shift whole columns)")
    rw, rh = args.render_size
    if not (w <= rw <= MAX_RENDER[0] and h <= rh <= MAX_RENDER[1]):
        parser.error(f"--render-size {rw} {rh} is out of range: it must be at least --size ({w} {h}) and at most "
                     f"{MAX_RENDER[0]} {MAX_RENDER[1]}; e.g. --render-size {2 * w} {2 * h}")
    if not (0.0 < args.compass_fraction <= 1.0):
        parser.error(f"--compass-fraction {args.compass_fraction} must lie in (0, 1]; e.g. --compass-fraction 0.3")
    bounded_int(parser, "--grid-snapshots", args.grid_snapshots, 1, 100_000)
    bounded_int(parser, "--grid-rounds", args.grid_rounds, 1, MAX_REPEAT)
    sw, sh = args.sift_size
    if not (8 <= sw <= MAX_SIFT[0] and 8 <= sh <= MAX_SIFT[1] and sw * sh <= MAX_SIFT_PIXELS):
        parser.error(f"--sift-size {sw} {sh} is out of range: W must lie in 8..{MAX_SIFT[0]}, H in 8..{MAX_SIFT[1]} "
                     f"and W x H at most {MAX_SIFT_PIXELS} pixels (the whole grid is held in memory); "
                     "e.g. --sift-size 1122 162")
    if args.images is not None and not (2 <= args.images <= 100_000):
        parser.error(f"--images must be >= 2 (and at most 100000), got {args.images}; e.g. --images 20")
    if args.cpu_features is not None and args.cpu_name is None:
        parser.error("--cpu-features needs --cpu-name NAME (the CPU the features belong to)")
    if args.reference is not None and (args.method != "minwarping" or args.grid is not None):
        parser.error("--reference times min-warping pairs only; drop --method/--grid or drop --reference")
    if args.method in ("sweep", "cleaning"):
        from bionav.bench.runs import check_arguments

        check_arguments(parser, args)


def _run_for_cpu(parser, args, argv: list[str]) -> int:
    """Re-run this command in a fresh process whose numba compiles for ``--cpu-name`` (exit status forwarded)."""
    from bionav.bench.cpu import KNOWN_TARGETS, host_cpu, missing_host_features, target_environment

    try:
        env_vars = target_environment(args.cpu_name, args.cpu_features)
    except ValueError as exc:
        parser.error(f"--cpu-name {args.cpu_name}: {exc}; or give its features with --cpu-features "
                     f"(known names: {', '.join(KNOWN_TARGETS)})")
    missing = missing_host_features(env_vars["NUMBA_CPU_FEATURES"])
    if missing:
        parser.error(f"--cpu-name {args.cpu_name}: this machine's CPU ({host_cpu()[0]}) lacks "
                     f"{', '.join(missing)}, so code compiled for {args.cpu_name} would die here with an illegal "
                     "instruction. Time it on a machine that has these features, or choose a CPU this one can run "
                     "(e.g. --cpu-name haswell on any AVX2 x86 machine)")
    env = dict(os.environ)
    env.update(env_vars)
    env[_CHILD] = args.cpu_name
    proc = subprocess.run([sys.executable, "-m", "bionav.bench", *argv], env=env)
    return proc.returncode


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = _parser()
    args = parser.parse_args(argv)
    _check_args(parser, args)
    if args.cpu_name is not None and os.environ.get(_CHILD) != args.cpu_name:
        return _run_for_cpu(parser, args, argv)
    if args.method in ("sweep", "cleaning"):
        from bionav.bench.runs import run_benchmark

        for row in run_benchmark(args):
            print(json.dumps(row) if args.json else "  ".join(f"{k}={v}" for k, v in row.items()))
        return 0
    if args.repeat is None:
        args.repeat = 1 if args.method in GRID_METHODS else 15
    batch = args.batch if args.batch is not None else 6 * args.threads
    if args.grid is not None:
        if args.method != "minwarping":
            parser.error("--grid times min-warping only; drop --method or use --method minwarping")
        try:
            rows = _grid_rows(args, args.background_load)
        except UserError as exc:
            parser.exit(2, f"{parser.prog}: error: {exc}\n")
        return _print_rows(rows, args)

    if args.method == "sift":
        variants = [v.strip() for v in args.variants.split(",") if v.strip()]
        bad = [v for v in variants if v not in SIFT_VARIANTS]
        if bad or not variants:
            parser.error(f"--variants must be a comma-separated list of {', '.join(SIFT_VARIANTS)}, not {args.variants!r}")
        return _print_sift(_sift_rows(args, variants), args)

    if args.size[0] % 2 and args.method in ("minwarping", "all"):
        parser.error(f"--size {args.size[0]} {args.size[1]}: min-warping's double search needs an even width; "
                     f"e.g. --size {args.size[0] + 1} {args.size[1]}")
    return _pair_rows(args, batch)


def _eight_bit(image, geometry, size):
    """The panorama resized to ``size`` (area averaging) and rounded to 8 bits (0..255), with its geometry."""
    from bionav.homing.imageops import resize_panorama

    img, geo = resize_panorama(np.asarray(image, dtype=np.float32), geometry=geometry, size=size)
    return np.clip(np.rint(255.0 * img), 0, 255).astype(np.uint8), geo


def _write_reference_inputs(folder: Path, images, geometry, args) -> None:
    """The 8-bit images both programs time, as binary PGM, and ``manifest.txt`` (see ``--reference``)."""
    names = ["snapshot.pgm"] + [f"current_{k + 1}.pgm" for k in range(len(images) - 1)]
    for name, img in zip(names, images):
        h, w = img.shape
        (folder / name).write_bytes(f"P5\n{w} {h}\n255\n".encode("ascii") + img.tobytes())
    head = (f"{geometry.width} {geometry.height} {geometry.horizon_row:.6f} {geometry.rad_per_row:.9f} "
            f"{args.steps} {args.steps} {args.compass_fraction}")
    (folder / "manifest.txt").write_text("\n".join([head, *names]) + "\n", encoding="ascii")


def _reference_round(command: list[str], folder: Path, batch: int) -> dict[str, float]:
    """Run the reference command once; its CPU ms per home vector by variant."""
    shown = " ".join(command)
    try:
        proc = subprocess.run([*command, str(folder), str(batch)], capture_output=True, text=True, timeout=3600)
    except FileNotFoundError:
        raise UserError(f"--reference {shown!r}: no such program {command[0]!r}; give the path of the reference "
                        "driver (docs/performance.md)") from None
    except PermissionError:
        raise UserError(f"--reference {shown!r}: {command[0]!r} is not executable; chmod +x it or give "
                        "the right program") from None
    except subprocess.TimeoutExpired:
        raise UserError(f"--reference {shown!r} ran for over an hour in one round; give it fewer home vectors "
                        "(--batch)") from None
    if proc.returncode != 0:
        lines = [line.strip() for line in proc.stderr.splitlines() if line.strip()]
        tail = lines[-1] if lines else "no message"  # its last line (the error, not a traceback)
        raise UserError(f"--reference {shown!r} failed with status {proc.returncode} ({tail}); run it by hand as "
                        f"`{shown} DIR N` to see why")
    out: dict[str, float] = {}
    for line in proc.stdout.splitlines():
        line = line.strip()
        if not line:
            continue
        try:
            row = json.loads(line)
            out[str(row["variant"])] = float(row["cpu_ms_per_home_vector"])
        except (ValueError, KeyError, TypeError):
            raise UserError(f"--reference {shown!r} printed {line[:80]!r}; it must print one JSON object per "
                            "variant with \"variant\" and \"cpu_ms_per_home_vector\"") from None
    if not out:
        raise UserError(f"--reference {shown!r} printed nothing; it must print one JSON line per variant "
                        f"({', '.join(v for v, _ in MINWARPING_VARIANTS)})")
    return out


def _pair_rows(args, batch: int) -> int:
    """Time the pair methods on the pillar room (and the ``--reference`` command); print the rows."""
    import shlex
    import tempfile

    from bionav.bench.cpu import numba_target
    from bionav.testing.pillar_scene import render_pillar_panorama

    rw, rh = args.render_size
    snap, geometry = render_pillar_panorama((0.0, 0.0), width=rw, height=rh, supersample=2)
    currents = [render_pillar_panorama(p, heading=h, width=rw, height=rh, supersample=2)[0]
                for p, h in POSES[:args.pairs]]
    reference = None
    if args.reference is not None:
        try:
            command = shlex.split(args.reference)
        except ValueError as exc:
            raise UserError(f"--reference {args.reference!r}: {exc}; quote the command as one shell word") from None
        if not command:
            raise UserError("--reference is empty; give the reference driver's command line")
        # both programs time the same 8-bit pixels at --size
        snap, g8 = _eight_bit(snap, geometry, args.size)
        currents = [_eight_bit(c, geometry, args.size)[0] for c in currents]
        geometry = g8
        reference = {"command": command, "dir": tempfile.TemporaryDirectory(prefix="bionav-reference-"),
                     "cpu": {v: [] for v, _ in MINWARPING_VARIANTS}}
        _write_reference_inputs(Path(reference["dir"].name), [snap, *currents], geometry, args)

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
                if reference is not None:  # interleaved: one reference round after each bionav round
                    got = _reference_round(reference["command"], Path(reference["dir"].name), batch)
                    for v in reference["cpu"]:
                        reference["cpu"][v].append(got.get(v, float("nan")))
            load_after = os.getloadavg()[0]
    finally:
        _stop_load(load)
        if reference is not None:
            reference["dir"].cleanup()

    target = numba_target()
    common = {"threads": args.threads, "rounds": args.repeat, "home_vectors_per_round": batch, "pairs": args.pairs,
              "background_load": args.background_load, "loadavg_1min": [round(load_before, 2), round(load_after, 2)],
              "machine": f"{platform.machine()} {os.cpu_count()} cpus", **target}
    rows = []
    for run in runs:
        row = {
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
            **common,
        }
        ref = reference["cpu"].get(run["variant"]) if reference is not None else None
        if ref is not None and np.isfinite(ref).all():
            row["input"] = "8bit"
            row["reference_cpu_ms_per_home_vector"] = round(float(np.median(ref)), 3)
            row["reference_cpu_ms_min"] = round(float(np.min(ref)), 3)
            # per round: bionav / reference of the same round (interleaved), median over the rounds
            row["cpu_ratio_to_reference"] = round(float(np.median(np.asarray(run["cpu"]) / np.asarray(ref))), 3)
        elif reference is not None:  # the reference printed no line for this variant
            row["input"] = "8bit"
            row["reference_cpu_ms_per_home_vector"] = None
        if reference is not None:
            row["reference_command"] = args.reference
        rows.append(row)
    return _print_rows(rows, args)


def _fmt(x) -> str:
    return "-" if x is None else f"{x:.2f}"


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
    if args.reference is not None:
        header = (*header, "reference CPU ms/hv (median)", "bionav / reference")
        cells = [(*c, _fmt(r.get("reference_cpu_ms_per_home_vector")), _fmt(r.get("cpu_ratio_to_reference")))
                 for c, r in zip(cells, rows)]
    _print_aligned(header, cells)
    print(f"numba target CPU {rows[0]['cpu']} ({rows[0]['isa']})")
    print(f"load average (1 min) {rows[0]['loadavg_1min'][0]} -> {rows[0]['loadavg_1min'][1]}, "
          f"background load {args.background_load}, {rows[0]['machine']}")
    return 0


def _sift_rows(args, variants) -> list[dict]:
    """Time SIFT homing over a grid per variant: per-image work and all pairs, CPU and wall time."""
    from bionav.bench.cpu import numba_target
    from bionav.config import compose
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
                first = (str(exc).splitlines() or [type(exc).__name__])[0]
                raise UserError(f"--db {args.db!r}: no such database config ({first}); use a name of "
                                "bionav/conf/db, e.g. --db sim_original") from None
            t0 = time.perf_counter()
            db = load_configured_database(cfg)
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
                    **numba_target(),
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
    from bionav.bench._cli import run

    run(main, "python -m bionav.bench")
