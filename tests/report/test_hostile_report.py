"""Hostile input to ``python -m bionav.report`` (issue 32): a missing or odd directory, metrics.json that
is a FIFO or not an object, overrides.yaml that is a number, output into a closed pipe."""

from __future__ import annotations

import json
import os

from helpers import assert_fails_cleanly, run_bionav, run_into_closed_pipe


def report(*args, cwd):
    return run_bionav(*args, cwd=cwd, module="bionav.report", timeout=120)


def test_missing_directory_and_file(tmp_path):
    assert_fails_cleanly(report(str(tmp_path / "nope"), cwd=tmp_path), "is not a directory", code=2, max_seconds=60)
    (tmp_path / "f").write_text("x")
    assert_fails_cleanly(report(str(tmp_path / "f"), cwd=tmp_path), "is not a directory", code=2, max_seconds=60)


def test_odd_runs_are_failed_rows_and_a_fifo_does_not_block(tmp_path):
    sweep = tmp_path / "sweep"
    for job, metrics in (("0", {"status": "completed", "aae": 1.25}), ("1", [1, 2])):
        (sweep / job / ".hydra").mkdir(parents=True)
        (sweep / job / "metrics.json").write_text(json.dumps(metrics))
        (sweep / job / ".hydra" / "overrides.yaml").write_text("- homing=sift\n" if job == "0" else "5\n")
    (sweep / "2").mkdir()
    os.mkfifo(sweep / "2" / "metrics.json")
    proc = report(str(sweep), cwd=tmp_path)
    assert proc.returncode == 0 and "Traceback" not in proc.stderr, proc.stderr
    rows = {line.split("|")[1].strip(): line for line in proc.stdout.splitlines() if line.startswith("| ")}
    assert "1.25" in rows["0"]
    assert "holds a JSON list" in rows["1"] and "failed" in rows["1"]
    assert "FIFO" in rows["2"] and "failed" in rows["2"]
    assert proc.seconds < 60


def test_output_into_a_closed_pipe_ends_quietly(tmp_path):
    (tmp_path / "run").mkdir()
    (tmp_path / "run" / "metrics.json").write_text(json.dumps({"status": "completed", "aae": 1.0}))
    proc = run_into_closed_pipe(str(tmp_path), module="bionav.report", cwd=tmp_path)
    assert proc.returncode == 141, proc.stderr
    assert "Traceback" not in proc.stderr and "BrokenPipeError" not in proc.stderr, proc.stderr
