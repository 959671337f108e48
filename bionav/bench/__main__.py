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
import subprocess
import sys

from bionav.bench.grid import GRID_METHODS, SIFT_VARIANTS, grid_rows, sift_rows
from bionav.bench.pairs import METHODS, POSES, pair_rows
from bionav.errors import UserError


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
    parser.add_argument("--method", choices=METHODS + GRID_METHODS + ("all", "scaling", "stages", "calibrate") + RUN_METHODS,
                        default="minwarping",
                        help="method to time (default: minwarping; all = the pair methods, not sift); "
                             "sweep and cleaning time whole runs; scaling: CPU per home vector against image "
                             "and grid size for each method; stages: min-warping's stages against the arithmetic "
                             "floor; calibrate: the plan's calibration workloads (python -m bionav.thesis --plan)")
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
    scaling = parser.add_argument_group("--method scaling (CPU against image and grid size)")
    scaling.add_argument("--scaling-sizes", default="144x25,288x50,576x100", metavar="WxH,...",
                         help="image sizes of the pair table (default: 144x25,288x50,576x100)")
    scaling.add_argument("--scaling-snapshots", type=int, default=4, metavar="N",
                         help="snapshots of the larger whole run (the smaller has 1; default: 4)")
    scaling.add_argument("--scaling-runs", type=int, default=1, choices=(0, 1),
                         help="1: also time whole grid-homing runs on --db (default); 0: the pair table only")
    scaling.add_argument("--clock-ghz", type=float, default=None, metavar="F",
                         help="--method stages: the core clock of the floor (default: measured)")
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
    if args.method == "scaling":
        from bionav.bench.scaling import parse_sizes

        try:
            parse_sizes(args.scaling_sizes)
        except ValueError as exc:
            parser.error(f"--scaling-sizes: {exc}; e.g. --scaling-sizes 144x25,288x50")
        bounded_int(parser, "--scaling-snapshots", args.scaling_snapshots, 2, 1000)
    if args.clock_ghz is not None and not 0.1 <= args.clock_ghz <= 10.0:
        parser.error(f"--clock-ghz {args.clock_ghz} is out of range: give the core clock in GHz, 0.1..10; e.g. "
                     "--clock-ghz 2.6")


def _run_for_cpu(parser, args, argv: list[str]) -> int:
    """Re-run this command in a fresh process whose numba compiles for ``--cpu-name`` (exit status forwarded)."""
    from bionav.bench.cpu import KNOWN_TARGETS, host_cpu, missing_host_features, target_environment, unrecognized

    try:
        env_vars = target_environment(args.cpu_name, args.cpu_features)
    except ValueError as exc:
        parser.error(f"--cpu-name {args.cpu_name}: {exc}; or give its features with --cpu-features "
                     f"(known names: {', '.join(KNOWN_TARGETS)})")
    unknown = unrecognized(args.cpu_name, env_vars["NUMBA_CPU_FEATURES"])
    if unknown:
        parser.error(f"--cpu-name {args.cpu_name}: LLVM does not know {', '.join(unknown)} for this machine's "
                     f"target ({host_cpu()[0]}), so numba would compile for a generic CPU or abort; give a CPU name "
                     f"LLVM knows (e.g. {', '.join(KNOWN_TARGETS)}) and features such as +sse2,+avx2")
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
        args.repeat = 1 if args.method in GRID_METHODS else 5 if args.method in ("scaling", "stages") else 15
    if args.method == "scaling":
        from bionav.bench.scaling import scaling_rows

        return _print_scaling(scaling_rows(args), args)
    if args.method == "calibrate":
        from bionav.bench.calibration import run_calibration

        cal = run_calibration()
        print(json.dumps(cal) if args.json else "  ".join(f"{k}={v}" for k, v in cal.items()))
        return 0
    if args.method == "stages":
        from bionav.bench.stages import stage_rows

        return _print_stages(stage_rows(args), args)
    batch = args.batch if args.batch is not None else 6 * args.threads
    if args.grid is not None:
        if args.method != "minwarping":
            parser.error("--grid times min-warping only; drop --method or use --method minwarping")
        try:
            rows = grid_rows(args, args.background_load)
        except UserError as exc:
            parser.exit(2, f"{parser.prog}: error: {exc}\n")
        return _print_rows(rows, args)

    if args.method == "sift":
        variants = [v.strip() for v in args.variants.split(",") if v.strip()]
        bad = [v for v in variants if v not in SIFT_VARIANTS]
        if bad or not variants:
            parser.error(f"--variants must be a comma-separated list of {', '.join(SIFT_VARIANTS)}, not {args.variants!r}")
        return _print_sift(sift_rows(args, variants), args)

    if args.size[0] % 2 and args.method in ("minwarping", "all"):
        parser.error(f"--size {args.size[0]} {args.size[1]}: min-warping's double search needs an even width; "
                     f"e.g. --size {args.size[0] + 1} {args.size[1]}")
    return _print_rows(pair_rows(args, batch), args)


def _load_line(row: dict) -> str:
    return f"load average (1 min) {row['loadavg_1min'][0]} -> {row['loadavg_1min'][1]}"


def _json_lines(rows: list[dict]) -> int:
    """Print one JSON object per row (``--json``); status 0."""
    for row in rows:
        print(json.dumps(row))
    return 0


def _fmt(x) -> str:
    return "-" if x is None else f"{x:.2f}"


def _print_rows(rows: list[dict], args) -> int:
    if args.json:
        return _json_lines(rows)
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
    print(_load_line(rows[0]) + f", background load {args.background_load}, {rows[0]['machine']}")
    return 0


def _print_scaling(rows: list[dict], args) -> int:
    if args.json:
        return _json_lines(rows)
    pairs = [r for r in rows if r["table"] == "pairs"]
    _print_aligned(("method", "image", "pixels", "CPU ms/hv (min)", "CPU ms/hv (median)", "growth exponent",
                    "prepare CPU ms/image"),
                   [(r["method"], r["image"], str(r["pixels"]), f"{r['cpu_ms_min']:.3f}",
                     f"{r['cpu_ms_per_home_vector']:.3f}", _fmt(r.get("growth_exponent")),
                     f"{r['prepare_cpu_ms_per_image']:.1f}") for r in pairs])
    runs = [r for r in rows if r["table"] == "runs"]
    if runs:
        print()
        _print_aligned(("method", "db", "snapshots", "home vectors", "run CPU s", "CPU ms/hv (slope)",
                        "fixed CPU s per run"),
                       [(r["method"], r["db"], " / ".join(map(str, r["snapshots"])),
                         " / ".join(map(str, r["home_vectors"])), " / ".join(map(str, r["cpu_s"])),
                         f"{r['cpu_ms_per_home_vector']:.3f}", f"{r['fixed_cpu_s']:.2f}") for r in runs])
    print(f"numba target CPU {rows[0]['cpu']} ({rows[0]['isa']}); " + _load_line(rows[0]) + f", {rows[0]['machine']}")
    return 0


def _print_stages(rows: list[dict], args) -> int:
    if args.json:
        return _json_lines(rows)
    _print_aligned(("stage", "byte-lane ops", "floor ms", "CPU ms (min)", "fraction of the floor"),
                   [(r["stage"], "-" if r["byte_lane_ops"] is None else f"{r['byte_lane_ops'] / 1e6:.1f} M",
                     f"{r['floor_ms']:.3f}", f"{r['cpu_ms']:.3f}", f"{100 * r['fraction_of_floor']:.1f} %")
                    for r in rows])
    print(f"min-warping at {rows[0]['image']}, {rows[0]['steps']} x {rows[0]['steps']} steps; floor: 2 x 64 byte lanes "
          f"per cycle at {rows[0]['clock_ghz']} GHz; load average (1 min) {rows[0]['loadavg_1min']}")
    return 0


def _print_sift(rows: list[dict], args) -> int:
    if args.json:
        return _json_lines(rows)
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
