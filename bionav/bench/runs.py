"""Whole-run benchmarks of ``python -m bionav.bench``: ``--method sweep`` and ``--method cleaning``.

Each runs the documented ``python -m bionav`` command in a subprocess (in a
temporary directory, removed afterwards) and reports its wall time and the
CPU time of the subprocess and every process it waited for (its worker
processes included; ``resource.getrusage(RUSAGE_CHILDREN)``), with the
1-minute load average before and after, and what the run's ``metrics.json``
says about its own parts (render time, per-run seconds).

* ``sweep``: ``python -m bionav -m experiment=param_sweep_grid db=<dbs>``,
  the thesis' parameter sweep (thesis 5.2.1, tables 5.5-5.7; 5,202
  configurations per database with ``--sweep-grid full``). ``--cold`` gives the run
  an empty render cache (the stand-ins are rendered first, timed separately).
* ``cleaning``: ``python -m bionav experiment=cleaning runs=<runs>`` with
  rendered vision (thesis chapter 7).
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bionav.errors import UserError
from bionav.machine import machine_label

RUN_METHODS = ("sweep", "cleaning")
#: at most this many worker processes (each a Python process with its own numba and images)
MAX_WORKERS = 256
MAX_RUNS = 1000


def config_names(group: str) -> list[str]:
    """Names of the packaged configs of one group (``bionav/conf/<group>/*.yaml``)."""
    folder = Path(__file__).resolve().parent.parent / "conf" / group
    return sorted(p.stem for p in folder.glob("*.yaml"))


def check_arguments(parser, args) -> None:
    """The whole-run options against their bounds and the packaged names, before any work."""
    from bionav.bench._cli import bounded_int

    bounded_int(parser, "--workers", args.workers, 1, MAX_WORKERS)
    bounded_int(parser, "--runs", args.runs, 1, MAX_RUNS)
    dbs = [d.strip() for d in args.dbs.split(",") if d.strip()]
    if not dbs:
        parser.error(f"--dbs {args.dbs!r} names no database; e.g. --dbs sim_original,sim_hall1,sim_uni")
    known = config_names("db")
    bad = [d for d in dbs if d not in known]
    if bad:
        parser.error(f"--dbs: no database config named {', '.join(bad)}; choose from {', '.join(known)}")
    layouts = config_names("layout")
    if args.layout not in layouts:
        parser.error(f"--layout {args.layout!r} is not a layout; choose one of {', '.join(layouts)}")
    for item in args.override:
        if "=" not in item or item.startswith("="):
            parser.error(f"--override {item!r} is not KEY=VALUE; e.g. --override layout.n_lanes=3")


def add_arguments(parser) -> None:
    """The options of the whole-run benchmarks."""
    group = parser.add_argument_group("--method sweep / cleaning (whole runs of python -m bionav)")
    group.add_argument("--sweep-grid", choices=("full", "ci"), default="full",
                       help="sweep: the parameter grid (default: full, 5202 configurations per database)")
    group.add_argument("--dbs", default="sim_original,sim_hall1,sim_uni",
                       help="sweep: comma-separated databases (default: the thesis' three stand-ins)")
    group.add_argument("--cold", action="store_true",
                       help="sweep: start from an empty render cache (the stand-ins are rendered in the run)")
    group.add_argument("--workers", type=int, default=2,
                       help="sweep / cleaning: worker processes of the run (default: 2)")
    group.add_argument("--runs", type=int, default=10,
                       help="cleaning: runs of the layout (default: 10, the thesis')")
    group.add_argument("--layout", default="long_lanes", help="cleaning: layout (default: long_lanes)")
    group.add_argument("--override", action="append", default=[], metavar="KEY=VALUE",
                       help="sweep / cleaning: an extra python -m bionav override (repeatable), e.g. "
                            "--override layout.n_lanes=3")


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _run(args: list[str], *, cwd: Path, env: dict) -> tuple[float, float]:
    """Run ``python -m bionav args``; return (wall s, CPU s of it and its waited-for children).

    On failure the error of every failed job (its metrics.json, in ``cwd``)
    goes into the message: the temporary directory is removed afterwards.
    """
    c0, t0 = _children_cpu(), time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "bionav", *args], cwd=cwd, env=env, capture_output=True, text=True,
                          errors="replace")
    wall, cpu = time.perf_counter() - t0, _children_cpu() - c0
    if proc.returncode != 0:
        lines = [line for line in proc.stderr.splitlines() if line.strip() and not line.startswith("[")]
        why = lines[-1].strip() if lines else f"exit status {proc.returncode}"
        errors = sorted({str(m.get("error")) for m in _metrics(cwd) if m.get("status") == "failed"})
        if errors:
            why = f"{why} Job errors: {'; '.join(e[:300] for e in errors[:3])}"
        raise UserError(f"the benchmarked run `python -m bionav {' '.join(a for a in args if 'dir=' not in a)}` "
                        f"failed (status {proc.returncode}): {why}. Run that command by hand to see its log; "
                        "fix the option it names (--override, --dbs, --layout)")
    return wall, cpu


def _metrics(root: Path) -> list[dict]:
    out = []
    for p in sorted(root.rglob("metrics.json")):
        try:
            data = json.loads(p.read_text())
        except (OSError, ValueError):
            continue
        if isinstance(data, dict):
            out.append(data)
    return out


def run_benchmark(args) -> list[dict]:
    """Rows (one dict) of the whole-run benchmark ``args.method``."""
    from bionav.bench.cpu import numba_target

    machine = machine_label()
    with tempfile.TemporaryDirectory(prefix="bionav-bench-") as tmp:
        tmp = Path(tmp)
        env = dict(os.environ)
        if args.cold:
            env["BIONAV_CACHE"] = str(tmp / "cache")
        load_before = os.getloadavg()[0]
        if args.method == "sweep":
            dbs = [d.strip() for d in args.dbs.split(",") if d.strip()]
            command = ["-m", "experiment=param_sweep_grid", f"experiment.grid={args.sweep_grid}", f"db={','.join(dbs)}",
                       f"workers={args.workers}", f"hydra.sweep.dir={tmp / 'sweep'}"]
            if args.cold:
                command.append(f"cache_dir={tmp / 'cache'}")
            command += list(args.override)
            wall, cpu = _run(command, cwd=tmp, env=env)
            metrics = _metrics(tmp / "sweep")
            row = {
                "method": "sweep", "variant": f"{args.sweep_grid}{'_cold' if args.cold else '_warm'}",
                "dbs": dbs, "configurations": sum(int(m.get("n_configs", 0)) for m in metrics),
                "workers": args.workers, "wall_s": round(wall, 2), "cpu_s": round(cpu, 2),
                "render_wall_s": round(sum(float(m.get("render_wall_s", 0.0)) for m in metrics), 2),
                "runs_wall_s": [round(float(m.get("wall_time_s", 0.0)), 2) for m in metrics],
                "workers_used": [int(m.get("workers", 0)) for m in metrics],
            }
        elif args.method == "cleaning":
            command = ["experiment=cleaning", f"layout={args.layout}", f"runs={args.runs}",
                       f"workers={args.workers}", f"hydra.run.dir={tmp / 'cleaning'}", *args.override]
            wall, cpu = _run(command, cwd=tmp, env=env)
            (m,) = _metrics(tmp / "cleaning")
            row = {
                "method": "cleaning", "variant": f"{args.layout}_render", "runs": args.runs,
                "workers": args.workers, "wall_s": round(wall, 2), "cpu_s": round(cpu, 2),
                "seconds_per_run": round(float(m.get("seconds_per_run", 0.0)), 2),
                "coverage": m.get("coverage"),
            }
        else:  # pragma: no cover - argparse restricts the choices
            raise SystemExit(f"unknown method {args.method!r}")
        row.update({"loadavg_1min": [round(load_before, 2), round(os.getloadavg()[0], 2)], "machine": machine,
                    **numba_target(),
                    "command": "python -m bionav " + " ".join(c for c in command if "dir=" not in c)})
    return [row]
