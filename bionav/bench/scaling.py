"""``python -m bionav.bench --method scaling``: how the CPU time grows with the image and with the grid.

Two kinds of rows (``"table"``):

* ``pairs``: for each pair method (min-warping and 2D-warping single search, 1D warping, HiSS,
  SIFT) and each size of ``--scaling-sizes`` (default 144x25, 288x50, 576x100) the CPU ms per home
  vector on the bench's pillar-room pairs (rendered at twice the size; per-image work excluded,
  minimum and median over ``--repeat`` rounds of ``--batch`` home vectors), the CPU ms of the
  per-image work, and ``growth_exponent``: ``log(cpu / cpu_before) / log(pixels / pixels_before)``
  against the size before (min-warping's distances grow as ``W^2 H``, i.e. pixels^1.5 at a fixed
  aspect ratio). The warping methods keep ``--steps`` search steps at every size.
* ``runs``: the whole command ``python -m bionav experiment=grid_homing homing=M db=DB`` (``--db``,
  ``--override KEY=VALUE`` added, render cache as it is) with 1 snapshot and with ``--scaling-snapshots`` snapshots, for min-warping
  and SIFT: CPU seconds of the process (``RUSAGE_CHILDREN``), home vectors, and the line through both
  points: ``cpu_ms_per_home_vector`` (its slope) and ``fixed_cpu_s`` (its intercept: start-up, the
  database, per-image work, agents and plots: what a run costs before its first home vector).
"""

from __future__ import annotations

import math
import os
import tempfile
import time
from pathlib import Path

import numpy as np

from bionav.bench.pairs import POSES, plugin, time_batch
from bionav.machine import machine_label

SCALING_METHODS = ("minwarping", "warping2d", "warping1d", "hiss", "sift")
DEFAULT_SIZES = "144x25,288x50,576x100"
RUN_METHODS = ("minwarping", "sift")


def parse_sizes(text: str) -> list[tuple[int, int]]:
    """``"144x25,288x50"`` -> ``[(144, 25), (288, 50)]``; ValueError naming the bad item."""
    sizes = []
    for item in (t.strip() for t in text.split(",")):
        w, _, h = item.lower().partition("x")
        if not (w.isdigit() and h.isdigit()) or not (16 <= int(w) <= 2048 and 8 <= int(h) <= 512) or int(w) % 2:
            raise ValueError(f"{item!r} is not a size WxH with an even W in 16..2048 and H in 8..512")
        sizes.append((int(w), int(h)))
    if not sizes:
        raise ValueError("no size given")
    return sizes


def _method(name: str, args, size, geometry):
    if name == "sift":
        from bionav.plugins.homing.sift import SiftConfig, SiftHoming

        return SiftHoming(SiftConfig(image_size=list(size)), geometry=geometry)
    a = _Args(size=list(size), steps=min(args.steps, size[0]), compass_fraction=args.compass_fraction)
    return plugin(name, {}, a, geometry)[0]


class _Args:
    def __init__(self, **kw) -> None:
        self.__dict__.update(kw)


def _pair_row(name: str, size, args, pool, batch: int) -> dict:
    from bionav.testing.pillar_scene import render_pillar_panorama

    rw, rh = 2 * size[0], 2 * size[1]
    snap, geometry = render_pillar_panorama((0.0, 0.0), width=rw, height=rh, supersample=2)
    currents = [render_pillar_panorama(p, heading=h, width=rw, height=rh, supersample=2)[0] for p, h in POSES]
    method = _method(name, args, size, geometry)
    method.prepare(currents[0])  # warm-up of the per-image work (compilation)
    c0 = time.process_time()
    s = method.prepare(snap)
    prep_ms = 1e3 * (time.process_time() - c0)
    pairs = [(s, method.prepare(c)) for c in currents]
    time_batch(pool, 1, method, pairs, 2)  # warm-up: compilation, templates
    cpu = [1e3 * time_batch(pool, 1, method, pairs, batch)[0] / batch for _ in range(args.repeat)]
    row = {"table": "pairs", "method": name, "image": f"{size[0]}x{size[1]}", "pixels": size[0] * size[1],
           "cpu_ms_per_home_vector": round(float(np.median(cpu)), 4), "cpu_ms_min": round(float(np.min(cpu)), 4),
           "prepare_cpu_ms_per_image": round(prep_ms, 3)}
    if name == "sift":
        row["keypoints_per_image"] = round(float(np.mean([len(p[1].xy) for p in pairs])), 1)
    return row


def pair_scaling_rows(args, sizes) -> list[dict]:
    """The ``pairs`` rows: every method at every size, with the growth exponent against the size before."""
    from concurrent.futures import ThreadPoolExecutor

    rows = []
    batch = args.batch if args.batch is not None else 6
    with ThreadPoolExecutor(1) as pool:
        for name in SCALING_METHODS:
            before = None
            for size in sizes:
                row = _pair_row(name, size, args, pool, batch)
                if before is not None and row["pixels"] != before["pixels"] and before["cpu_ms_min"] > 0:
                    row["growth_exponent"] = round(math.log(row["cpu_ms_min"] / before["cpu_ms_min"])
                                                   / math.log(row["pixels"] / before["pixels"]), 3)
                rows.append(row)
                before = row
    return rows


def run_scaling_rows(args) -> list[dict]:
    """The ``runs`` rows: whole grid-homing runs with 1 and ``--scaling-snapshots`` snapshots."""
    from bionav.bench.runs import _run

    rows = []
    with tempfile.TemporaryDirectory(prefix="bionav-scaling-") as tmp:
        tmp = Path(tmp)
        for name in RUN_METHODS:
            points = []
            for k in (1, args.scaling_snapshots):
                snaps = ",".join(str(i) for i in range(k))
                command = ["experiment=grid_homing", f"homing={name}", f"db={args.db}", f"experiment.snapshots=[{snaps}]",
                           "workers=1", f"hydra.run.dir={tmp / f'{name}{k}'}", *args.override]
                wall, cpu = _run(command, cwd=tmp, env=dict(os.environ))
                points.append((_home_vectors(tmp / f"{name}{k}"), cpu, wall))
            (h1, c1, _), (h2, c2, w2) = points
            slope = (c2 - c1) / (h2 - h1) if h2 > h1 else float("nan")
            rows.append({"table": "runs", "method": name, "db": args.db, "snapshots": [1, args.scaling_snapshots],
                         "home_vectors": [h1, h2], "cpu_s": [round(c1, 2), round(c2, 2)],
                         "cpu_ms_per_home_vector": round(1e3 * slope, 4), "fixed_cpu_s": round(c1 - slope * h1, 2),
                         "command": "python -m bionav " + " ".join(c for c in command if "dir=" not in c)})
    return rows


def _home_vectors(run_dir: Path) -> int:
    """Home vectors of a grid-homing run (its metrics.json's ``n_pairs``)."""
    import json

    return int(json.loads((run_dir / "metrics.json").read_text())["n_pairs"])


def scaling_rows(args) -> list[dict]:
    """Both tables (``--scaling-runs 0`` leaves out the whole runs), with the machine's state."""
    from bionav.bench.cpu import numba_target

    sizes = parse_sizes(args.scaling_sizes)
    load0 = os.getloadavg()[0]
    rows = pair_scaling_rows(args, sizes)
    if args.scaling_runs:
        rows += run_scaling_rows(args)
    common = {"loadavg_1min": [round(load0, 2), round(os.getloadavg()[0], 2)], "machine": machine_label(),
              **numba_target()}
    return [{**r, **common} for r in rows]
