"""Command line of :mod:`bionav.bench.sweep`."""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bionav.errors import UserError


def _sweep(launcher_args: list[str], overrides: list[str], sweep_dir: Path) -> float:
    t0 = time.perf_counter()
    proc = subprocess.run(
        [sys.executable, "-m", "bionav", "-m", *overrides, *launcher_args, f"hydra.sweep.dir={sweep_dir}"],
        capture_output=True, text=True, errors="replace",
    )
    elapsed = time.perf_counter() - t0
    if proc.returncode != 0:
        lines = [line.strip() for line in proc.stderr.splitlines() if line.strip() and not line.startswith("[")]
        why = lines[-1] if lines else f"exit status {proc.returncode}"
        raise UserError(f"the timed sweep `python -m bionav -m {' '.join(overrides + launcher_args)}` failed "
                        f"(status {proc.returncode}): {why}. Fix the option it names (--homing, --db, --sweep) "
                        "or run that command by hand to see its log")
    return elapsed


def main(argv: list[str] | None = None) -> int:
    from bionav.bench._cli import BenchParser, bounded_int
    from bionav.bench.runs import config_names

    parser = BenchParser(
        prog="python -m bionav.bench.sweep",
        description="time the same 4-job sweep with the basic and the joblib launcher",
    )
    parser.add_argument("--homing", default="mfdid", help="homing method of the jobs (default: mfdid)")
    parser.add_argument("--db", default="sim_original", help="database (default: sim_original)")
    parser.add_argument("--sweep", default="homing.lowpass_sigma=0.02,0.03,0.04,0.05",
                        help="the swept override KEY=V1,V2,... (4 values by default)")
    parser.add_argument("--n-jobs", type=int, default=2, help="joblib workers (default: 2; 1..256)")
    args = parser.parse_args(argv)
    bounded_int(parser, "--n-jobs", args.n_jobs, 1, 256)
    from bionav.registry import entry_points_of

    homings = sorted(set(entry_points_of("homing")) | set(config_names("homing")))
    if args.homing not in homings:
        parser.error(f"--homing {args.homing!r} is not a homing method; choose one of {', '.join(homings)}")
    dbs = config_names("db")
    if args.db not in dbs:
        parser.error(f"--db {args.db!r} is not a database config; choose one of {', '.join(dbs)}")
    key, sep, values = args.sweep.partition("=")
    if not sep or not key.strip() or not values.strip():
        parser.error(f"--sweep {args.sweep!r} is not KEY=V1,V2,...; e.g. --sweep homing.lowpass_sigma=0.02,0.04")
    n_values = len([v for v in values.split(",") if v.strip()])
    overrides = [f"homing={args.homing}", f"db={args.db}", args.sweep, "workers=1", "experiment.n_quiver_plots=0"]
    with tempfile.TemporaryDirectory() as tmp:
        # render / cache the database once so neither timing includes it
        _sweep([], [f"homing={args.homing}", f"db={args.db}", "experiment.snapshots=[0]"], Path(tmp) / "warm")
        basic = _sweep([], overrides, Path(tmp) / "basic")
        joblib = _sweep(["hydra/launcher=joblib", f"hydra.launcher.n_jobs={args.n_jobs}"], overrides, Path(tmp) / "joblib")
    print("| launcher | jobs | wall time (s) |")
    print("|---|---|---|")
    print(f"| basic | {n_values} | {basic:.1f} |")
    print(f"| joblib (n_jobs={args.n_jobs}) | {n_values} | {joblib:.1f} |")
    print(f"\nspeed-up: {basic / joblib:.2f}x")
    return 0


if __name__ == "__main__":
    from bionav.bench._cli import run

    run(main, "python -m bionav.bench.sweep")
