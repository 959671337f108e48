"""Hostile input to ``python -m bionav.thesis`` (issue 32): ``--only`` selecting nothing, an unknown
launcher, a report directory holding files that are not what a run writes, two commands writing one
``--out``, output into a closed pipe."""

from __future__ import annotations

import json
import os
import socket

import pytest
from helpers import assert_fails_cleanly, run_bionav, run_into_closed_pipe

#: a refusal comes before any run: Python, the item registry and argument checks
REFUSAL_S = 120


def thesis(*args, cwd):
    return run_bionav(*args, cwd=cwd, module="bionav.thesis")


@pytest.mark.parametrize("only", [",", "", " , "])
def test_only_selecting_nothing_is_refused(tmp_path, only):
    proc = thesis("--only", only, "--out", str(tmp_path / "out"), "--dry-run", cwd=tmp_path)
    assert_fails_cleanly(proc, "--only", "names no item", "--only 5.3,B.1", "leave --only out", code=2,
                         max_seconds=REFUSAL_S)


def test_an_unknown_launcher_is_named_with_the_installed_ones(tmp_path):
    proc = thesis("--only", "5.3", "--launcher", "nonexistent", "--out", str(tmp_path / "out"), "--dry-run",
                  cwd=tmp_path)
    assert_fails_cleanly(proc, "unknown --launcher 'nonexistent'", "joblib", "submitit_slurm", code=2,
                         max_seconds=REFUSAL_S)


@pytest.mark.parametrize("metrics, overrides", [("[1, 2]", "- homing=sift\n"), ('{"status": "completed"}', "5\n"),
                                                 ("null", "{a: 1}\n")])
@pytest.mark.slow
def test_odd_files_in_the_report_directory_are_not_runs(tmp_path, metrics, overrides):
    """metrics.json that is a list, overrides.yaml that is a number: not a run of ours, skipped, and the
    report is written (the item is 'not produced')."""
    out = tmp_path / "out"
    run = out / "runs" / "x"
    (run / ".hydra").mkdir(parents=True)
    (run / "metrics.json").write_text(metrics)
    (run / ".hydra" / "overrides.yaml").write_text(overrides)
    proc = thesis("--preset", "tiny", "--only", "5.3", "--out", str(out), "--report-only", cwd=tmp_path)
    assert proc.returncode == 0 and "Traceback" not in proc.stderr, proc.stderr
    assert "not produced 1" in proc.stdout
    assert (run / "metrics.json").read_text() == metrics  # left as it was


def _process_start(pid: int) -> str:
    return open(f"/proc/{pid}/stat").read().rsplit(")", 1)[-1].split()[19]


@pytest.mark.slow
def test_a_second_writer_of_one_out_is_refused_and_a_stale_lock_taken_over(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    lock = out / ".bionav.lock"
    me = os.getpid()  # a live process holding the lock: this test
    lock.write_text(json.dumps({"pid": me, "host": socket.gethostname(), "started": "now",
                                "start_ticks": _process_start(me)}))
    proc = thesis("--preset", "tiny", "--only", "5.3", "--out", str(out), "--report-only", cwd=tmp_path)
    assert_fails_cleanly(proc, str(out), "in use by another bionav command", f"pid {me}", "another --out", code=2,
                         max_seconds=REFUSAL_S)
    assert not (out / "report.md").exists()
    lock.write_text(json.dumps({"pid": 2**22 + 12345, "host": socket.gethostname(), "started": "long ago"}))
    proc = thesis("--preset", "tiny", "--only", "5.3", "--out", str(out), "--report-only", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert (out / "report.md").is_file() and not lock.exists()  # taken over, then released


def test_help_into_a_closed_pipe_ends_quietly(tmp_path):
    proc = run_into_closed_pipe("--help", module="bionav.thesis", cwd=tmp_path)
    assert proc.returncode == 141, proc.stderr
    assert "Traceback" not in proc.stderr and "BrokenPipeError" not in proc.stderr, proc.stderr
