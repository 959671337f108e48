"""Command line of :mod:`bionav.bench.sweep`."""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def _sweep(launcher_args: list[str], overrides: list[str], sweep_dir: Path) -> float:
    t0 = time.perf_counter()
    proc = subprocess.run(
        [sys.executable, "-m", "bionav", "-m", *overrides, *launcher_args, f"hydra.sweep.dir={sweep_dir}"],
        capture_output=True, text=True,
    )
    elapsed = time.perf_counter() - t0
    if proc.returncode != 0:
        raise SystemExit(f"sweep failed:\n{proc.stderr[-2000:]}")
    return elapsed


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m bionav.bench.sweep",
        description="time the same 4-job sweep with the basic and the joblib launcher",
    )
    parser.add_argument("--homing", default="mfdid", help="homing method of the jobs (default: mfdid)")
    parser.add_argument("--db", default="sim_original", help="database (default: sim_original)")
    parser.add_argument("--sweep", default="homing.lowpass_sigma=0.02,0.03,0.04,0.05",
                        help="the swept override (4 values by default)")
    parser.add_argument("--n-jobs", type=int, default=2, help="joblib workers (default: 2)")
    args = parser.parse_args(argv)
    overrides = [f"homing={args.homing}", f"db={args.db}", args.sweep, "workers=1", "experiment.n_quiver_plots=0"]
    with tempfile.TemporaryDirectory() as tmp:
        # render / cache the database once so neither timing includes it
        _sweep([], [f"homing={args.homing}", f"db={args.db}", "experiment.snapshots=[0]"], Path(tmp) / "warm")
        basic = _sweep([], overrides, Path(tmp) / "basic")
        joblib = _sweep(["hydra/launcher=joblib", f"hydra.launcher.n_jobs={args.n_jobs}"], overrides, Path(tmp) / "joblib")
    print("| launcher | jobs | wall time (s) |")
    print("|---|---|---|")
    print(f"| basic | 4 | {basic:.1f} |")
    print(f"| joblib (n_jobs={args.n_jobs}) | 4 | {joblib:.1f} |")
    print(f"\nspeed-up: {basic / joblib:.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
