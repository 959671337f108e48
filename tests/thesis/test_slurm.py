"""A sweep on a real SLURM cluster (scripts/slurm-localhost.sh start): failures, scancel, resume.

Skipped with the reason when no slurmctld answers. CI starts the one-node cluster before the
tests (.ci/run).
"""

import csv
import json
import os
import shutil
import subprocess
import sys
import time
import uuid

import cv2
import numpy as np
import pytest

pytestmark = pytest.mark.slurm

OUTER_TIMEOUT_S = 300


def _slurm_answers() -> str | None:
    """None when a slurmctld answers and a node is up, else the reason to skip."""
    if shutil.which("scontrol") is None or shutil.which("sbatch") is None:
        return "no SLURM client tools (scontrol, sbatch); start a local cluster with scripts/slurm-localhost.sh start"
    ping = subprocess.run(["scontrol", "ping"], capture_output=True, text=True, timeout=30)
    if ping.returncode != 0 or "UP" not in ping.stdout:
        said = (ping.stdout + ping.stderr).strip()
        return f"no slurmctld answers (scontrol ping: {said}); run scripts/slurm-localhost.sh start"
    nodes = subprocess.run(["sinfo", "-h", "-o", "%t"], capture_output=True, text=True, timeout=30).stdout.split()
    if not any(state.rstrip("*") in ("idle", "mix", "alloc") for state in nodes):
        return f"no SLURM node is up (sinfo: {' '.join(nodes) or 'none'})"
    try:
        import hydra_plugins.hydra_submitit_launcher  # noqa: F401
    except ImportError:
        return "needs the slurm extra: pip install 'bionav[slurm]'"
    return None


def _queue(name: str) -> tuple[dict[str, str], dict[str, str]]:
    """Array task index -> state, and -> job id, of the jobs named ``name`` in the queue."""
    out = subprocess.run(["squeue", "-h", "-r", "-n", name, "-o", "%i %T"], capture_output=True, text=True).stdout
    states = {}
    for line in out.splitlines():
        job_id, state = line.split()
        states[job_id.partition("_")[2]] = state
    return states, {job_id.partition("_")[2]: job_id for job_id, _ in (line.split() for line in out.splitlines())}


def _wait_for(predicate, what: str, timeout: float = 120.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.2)
    raise AssertionError(f"timed out waiting for {what}")


def _rows(path):
    with open(path) as f:
        return {r["job"]: r for r in csv.DictReader(f)}


@pytest.fixture
def folders(tmp_path):
    """Three 3 x 3 databases of textured 64 x 16 panoramas (same images) and a missing one."""
    rng = np.random.default_rng(0)
    images = [cv2.GaussianBlur(rng.random((16, 64)).astype(np.float32), (0, 0), 1.5) for _ in range(9)]
    paths = []
    for name in ("a", "b", "c", "d"):
        folder = tmp_path / name
        folder.mkdir()
        for k, img in enumerate(images):
            cv2.imwrite(str(folder / f"{k // 3}_{k % 3}.png"), np.uint8(255 * img / img.max()))
        paths.append(folder)
    return paths, tmp_path / "missing"


@pytest.mark.slow
def test_sweep_on_slurm_with_failure_cancellations_and_resume(tmp_path, folders):
    reason = _slurm_answers()
    if reason:
        pytest.skip(reason)
    (a, b, c, d), missing = folders
    sweep = tmp_path / "sweep"
    name = f"bionav-test-{uuid.uuid4().hex[:8]}"
    release = tmp_path / "release"  # task 1 holds its node in the job script until this file exists
    env = dict(os.environ, BIONAV_CACHE=str(tmp_path / "cache"), HYDRA_FULL_ERROR="0")
    command = [
        sys.executable, "-m", "bionav", "-m", "homing=mfdid", "db=folder",
        # job 0 and 3: complete; 1: cancelled while running; 2: fails (no such folder); 4: cancelled while pending
        f"db.path={a},{b},{missing},{c},{d}", "workers=1",
        "hydra/launcher=submitit_slurm", f"hydra.launcher.name={name}", "hydra.launcher.cpus_per_task=1",
        "hydra.launcher.mem_gb=1", "hydra.launcher.timeout_min=10", "hydra.launcher.array_parallelism=2",
        "hydra.launcher.bionav_poll_s=0.5", "hydra.launcher.bionav_grace_s=3",
        f"hydra.launcher.setup=['test \"$SLURM_ARRAY_TASK_ID\" != 1 || test -e {release} || sleep 600']",
        f"hydra.sweep.dir={sweep}",
    ]
    started = time.monotonic()
    proc = subprocess.Popen(command, cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        # cancel task 4 while it waits (only two tasks run at a time, task 1 holds one slot)
        states, ids = _wait_for(lambda: (lambda q: q if "4" in q[0] else None)(_queue(name)), "the job array in squeue")
        assert states["4"] == "PENDING", states
        subprocess.run(["scancel", ids["4"]], check=True)
        # cancel task 1 while it runs
        _wait_for(lambda: _queue(name)[0].get("1") == "RUNNING", "task 1 running")
        subprocess.run(["scancel", ids["1"]], check=True)
        stdout, stderr = proc.communicate(timeout=OUTER_TIMEOUT_S)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
            subprocess.run(["scancel", "-n", name])
    first_s = time.monotonic() - started
    assert proc.returncode == 1 and "3 of 5 jobs failed: 1, 2, 4" in stderr, stderr  # ended, failures named
    assert "Traceback" not in stderr
    rows = _rows(sweep / "summary.csv")
    assert sorted(rows) == ["0", "1", "2", "3", "4"]
    assert [rows[j]["status"] for j in "01234"] == ["completed", "failed", "failed", "completed", "failed"]
    assert "ended as CANCELLED" in rows["1"]["error"]
    assert "cancelled or removed from the queue before it started" in rows["4"]["error"]
    assert "not found" in rows["2"]["error"]
    assert rows["4"]["db.path"] == str(d)  # a job that never started still has its overrides
    assert float(rows["0"]["n_pairs"]) == 72
    assert "5 runs, 3 failed" in (sweep / "summary.md").read_text()

    # resume: the same command runs only what is missing
    before = {j: (sweep / j / "metrics.json").stat().st_mtime_ns for j in ("0", "3")}
    release.touch()
    started = time.monotonic()
    proc = subprocess.run([*command, "bionav.resume=true"], cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=OUTER_TIMEOUT_S)
    resume_s = time.monotonic() - started
    assert proc.returncode == 1 and "1 of 5 jobs failed: 2" in proc.stderr, proc.stderr  # the missing database
    rows = _rows(sweep / "summary.csv")
    assert [rows[j]["status"] for j in "01234"] == ["completed", "completed", "failed", "completed", "completed"]
    assert {j: (sweep / j / "metrics.json").stat().st_mtime_ns for j in ("0", "3")} == before
    for j in ("1", "4"):
        metrics = json.loads((sweep / j / "metrics.json").read_text())
        assert metrics["n_pairs"] == 72 and "resumed" not in metrics
    print(f"\nSLURM sweep: first run {first_s:.1f} s (2 cancellations), resume {resume_s:.1f} s")


def _item_values(path) -> dict[tuple[str, str], str]:
    with open(path) as f:
        return {(r["item"], r["quantity"]): r["bionav"] for r in csv.DictReader(f)}


@pytest.mark.slow
def test_thesis_tiny_preset_on_slurm_gives_the_local_numbers(tmp_path):
    """``python -m bionav.thesis --launcher submitit_slurm``: the tiny preset's runs go to SLURM as job
    arrays, and every number of the report equals the one of the same runs made locally (issue 29)."""
    reason = _slurm_answers()
    if reason:
        pytest.skip(reason)
    name = f"bionav-thesis-{uuid.uuid4().hex[:8]}"
    env = dict(os.environ, BIONAV_CACHE=str(tmp_path / "cache"))
    items = ("--preset", "tiny", "--only", "fig4_4,fig4_6")

    def thesis(*args):
        return subprocess.run([sys.executable, "-m", "bionav.thesis", *items, *args], cwd=tmp_path, env=env,
                              capture_output=True, text=True, timeout=OUTER_TIMEOUT_S)

    local = thesis("--out", str(tmp_path / "local"), "--jobs", "1")
    assert local.returncode == 0, local.stderr + local.stdout
    started = time.monotonic()
    slurm = thesis("--out", str(tmp_path / "slurm"), "--launcher", "submitit_slurm",
                   "--launcher-arg", f"hydra.launcher.name={name}", "--launcher-arg", "hydra.launcher.cpus_per_task=1",
                   "--launcher-arg", "hydra.launcher.mem_gb=1", "--launcher-arg", "hydra.launcher.timeout_min=10",
                   "--launcher-arg", "hydra.launcher.bionav_poll_s=0.5")
    wall = time.monotonic() - started
    assert slurm.returncode == 0, slurm.stderr + slurm.stdout
    assert "Traceback" not in slurm.stderr
    # the jobs ran under SLURM: submitit's job folders hold the slurm job ids, and sacct knows the name
    submitted = list((tmp_path / "slurm" / "sweeps").glob("*/.submitit/*"))
    assert submitted, "no submitit job folder: the runs did not go through SLURM"
    assert not (tmp_path / "slurm" / "runs").exists()
    got, want = _item_values(tmp_path / "slurm" / "items.csv"), _item_values(tmp_path / "local" / "items.csv")
    assert set(got) == set(want) and len(want) >= 4
    numbers = {k: v for k, v in want.items() if v not in ("", "not produced")}
    assert numbers and all(got[k] == v for k, v in numbers.items()), {k: (got[k], v) for k, v in want.items()}
    print(f"\nthesis tiny preset (fig4_4, fig4_6) on SLURM: {wall:.1f} s wall")
