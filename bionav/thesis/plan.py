"""A plan before the run: ``python -m bionav.thesis --preset P --plan --nodes N --cores C [--json]``.

The plan lists every task the preset's runs make (a run, or one ``experiment.block=[i,n]`` task of
a split run, :meth:`bionav.thesis.runs.RunSpec.tasks`), the CPU seconds each is expected to need,
the critical path and the expected wall time on ``nodes x cores`` cores.

How the CPU of a task is estimated (:func:`task_cpu_s`), each figure with its basis, all of them CPU
time on one core of the reference machine (:data:`bionav.thesis.calibration.REFERENCE`):

* every run: the start-up of ``python -m bionav`` (:data:`RUN_START_S`);
* grid homing and the cross-database test: home vectors x the method's CPU ms per home vector
  (:data:`HOME_VECTOR_MS`, measured with ``python -m bionav.bench``, scaled with the image's pixels
  where the method works on the database's own size; SIFT by its keypoints, :func:`sift_costs`),
  plus loading its databases (:data:`DB_LOAD_S_PER_MPX`) and rendering them once
  (:data:`RENDER_S_PER_IMAGE`, :data:`RENDER_S_PER_MPX`); a task of a split run holds every
  n-th snapshot (or (snapshot, database pair) unit) from the i-th, exactly as the experiment splits;
* the parameter sweep: its jobs x the CPU of one job (:data:`RUN_CPU_S`);
* every other experiment: the CPU of one run (:data:`RUN_CPU_S`), measured or assumed as the
  table says.

The figures are then scaled to the machine planned for: per method family by this machine's
calibration (:mod:`bionav.thesis.calibration`, cached per CPU), by ``--cpu-factor F``, or by the
calibration file of another machine (``--calibration FILE``).

The expected wall time schedules the renders first, then the tasks on ``nodes x cores`` slots of
one core each (a task's own threads are not counted): the earliest free core takes the longest
task whose render is done. The critical path is the longest chain on unlimited cores: a
database's render, then its longest task.
"""

from __future__ import annotations

import functools
import heapq
import math
from dataclasses import asdict, dataclass
from typing import Any, Iterable, Sequence

from bionav.thesis.runs import RunSpec

#: CPU ms per home vector on one core of the reference machine (method -> (ms, reference pixels or None
#: when the method resizes to its own size, basis)); "measured" figures are the minimum CPU time over the
#: rounds of ``python -m bionav.bench`` (native code), which other processes change little
HOME_VECTOR_MS: dict[str, tuple[float, int | None, str]] = {
    "minwarping": (3.2, None, "measured 2026-11-28: min-warping single search at 288x50, 96x96 steps, CPU ms per home "
                              "vector on the bench's pairs (python -m bionav.bench --method scaling, minimum)"),
    "minwarping_cleaning": (3.2, None, "as minwarping"),
    "warping2d": (19.1, None, "measured 2026-11-28: 2D-warping single search at 288x50 (bench pairs, minimum)"),
    "warping1d": (23.2, None, "measured 2026-11-28: python -m bionav.bench --method scaling, warping1d at 288x50"),
    "hiss": (0.8, None, "measured 2026-11-28: python -m bionav.bench --method scaling, hiss at 288x50"),
    "minwarping_thesis": (7.6, None, "measured 2026-11-28: homing=minwarping_thesis (346x50, double and fine "
                                     "search) on the bench's pairs, CPU ms per home vector (minimum)"),
    "warping2d_thesis": (30.4, None, "measured 2026-11-28: homing=warping2d_thesis (346x50) on the bench's pairs"),
    "mfdid": (0.05, 288 * 50, "assumed: an image difference and two shifts per pair (not timed)"),
    "parameter": (0.02, None, "assumed: signature distances (not timed)"),
}
#: per-image work (CPU ms per image) of the methods that resize to their own size (measured with the figures above)
PREPARE_MS = {"minwarping": 1.0, "minwarping_cleaning": 1.0, "warping2d": 1.0, "warping1d": 0.3, "hiss": 18.0,
              "minwarping_thesis": 2.0, "warping2d_thesis": 2.0}
#: CPU seconds of starting one ``python -m bionav`` run (imports, Hydra, numba's cache, agents, plots, the run's
#: files), measured 2026-11-28: 3.9-4.2 s for a grid_homing run of one mfdid snapshot on sim_original at 64x16
RUN_START_S = 3.9
#: loading a database from the render cache, per million pixels of its images (measured 2026-11-28 with the
#: same one-snapshot mfdid run: sim_hall1 at 561x81, 7.7 Mpx, 5.8-6.1 s; sim_roeben1, 18 Mpx, 8.0 s)
DB_LOAD_S_PER_MPX = 0.22
#: SIFT's matching per home vector grows with the keypoints of both images (the candidates within the
#: radius, 22 % of the width, of each current keypoint), its detection per image with the pixels (less than
#: linearly); the keypoints per image hardly grow with the image size. Measured 2026-11-28 on sim_original
#: (python -m bionav.bench --method sift --sift-size W H at 561x81 and 1122x162, plain and histeq): 313 / 349
#: plain and 490 / 697 histeq keypoints, 2.3-3.5 ns per home vector and keypoint^2, 17.6 / 39.7 ms (plain) and
#: 24.9 / 52.8 ms (histeq) per image
SIFT_PAIR_NS_PER_KP2 = 2.9
SIFT_IMAGE_MS = {"plain": 39.7, "histeq": 52.8}
SIFT_IMAGE_EXPONENT = 0.6
SIFT_KEYPOINTS = {"plain": 349.0, "histeq": 697.0}
SIFT_REF_SIZE = (1122, 162)
SIFT_KEYPOINTS_EXPONENT = 0.15
SIFT_BASIS = "measured on sim_original at 561x81 and 1122x162 (python -m bionav.bench --method sift)"
#: rendering a stand-in: CPU seconds per image plus per million pixels (fitted 2026-11-28 to the quick preset's first
#: runs of each database on this machine, which render it: fig. 5.6's six databases at 346x50 in 108 s, sim_hall1
#: at 561x81 in about 25 s; worlds of other kinds, e.g. sim_roeben1's, take up to twice as long)
RENDER_S_PER_IMAGE = 0.1
RENDER_S_PER_MPX = 0.3
#: default image size of the stand-ins when a run names none (W, H)
DEFAULT_SIZE = (561, 81)
#: CPU seconds of one run of the experiments without home-vector counts (experiment -> (s, basis)); the
#: "measured" ones are the process CPU (os.wait4) of the quick preset's runs on the reference machine,
#: ``python -m bionav.thesis --preset quick --jobs 2``, 2026-11-28 (main at 3e0c917), start-up included
RUN_CPU_S: dict[str, tuple[float, str]] = {
    "param_sweep_job": (1.7, "measured: 28-37 s CPU for the 19 jobs of one ci-grid sweep (quick preset)"),
    "param_sweep_job_full": (2.1, "measured: 1.7 s per job on the ci grid plus 393 s CPU (AMD EPYC, scaled by its "
                                  "ratio to this machine, about 1.0) for the 15,606 configurations of three "
                                  "stand-ins (docs/performance.md section 6) over 3 x 342 jobs"),
    "cleaning_start": (13.0, "measured: 19-21 s CPU for 2 runs (quick preset), minus the runs"),
    "cleaning_run": (3.5, "measured: 35.3 s CPU for 10 runs of long_lanes (docs/performance.md section 0)"),
    "pol_compass": (5.0, "measured: 4-7 s CPU per mode (quick preset; the full preset's runs are the same)"),
    "contrast_lda_start": (3.9, "measured: 10-12 s CPU at 1000 resamples (quick preset): the start-up"),
    "contrast_lda_resample": (0.007, "and 7 ms per resample"),
    "contrast_scan_start": (3.9, "measured: 10-11 s CPU for one cloudy 57 x 13 scan and 26 s for 14 clear 38 x 9 "
                                 "scans (quick preset): the start-up"),
    "contrast_scan_direction": (0.0046, "and 4.6 ms per scan direction (the 14 scans of 38 x 9; the single 57 x 13 "
                                        "scans took 8.9 ms per direction: the plan is 30 % low for them)"),
    "skyline_homing_start": (3.9, "measured: 68 s CPU at snapshot_stride=4 (quick preset): the start-up"),
    "skyline_homing_stride4": (64.0, "and 64 s at stride 4, scaled by the snapshots (1 / stride^2)"),
    "standins": (60.0, "assumed"),
}
#: jobs of one parameter-sweep multirun per grid (19 signatures x sizes x preprocessings)
PARAM_SWEEP_JOBS = {"full": 342, "ci": 19}


@dataclass(frozen=True)
class TaskEstimate:
    """One task of the plan: its command, expected CPU seconds and their basis."""

    command: str
    experiment: str
    cpu_s: float
    basis: str
    render: tuple[str, ...]
    render_cpu_s: float


def _overrides(spec: RunSpec) -> dict[str, str]:
    return dict(o.lstrip("+~").partition("=")[::2] for o in spec.overrides)


def _items(text: str) -> list[str]:
    """The items of a list override value such as ``[a,b]`` or ``'[a, b]'``."""
    return [v.strip() for v in text.strip("[] '").split(",") if v.strip()]


def _ints(text: str) -> list[int]:
    return [int(v) for v in _items(text)]


#: grid assumed for a database whose preset gives no grid shape (a folder: known only once read)
ASSUMED_GRID = (10, 17)


def _size(ov: dict[str, str]) -> tuple[int, int]:
    if "db.image_size" in ov:
        w, h = _ints(ov["db.image_size"])
        return w, h
    return DEFAULT_SIZE


#: the calibration family each homing method's cost scales with (bionav.thesis.calibration.FAMILIES)
METHOD_FAMILY = {"sift": "sift", "minwarping": "minwarping", "minwarping_cleaning": "minwarping",
                 "minwarping_thesis": "minwarping", "warping2d": "warping2d", "warping2d_thesis": "warping2d",
                 "warping1d": "warping2d"}


def _factor(factors: dict | None, family: str) -> float:
    return 1.0 if factors is None else float(factors.get(family, 1.0))


def block_share(total: int, block: Sequence[int] | None) -> int:
    """How many of ``total`` items task ``block = [i, n]`` holds: every n-th from the i-th, as
    :func:`bionav.experiments.tasks.block_of` splits them (``ceil((total - i) / n)``, not ``ceil(total / n)``)."""
    if not block:
        return total
    i, n = int(block[0]), int(block[1])
    return len(range(i, total, n))


def keypoints_per_image(size: tuple[int, int], *, histeq: bool = False) -> float:
    """Expected SIFT keypoints per image at ``size`` (W, H): :data:`SIFT_KEYPOINTS` scaled as
    ``pixels ** SIFT_KEYPOINTS_EXPONENT`` (fitted to the stand-ins at 561 x 81 and 1122 x 162)."""
    kp, ref = SIFT_KEYPOINTS["histeq" if histeq else "plain"], SIFT_REF_SIZE[0] * SIFT_REF_SIZE[1]
    return kp * (size[0] * size[1] / ref) ** SIFT_KEYPOINTS_EXPONENT


def sift_costs(size: tuple[int, int], *, histeq: bool = False) -> tuple[float, float, str]:
    """SIFT's CPU ms per home vector (matching: grows with the keypoints of both images) and per image
    (detection: grows with the pixels), and their basis."""
    kp = keypoints_per_image(size, histeq=histeq)
    pair_ms = SIFT_PAIR_NS_PER_KP2 * kp * kp / 1e6
    ratio = size[0] * size[1] / (SIFT_REF_SIZE[0] * SIFT_REF_SIZE[1])
    image_ms = SIFT_IMAGE_MS["histeq" if histeq else "plain"] * ratio ** SIFT_IMAGE_EXPONENT
    return pair_ms, image_ms, (f"SIFT: {kp:.0f} keypoints per image expected, {SIFT_PAIR_NS_PER_KP2:g} ns per home "
                               f"vector and keypoint^2, {image_ms:.1f} ms per image; {SIFT_BASIS}")


def _hv_ms(homing: str, size: tuple[int, int], ov: dict[str, str]) -> tuple[float, float, str]:
    """CPU ms per home vector and per image (its per-image work, once per image of a run) and the basis."""
    if homing == "sift":
        return sift_costs(size, histeq=ov.get("preprocess", "none") not in ("none", "") and "he" in ov["preprocess"])
    ms, ref, basis = HOME_VECTOR_MS.get(homing, (10.0, None, f"assumed for the unknown method {homing!r}"))
    if ref is not None:
        ms *= size[0] * size[1] / ref
    return ms, PREPARE_MS.get(homing, 0.0), basis


def task_cpu_s(spec: RunSpec, factors: dict | None = None) -> TaskEstimate:
    """The expected CPU seconds of one task (a run or a block of a split run) and their basis.

    ``factors`` (:func:`bionav.thesis.calibration.factors`) scale the reference machine's figures to
    the machine planned for; None keeps the reference machine's.
    """
    ov = _overrides(spec)
    experiment = ov.get("experiment", "grid_homing")
    command = "python -m bionav " + (" -m " if spec.multirun else "") + " ".join(spec.overrides)
    start = RUN_START_S * _factor(factors, "python")
    if experiment in ("grid_homing", "cross_db"):
        return _pairs_task(experiment, ov, command, start, factors)
    f = _factor(factors, "python")
    if experiment == "param_sweep":
        grid = ov.get("experiment.grid", "full")
        jobs = PARAM_SWEEP_JOBS.get(grid, 342)
        s, basis = RUN_CPU_S["param_sweep_job" if grid == "ci" else "param_sweep_job_full"]
        return TaskEstimate(command, experiment, jobs * s * f, f"{jobs} jobs; {basis}", (ov.get("db", ""),), 0.0)
    if experiment == "cleaning":
        s0, basis0 = RUN_CPU_S["cleaning_start"]
        s, basis = RUN_CPU_S["cleaning_run"]
        runs = int(ov.get("runs", 10))
        return TaskEstimate(command, experiment, (s0 + runs * s) * f, f"{runs} runs; {basis0}; {basis}", (), 0.0)
    scaled = _scaled_run_cpu_s(experiment, ov)
    if scaled is not None:
        return TaskEstimate(command, experiment, scaled[0] * f, scaled[1], (), 0.0)
    s, basis = RUN_CPU_S.get(experiment, (60.0, f"assumed for {experiment}"))
    return TaskEstimate(command, experiment, s * f, basis, (), 0.0)


def _pairs_task(experiment: str, ov: dict[str, str], command: str, start: float, factors) -> TaskEstimate:
    """A grid-homing or cross-database task: start-up, per-image work, home vectors; its render."""
    homing = ov.get("homing", "sift")
    size = _size(ov)
    block = _ints(ov["experiment.block"]) if "experiment.block" in ov else None
    ms, image_ms, basis = _hv_ms(homing, size, ov)
    f = _factor(factors, METHOD_FAMILY.get(homing, "python"))
    render_f = _factor(factors, "python")
    if experiment == "grid_homing":
        db = ov.get("db", "sim_original")
        gx, gy, assumed = _grid_shape(db)
        n = gx * gy
        snaps = block_share(len(_ints(ov["experiment.snapshots"])) if "experiment.snapshots" in ov else n, block)
        mpx = n * size[0] * size[1] / 1e6
        load = mpx * DB_LOAD_S_PER_MPX * render_f
        render = (n * RENDER_S_PER_IMAGE + mpx * RENDER_S_PER_MPX) * render_f
        cpu = start + load + (snaps * n * ms + n * image_ms) / 1e3 * f
        return TaskEstimate(command, experiment, cpu, f"start-up {start:.1f} s, database {load:.1f} s; {snaps} x {n} "
                            f"home vectors{assumed}; {basis}", (db, f"{size[0]}x{size[1]}"), render)
    family = _items(ov.get("experiment.family", "[sim_original]"))
    stride = int(ov.get("experiment.snapshot_stride", 2))
    gx, gy, assumed = _grid_shape(family[0])
    n = gx * gy
    snaps, n_pairs = math.ceil(gx / stride) * math.ceil(gy / stride), len(family) ** 2
    if block and block[1] <= snaps:  # every n-th snapshot, all pairs (bionav.experiments.cross_db.task_units)
        hv, what = n_pairs * block_share(snaps, block) * n, f"{n_pairs} database pairs x {block_share(snaps, block)}"
    else:  # every n-th (snapshot, pair) unit
        units = block_share(snaps * n_pairs, block)
        hv, what = units * n, f"{units} (snapshot, database pair) units"
    mpx = len(family) * n * size[0] * size[1] / 1e6
    load = mpx * DB_LOAD_S_PER_MPX * render_f
    render = (len(family) * n * RENDER_S_PER_IMAGE + mpx * RENDER_S_PER_MPX) * render_f
    cpu = start + load + (hv * ms + len(family) * n * image_ms) / 1e3 * f
    return TaskEstimate(command, experiment, cpu, f"start-up {start:.1f} s, databases {load:.1f} s; {what} x {n} home "
                        f"vectors{assumed}; {basis}", tuple(sorted(family)) + (f"{size[0]}x{size[1]}",), render)


def _scaled_run_cpu_s(experiment: str, ov: dict[str, str]) -> tuple[float, str] | None:
    """Start-up plus a measured unit cost times the run's size, for the experiments whose size the
    overrides give (defaults: the experiment's config dataclass); None for the others."""
    if experiment not in ("contrast_lda", "contrast_scan", "skyline_homing"):
        return None
    d = _experiment_defaults(experiment)
    if experiment == "contrast_lda":
        n = int(ov.get("experiment.n_resamples", d["n_resamples"]))
        (s0, b0), (s1, b1) = RUN_CPU_S["contrast_lda_start"], RUN_CPU_S["contrast_lda_resample"]
        return s0 + n * s1, f"{n} resamples; {b0}, {b1}"
    if experiment == "contrast_scan":
        n_times = len(_items(ov["experiment.times"])) if "experiment.times" in ov else len(d["times"])
        n_dir = int(ov.get("experiment.n_pan", d["n_pan"])) * int(ov.get("experiment.n_tilt", d["n_tilt"]))
        (s0, b0), (s1, b1) = RUN_CPU_S["contrast_scan_start"], RUN_CPU_S["contrast_scan_direction"]
        return s0 + n_times * n_dir * s1, f"{n_times} scans x {n_dir} directions; {b0}, {b1}"
    stride = int(ov.get("experiment.snapshot_stride", d["snapshot_stride"]))  # skyline_homing
    (s0, b0), (s1, b1) = RUN_CPU_S["skyline_homing_start"], RUN_CPU_S["skyline_homing_stride4"]
    return s0 + s1 * (4 / stride) ** 2, f"snapshot_stride={stride}; {b0}, {b1}"


@functools.lru_cache(maxsize=None)
def _experiment_defaults(experiment: str) -> dict:
    """The ``experiment`` node of ``experiment=<name>`` as composed (its structured config's defaults)."""
    from omegaconf import OmegaConf

    from bionav.config import compose

    return OmegaConf.to_container(compose([f"experiment={experiment}"]).experiment, resolve=True)


@functools.lru_cache(maxsize=None)
def _grid_shape(db: str) -> tuple[int, int, str]:
    """``db``'s grid shape from its preset, or :data:`ASSUMED_GRID` with a note where the preset
    gives none (an estimate must never stop a run)."""
    from bionav.errors import UserError
    from bionav.thesis.databases import db_meta

    try:
        shape = db_meta(db)["grid_shape"]
    except (UserError, LookupError, ValueError, OSError, ImportError) as exc:  # e.g. no such preset
        shape, why = None, f"{type(exc).__name__}"
    else:
        why = "no grid_shape in its preset"
    if not shape:
        nx, ny = ASSUMED_GRID
        return nx, ny, f" (grid of {db} assumed {nx} x {ny}: {why})"
    return int(shape[0]), int(shape[1]), ""


def make_plan(specs: Iterable[RunSpec], *, nodes: int, cores: int, factors: dict | None = None) -> dict[str, Any]:
    """The tasks of ``specs`` with their CPU, the critical path and the expected wall time.

    Parameters
    ----------
    specs : iterable of RunSpec
        The runs of the selected items (duplicates counted once).
    nodes, cores : int
        Machines and cores per machine; every task takes one core.
    factors : dict, optional
        Per calibration family the factor to the machine planned for
        (:func:`bionav.thesis.calibration.factors`); None plans for the reference machine.

    Returns
    -------
    dict
        ``tasks`` (list of :class:`TaskEstimate` as dicts), ``n_tasks``, ``largest_task_cpu_s``,
        ``total_cpu_s`` (tasks and renders), ``critical_path_s``, ``expected_wall_s``, ``slots``,
        ``cpu_factors`` (the factors and their source).
    """
    unique: dict[str, RunSpec] = {}
    for s in specs:
        unique.setdefault(s.key, s)
    tasks = [task_cpu_s(t, factors) for s in unique.values() for t in s.tasks()]
    renders: dict[tuple[str, ...], float] = {}
    for t in tasks:
        if t.render:
            renders[t.render] = max(renders.get(t.render, 0.0), t.render_cpu_s)
    slots = max(1, nodes * cores)
    # renders first (longest first), then the tasks longest first, each on the earliest free slot and
    # not before its render is done
    free = [0.0] * slots
    heapq.heapify(free)
    ready: dict[tuple[str, ...], float] = {}
    for key, cpu in sorted(renders.items(), key=lambda kv: -kv[1]):
        start = heapq.heappop(free)
        ready[key] = start + cpu
        heapq.heappush(free, start + cpu)
    end = 0.0
    pending = sorted(tasks, key=lambda t: -t.cpu_s)
    while pending:  # the earliest free core takes the longest task whose render is done (else the first ready)
        at = heapq.heappop(free)
        pick = next((t for t in pending if ready.get(t.render, 0.0) <= at), None)
        if pick is None:
            pick = min(pending, key=lambda t: ready.get(t.render, 0.0))
        pending.remove(pick)
        start = max(at, ready.get(pick.render, 0.0))
        heapq.heappush(free, start + pick.cpu_s)
        end = max(end, start + pick.cpu_s)
    critical = max((renders.get(t.render, 0.0) + t.cpu_s for t in tasks), default=0.0)  # on unlimited cores
    return {
        "tasks": [asdict(t) for t in tasks],
        "n_tasks": len(tasks),
        "largest_task_cpu_s": max((t.cpu_s for t in tasks), default=0.0),
        "total_cpu_s": sum(t.cpu_s for t in tasks) + sum(renders.values()),
        "critical_path_s": critical,
        "expected_wall_s": max(end, critical),
        "slots": slots,
        "nodes": nodes,
        "cores": cores,
        "cpu_factors": factors or {"source": "the reference machine's figures, unscaled"},
    }


def format_plan(plan: dict[str, Any], *, preset: str, top: int = 15) -> str:
    """A human-readable summary: the totals and the ``top`` largest tasks."""
    h = 3600.0
    lines = [
        f"plan for --preset {preset} on {plan['nodes']} node(s) x {plan['cores']} core(s) ({plan['slots']} slots, one "
        f"task per core; CPU figures measured on the reference machine or assumed, as each task's basis says, scaled "
        f"by {plan['cpu_factors']['source']}):",
        f"  tasks: {plan['n_tasks']}",
        f"  total CPU: {plan['total_cpu_s'] / h:.1f} h",
        f"  largest task: {plan['largest_task_cpu_s'] / 60:.1f} min CPU",
        f"  critical path: {plan['critical_path_s'] / 60:.1f} min",
        f"  expected wall time: {plan['expected_wall_s'] / h:.2f} h",
        f"largest tasks (of {plan['n_tasks']}):",
    ]
    for t in sorted(plan["tasks"], key=lambda t: -t["cpu_s"])[:top]:
        lines.append(f"  {t['cpu_s'] / 60:8.1f} min  {t['command']}")
        lines.append(f"               ({t['basis']})")
    return "\n".join(lines)


def plan_for(specs: Sequence[RunSpec], *, nodes: int, cores: int, factors: dict | None = None) -> dict[str, Any]:
    """:func:`make_plan` with the arguments checked (one message naming the bad one)."""
    from bionav.errors import UserError

    if not 1 <= nodes <= 100_000:
        raise UserError(f"--nodes {nodes} is out of range; give 1 or more machines, e.g. --nodes 8.")
    if not 1 <= cores <= 10_000:
        raise UserError(f"--cores {cores} is out of range; give the cores per machine, e.g. --cores 16.")
    return make_plan(specs, nodes=nodes, cores=cores, factors=factors)
