"""How fast a machine runs bionav's kernels, relative to the machine the plan's figures come from.

The plan's unit costs (:mod:`bionav.thesis.plan`) are CPU times measured on one machine, the
*reference machine* (:data:`REFERENCE`). Another machine runs the same work faster or slower, and
not by one factor: the warping kernels follow the vector units, SIFT matching the float32 dot
products, the Python parts the scalar core. A **calibration** times four short workloads (about
two seconds of CPU in all) on the machine at hand, one per family: ``python -m bionav.bench --method
calibrate --json`` (:mod:`bionav.bench.calibration`), run as a command like the thesis' other runs.
A family's **factor** is its time there over the reference machine's; a task's cost in the plan is
the reference cost times the factor of its family.

The calibration is cached per CPU (model name, numba's target CPU and a digest of the kernels'
sources) as JSON in ``<cache dir>/calibration/`` (``$BIONAV_CACHE`` or ``~/.cache/bionav``), so a
plan calibrates once per machine. ``python -m bionav.thesis --calibrate`` prints it (and refreshes
the cache); the file is what ``--calibration FILE`` reads to plan for that other machine, and
``--cpu-factor F`` scales every family by ``F`` instead.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

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


def _kernels_digest() -> str:
    """A digest of the kernels' sources (read as files): a calibration is stale once they change."""
    root = Path(__file__).resolve().parents[1]
    h = hashlib.sha256()
    for rel in ("homing/warping/kernels.py", "homing/warping/vkernels.py", "homing/warping/distance.py",
                "homing/sift_kernels.py", "bench/calibration.py"):
        try:
            h.update((root / rel).read_bytes())
        except OSError:
            h.update(rel.encode())
    return h.hexdigest()[:10]


def cache_path() -> Path:
    """This machine's calibration file: ``<cache dir>/calibration/<cpu model>-<numba cpu>-<kernels>.json``."""
    from bionav.files import default_cache_dir
    from bionav.machine import cpu_model

    slug = re.sub(r"[^A-Za-z0-9._-]+", "_", cpu_model()).strip("_")[:80] or "cpu"
    target = re.sub(r"[^A-Za-z0-9._-]+", "_", os.environ.get("NUMBA_CPU_NAME") or "host")
    return default_cache_dir() / "calibration" / f"{slug}-{target}-v{VERSION}-{_kernels_digest()}.json"


def measure_machine() -> dict[str, Any]:
    """Time the workloads on this machine (``python -m bionav.bench --method calibrate --json``)."""
    from bionav.errors import UserError

    proc = subprocess.run([sys.executable, "-m", "bionav.bench", "--method", "calibrate", "--json"],
                          capture_output=True, text=True, timeout=600)
    try:
        if proc.returncode != 0:
            raise ValueError(f"status {proc.returncode}")
        return check_calibration(json.loads(proc.stdout.strip().splitlines()[-1]), "the calibration")
    except (ValueError, IndexError):
        tail = (proc.stderr.strip().splitlines() or ["no message"])[-1]
        raise UserError(f"calibrating this machine failed ({tail}); plan with --cpu-factor F instead, or run "
                        "`python -m bionav.bench --method calibrate` to see why.") from None


def machine_calibration(*, refresh: bool = False) -> dict[str, Any]:
    """This machine's calibration, from the cache or measured now (and cached); ``refresh`` measures anew."""
    from bionav.files import write_json_atomic

    path = cache_path()
    if not refresh:
        try:
            return check_calibration(json.loads(path.read_text(encoding="utf-8")), str(path))
        except (OSError, ValueError):
            pass  # none yet, or unreadable: measure
    cal = measure_machine()
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
