"""``python -m bionav.bench``'s per-pair timings: home vectors between views of the pillar room.

The snapshot is a ray-cast panorama of the pillar test room
(:mod:`bionav.testing.pillar_scene`) at the origin, the current views lie at
the displacements and headings of :data:`POSES` (metres, radians counter-clockwise
from east). Per-image work (``prepare``) is timed separately; every round runs
one batch of home vectors per variant on worker threads and records the process
CPU time and the wall time per home vector (ms). ``--reference`` interleaves a
round of an external program on the same 8-bit images.
"""

from __future__ import annotations

import json
import os
import subprocess
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

from bionav.bench.background_load import start_load, stop_load
from bionav.errors import UserError
from bionav.machine import machine_label

METHODS = ("minwarping", "warping2d", "warping1d", "hiss")

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


def variants(name: str):
    """The variants timed for method ``name``: ``((variant, plugin options), ...)``."""
    if name == "minwarping":
        return MINWARPING_VARIANTS
    if name == "warping2d":
        return WARPING2D_VARIANTS
    return (("single", {}),)


def plugin(name: str, options: dict, args, geometry):
    """The homing plugin ``name`` for the benchmark's arguments and its steps label (``"24x24"``, ``"-"``)."""
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


def time_batch(pool, threads: int, method, pairs, n: int):
    """Run ``n`` home vectors on ``threads`` workers; return (cpu s, wall s)."""
    chunks = [range(t, n, threads) for t in range(threads)]

    def work(chunk):
        for i in chunk:
            s, c = pairs[i % len(pairs)]
            method.home_vector(s, c)

    c0, t0 = time.process_time(), time.perf_counter()
    list(pool.map(work, chunks))
    return time.process_time() - c0, time.perf_counter() - t0


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
        proc = subprocess.run([*command, str(folder), str(batch)], capture_output=True, text=True, errors="replace", timeout=3600)
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


def pair_rows(args, batch: int) -> list[dict]:
    """Time the pair methods on the pillar room (and the ``--reference`` command); one row per variant."""
    snap, currents, geometry, reference = _pair_inputs(args)
    runs = _prepared_runs(args, snap, currents, geometry)
    load_before, load_after = _time_rounds(args, runs, reference, batch)

    from bionav.bench.cpu import numba_target

    target = numba_target()
    common = {"threads": args.threads, "rounds": args.repeat, "home_vectors_per_round": batch, "pairs": args.pairs,
              "background_load": args.background_load, "loadavg_1min": [round(load_before, 2), round(load_after, 2)],
              "machine": machine_label(), **target}
    return [_pair_row(run, args, common, reference) for run in runs]


def _pair_inputs(args):
    """Snapshot, current views and geometry (8-bit at ``--size`` with ``--reference``), and the reference's state."""
    import shlex
    import tempfile

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
    return snap, currents, geometry, reference


def _prepared_runs(args, snap, currents, geometry) -> list[dict]:
    """One run per method and variant: the plugin, its prepared pairs and the timing of ``prepare``."""
    names = METHODS if args.method == "all" else (args.method,)
    runs = []
    for name in names:
        for variant, options in variants(name):
            method, steps = plugin(name, options, args, geometry)
            t0 = time.process_time()
            s = method.prepare(snap)
            prep_ms = 1e3 * (time.process_time() - t0)
            pairs = [(s, method.prepare(c)) for c in currents]
            runs.append({"method": name, "variant": variant, "obj": method, "pairs": pairs, "steps": steps,
                         "prepare_cpu_ms": prep_ms, "cpu": [], "wall": []})
    return runs


def _time_rounds(args, runs: list[dict], reference, batch: int) -> tuple[float, float]:
    """Warm up, then ``--repeat`` interleaved rounds (and reference rounds); the load averages before and after."""
    load = start_load(args.background_load)
    try:
        with ThreadPoolExecutor(args.threads) as pool:
            for run in runs:  # warm-up: compilation, templates, caches
                time_batch(pool, args.threads, run["obj"], run["pairs"], max(args.threads, 2))
            load_before = os.getloadavg()[0]
            for _ in range(args.repeat):
                for run in runs:
                    cpu, wall = time_batch(pool, args.threads, run["obj"], run["pairs"], batch)
                    run["cpu"].append(1e3 * cpu / batch)
                    run["wall"].append(1e3 * wall / batch)
                if reference is not None:  # interleaved: one reference round after each bionav round
                    got = _reference_round(reference["command"], Path(reference["dir"].name), batch)
                    for v in reference["cpu"]:
                        reference["cpu"][v].append(got.get(v, float("nan")))
            load_after = os.getloadavg()[0]
    finally:
        stop_load(load)
        if reference is not None:
            reference["dir"].cleanup()
    return load_before, load_after


def _pair_row(run: dict, args, common: dict, reference) -> dict:
    """The output row of one timed run: medians and minima in ms per home vector, the reference's beside."""
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
    return row
