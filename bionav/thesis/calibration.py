"""How fast this machine runs bionav's kernels, relative to the machine the plan's figures come from.

The plan's unit costs (:mod:`bionav.thesis.plan`) are CPU times measured on one machine, the
*reference machine* (:data:`REFERENCE`). Another machine runs the same work faster or slower, and
not by one factor: the warping kernels follow the vector units, SIFT matching the float32 dot
products, the Python parts the scalar core. A **calibration** times four short workloads (about
two seconds of CPU in all) on the machine at hand:

* ``minwarping``: min-warping home vectors of a synthetic pair at 288 x 50 (96 x 96 steps);
* ``warping2d``: 2D-warping home vectors of the same pair;
* ``sift``: neighbourhood matching of two synthetic sets of 700 keypoints (integer descriptors);
* ``python``: a loop of small NumPy operations (the start-up and bookkeeping of a run);

each the minimum CPU time (``time.process_time``) over a few repetitions, so that other processes
on the machine change it little. A family's **factor** is its time here over the reference
machine's; a task's cost in the plan is the reference cost times the factor of its family.

The calibration is cached per CPU (model name, numba's target CPU and a digest of the kernels'
sources) as JSON in ``<cache dir>/calibration/`` (``$BIONAV_CACHE`` or ``~/.cache/bionav``), so a
plan calibrates once per machine. ``python -m bionav.thesis --calibrate`` prints it (and refreshes
the cache); the file is what ``--calibration FILE`` reads to plan for that other machine, and
``--cpu-factor F`` scales every family by ``F`` instead.
"""

from __future__ import annotations

import hashlib
import json
import re
import time
from pathlib import Path
from typing import Any

import numpy as np

#: the calibration workloads' CPU ms on the reference machine, where the plan's unit costs were measured
#: (the minimum of three calibrations, 2026-11-28, numba 0.68.1, native code, load average 15-17 from other work)
REFERENCE: dict[str, Any] = {
    "machine": "Intel(R) Xeon(R) Processor (Emerald Rapids, AVX-512), 2 vCPUs",
    "cpu": "emeraldrapids",
    "minwarping": 5.55,
    "warping2d": 19.1,
    "sift": 1.70,
    "python": 7.17,
}
#: the families a factor is given for, and the plan's methods in each
FAMILIES = ("minwarping", "warping2d", "sift", "python")
#: bumped when the workloads change (older cache files are then ignored)
VERSION = 1


def _pair():
    """Two synthetic 288 x 50 panoramas (smooth random texture, the second one shifted and rolled)."""
    from bionav.geometry import PanoramaGeometry

    rng = np.random.default_rng(42)
    noise = rng.random((50, 288 + 16)).astype(np.float32)
    kernel = np.ones(9, np.float32) / 9.0
    smooth = np.apply_along_axis(lambda r: np.convolve(r, kernel, mode="valid"), 1, noise)[:, :288]
    snap = (smooth - smooth.min()) / np.ptp(smooth)
    cur = np.roll(snap, 17, axis=1) * 0.8 + 0.1
    return snap, cur, PanoramaGeometry.square_pixels(288, 50)


def _min_cpu_ms(fn, repeat: int) -> float:
    fn()  # warm-up: compilation, caches
    best = float("inf")
    for _ in range(repeat):
        c0 = time.process_time()
        fn()
        best = min(best, time.process_time() - c0)
    return 1e3 * best


def _workloads():
    from bionav.homing.features import SiftFeatures
    from bionav.homing.sift_homing import column_index, match_in_neighbourhood
    from bionav.homing.warping import minwarping, scale_plane_stack, warping2d

    snap, cur, geo = _pair()
    s, c = scale_plane_stack(snap, geometry=geo), scale_plane_stack(cur, geometry=geo)
    rng = np.random.default_rng(7)

    def features(n=700):
        xy = np.column_stack([rng.random(n) * 1122, rng.random(n) * 162]).astype(np.float32)
        d = rng.integers(0, 256, (n, 128)).astype(np.float32)
        return column_index(SiftFeatures(xy, d, (d * d).sum(axis=1), width=np.asarray(1122)))

    fa, fb = features(), features()
    small = rng.random(64)

    def python_loop():
        total = 0.0
        for i in range(2000):
            total += float(np.sum(small * i)) + len(str(i))
        return total

    return {
        "minwarping": (lambda: minwarping(s, c), 8),
        "warping2d": (lambda: warping2d(s, c), 3),
        "sift": (lambda: match_in_neighbourhood(fa, fb, radius=247.0, width=1122), 5),
        "python": (python_loop, 5),
    }


def run_calibration() -> dict[str, Any]:
    """Time the workloads on this machine: ``{family: CPU ms, ..., "machine", "cpu", "version"}``."""
    from bionav.bench.cpu import numba_target
    from bionav.machine import cpu_model, machine_label

    out: dict[str, Any] = {f: round(_min_cpu_ms(fn, n), 4) for f, (fn, n) in _workloads().items()}
    out.update(machine=f"{cpu_model()}, {machine_label()}", cpu=numba_target()["cpu"], version=VERSION)
    return out


def _kernels_digest() -> str:
    """A digest of the kernels' sources: a calibration is stale once they change."""
    from bionav.homing import sift_kernels
    from bionav.homing.warping import distance, kernels, vkernels

    h = hashlib.sha256()
    for mod in (kernels, vkernels, distance, sift_kernels):
        h.update(Path(mod.__file__).read_bytes())
    return h.hexdigest()[:10]


def cache_path() -> Path:
    """This machine's calibration file: ``<cache dir>/calibration/<cpu model>-<numba cpu>-<kernels>.json``."""
    from bionav.bench.cpu import numba_target
    from bionav.files import default_cache_dir
    from bionav.machine import cpu_model

    slug = re.sub(r"[^A-Za-z0-9._-]+", "_", cpu_model()).strip("_")[:80] or "cpu"
    return default_cache_dir() / "calibration" / f"{slug}-{numba_target()['cpu']}-v{VERSION}-{_kernels_digest()}.json"


def machine_calibration(*, refresh: bool = False) -> dict[str, Any]:
    """This machine's calibration, from the cache or measured now (and cached); ``refresh`` measures anew."""
    from bionav.files import write_json_atomic

    path = cache_path()
    if not refresh:
        try:
            return check_calibration(json.loads(path.read_text(encoding="utf-8")), str(path))
        except (OSError, ValueError):
            pass  # none yet, or unreadable: measure
    cal = run_calibration()
    try:
        write_json_atomic(path, cal)
    except OSError:  # a read-only cache only costs the next plan two seconds
        pass
    return cal


def check_calibration(data: Any, source: str) -> dict[str, Any]:
    """``data`` as a calibration (every family a positive number), or ValueError naming ``source``."""
    if not isinstance(data, dict):
        raise ValueError(f"{source} is not a calibration (a JSON object of CPU ms per family)")
    bad = [f for f in FAMILIES if not isinstance(data.get(f), (int, float)) or not 0 < float(data[f]) < 1e6]
    if bad:
        raise ValueError(f"{source} lacks a positive CPU time for {', '.join(bad)}")
    return data


def load_calibration(path: str) -> dict[str, Any]:
    """A calibration file written on another machine (``python -m bionav.thesis --calibrate --json``)."""
    from bionav.errors import UserError
    from bionav.files import user_path

    p = user_path(path)
    try:
        return check_calibration(json.loads(p.read_text(encoding="utf-8")), str(p))
    except OSError as exc:
        raise UserError(f"--calibration {path}: cannot read it ({exc.strerror or exc}); write one on the machine "
                        "to plan for with `python -m bionav.thesis --calibrate --json > FILE`.") from None
    except ValueError as exc:
        raise UserError(f"--calibration {path}: {exc}; write one with `python -m bionav.thesis --calibrate "
                        "--json > FILE` on the machine to plan for.") from None


def factors(calibration: dict[str, Any] | None = None, *, cpu_factor: float | None = None) -> dict[str, Any]:
    """Per family the factor from the reference machine's CPU time to the planned machine's.

    ``cpu_factor`` gives every family that factor; otherwise ``calibration`` (default: this machine's,
    :func:`machine_calibration`) over :data:`REFERENCE`. The result also holds ``"source"``, a line
    saying where the factors come from.
    """
    if cpu_factor is not None:
        return {**{f: float(cpu_factor) for f in FAMILIES}, "source": f"--cpu-factor {cpu_factor:g}"}
    cal = machine_calibration() if calibration is None else calibration
    out: dict[str, Any] = {f: float(cal[f]) / float(REFERENCE[f]) for f in FAMILIES}
    out["source"] = (f"calibration of {cal.get('machine', 'a machine')} against {REFERENCE['machine']}: "
                     + ", ".join(f"{f} x{out[f]:.2f}" for f in FAMILIES))
    return out
