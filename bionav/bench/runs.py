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
import platform
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

RUN_METHODS = ("sweep", "cleaning")


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


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _run(args: list[str], *, cwd: Path, env: dict) -> tuple[float, float]:
    """Run ``python -m bionav args``; return (wall s, CPU s of it and its waited-for children)."""
    c0, t0 = _children_cpu(), time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "bionav", *args], cwd=cwd, env=env, capture_output=True, text=True)
    wall, cpu = time.perf_counter() - t0, _children_cpu() - c0
    if proc.returncode != 0:
        raise SystemExit(f"python -m bionav {' '.join(args)} failed:\n{proc.stderr[-3000:]}")
    return wall, cpu


def _metrics(root: Path) -> list[dict]:
    return [json.loads(p.read_text()) for p in sorted(root.rglob("metrics.json"))]


def run_benchmark(args) -> list[dict]:
    """Rows (one dict) of the whole-run benchmark ``args.method``."""
    if args.workers < 1:
        raise SystemExit("--workers must be >= 1")
    machine = f"{platform.machine()} {os.cpu_count()} cpus"
    with tempfile.TemporaryDirectory(prefix="bionav-bench-") as tmp:
        tmp = Path(tmp)
        env = dict(os.environ)
        if args.cold:
            env["BIONAV_CACHE"] = str(tmp / "cache")
        load_before = os.getloadavg()[0]
        if args.method == "sweep":
            dbs = [d for d in args.dbs.split(",") if d]
            command = ["-m", "experiment=param_sweep_grid", f"experiment.grid={args.sweep_grid}", f"db={','.join(dbs)}",
                       f"workers={args.workers}", f"hydra.sweep.dir={tmp / 'sweep'}"]
            if args.cold:
                command.append(f"cache_dir={tmp / 'cache'}")
            wall, cpu = _run(command, cwd=tmp, env=env)
            metrics = _metrics(tmp / "sweep")
            row = {
                "method": "sweep", "variant": f"{args.sweep_grid}{'_cold' if args.cold else '_warm'}",
                "dbs": dbs, "configurations": sum(int(m.get("n_configs", 0)) for m in metrics),
                "workers": args.workers, "wall_s": round(wall, 2), "cpu_s": round(cpu, 2),
                "render_wall_s": round(sum(float(m.get("render_wall_s", 0.0)) for m in metrics), 2),
                "runs_wall_s": [round(float(m.get("wall_time_s", 0.0)), 2) for m in metrics],
            }
        elif args.method == "cleaning":
            if args.runs < 1:
                raise SystemExit("--runs must be >= 1")
            command = ["experiment=cleaning", f"layout={args.layout}", f"runs={args.runs}",
                       f"workers={args.workers}", f"hydra.run.dir={tmp / 'cleaning'}"]
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
                    "command": "python -m bionav " + " ".join(c for c in command if "dir=" not in c)})
    return [row]
