"""``python -m bionav.bench``'s whole-grid timings: ``--grid DB`` (min-warping) and ``--method sift``.

Databases are loaded the way the experiments load them (composed configs,
:func:`bionav.experiments.common.load_configured_database`), and the home
vectors of all pairs come from the grid runner
(:func:`bionav.evaluation.pairs.home_vector_matrix`) with 1 worker and with
``--threads`` workers in alternate rounds; per-image work is done once
beforehand and timed separately. Times are process CPU time (all threads)
and wall time, in ms per home vector unless the key says ``_s``.
"""

from __future__ import annotations

import os
import time

import numpy as np

from bionav.bench.background_load import start_load, stop_load
from bionav.bench.pairs import MINWARPING_VARIANTS, plugin
from bionav.errors import UserError
from bionav.machine import machine_label

#: timed over a whole grid (``--method sift``), not per pair of the pillar room; not part of ``all``
GRID_METHODS = ("sift",)
SIFT_VARIANTS = ("plain", "histeq")


def grid_rows(args, load_procs_n: int) -> list[dict]:
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
        method, steps = plugin("minwarping", options, args, db.geometry)
        prepared = prepare_images(method, list(db.images), workers=args.threads)
        home_vector_matrix(method, db, snapshot_index=snapshots[:1], workers=args.threads,
                           prepared=(prepared, prepared))  # warm-up: compilation, templates
        runs.append({"variant": variant, "method": method, "prepared": prepared, "steps": steps,
                     "cpu": {w: [] for w in counts}, "wall": {w: [] for w in counts}, "n": 0})
    load = start_load(load_procs_n)
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
        stop_load(load)
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
                "machine": machine_label(),
                **numba_target(),
            })
    return rows


def sift_rows(args, variants) -> list[dict]:
    """Time SIFT homing over a grid per variant: per-image work and all pairs, CPU and wall time."""
    rows = []
    load = start_load(args.background_load)
    try:
        for variant in variants:
            rows += _sift_variant_rows(args, variant)
    finally:
        stop_load(load)
    return rows


def _sift_database(args, variant: str):
    """The ``--db`` database at ``--sift-size`` with the variant's preprocessing; its load time in s."""
    from bionav.config import compose
    from bionav.experiments.common import load_configured_database

    w_img, h_img = args.sift_size
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
    return db, load_s


def _sift_variant_rows(args, variant: str) -> list[dict]:
    """One variant of ``--method sift``: SIFT features of every image, then all pairs in alternate rounds."""
    from bionav.bench.cpu import numba_target
    from bionav.evaluation.pairs import home_vector_matrix, prepare_images
    from bionav.plugins.homing.sift import SiftConfig, SiftHoming

    w_img, h_img = args.sift_size
    db, load_s = _sift_database(args, variant)
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
    rows = []
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
            "machine": machine_label(),
            **numba_target(),
        })
    return rows
