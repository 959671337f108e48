"""Sweeps: summary with a deliberately failing job, resume skips finished jobs, report CLI."""

import csv
import json

import pytest
from helpers import run_bionav, write_tiny_folder


@pytest.fixture
def tiny_folder(tmp_path):
    """A 3 x 3 Vardy-named database of smooth random panoramas."""
    return write_tiny_folder(tmp_path / "tiny", shape=(16, 64), sigma=2.0)


def _rows(path):
    with open(path) as f:
        return list(csv.DictReader(f))


@pytest.mark.slow
def test_sweep_summary_includes_the_failing_job(tmp_path, tiny_folder):
    sweep = tmp_path / "sweep"
    proc = run_bionav(
        "-m", "homing=mfdid", "db=folder", f"db.path={tiny_folder},{tmp_path / 'missing'}",
        f"hydra.sweep.dir={sweep}", cwd=tmp_path,
    )
    assert proc.returncode == 1, proc.stderr  # a failed job fails the sweep, after the summary is written
    assert "1 of 2 jobs failed" in proc.stderr.strip().splitlines()[-1] and "Traceback" not in proc.stderr
    rows = _rows(sweep / "summary.csv")
    assert len(rows) == 2
    by_path = {r["db.path"]: r for r in rows}
    ok, bad = by_path[str(tiny_folder)], by_path[str(tmp_path / "missing")]
    assert ok["status"] == "completed" and float(ok["n_pairs"]) == 72
    assert bad["status"] == "failed" and "not found" in bad["error"]
    md = (sweep / "summary.md").read_text()
    assert "2 runs, 1 failed" in md


@pytest.mark.slow
def test_resumed_sweep_does_not_recompute_finished_jobs(tmp_path, tiny_folder):
    sweep = tmp_path / "sweep"
    args = ["-m", "homing=mfdid,sift", "db=folder", f"db.path={tiny_folder}", f"hydra.sweep.dir={sweep}"]
    assert run_bionav(*args, cwd=tmp_path).returncode == 0
    before = {p: p.stat().st_mtime_ns for p in sweep.glob("*/metrics.json")}
    logs = {p: p.read_bytes() for p in sweep.glob("*/run.mcap")}
    assert len(before) == 2
    proc = run_bionav(*args, "bionav.resume=true", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert {p: p.stat().st_mtime_ns for p in sweep.glob("*/metrics.json")} == before
    assert {p: p.read_bytes() for p in sweep.glob("*/run.mcap")} == logs
    # without resume a finished sweep is not overwritten (issue 32): refused, naming the directory and the fix
    proc = run_bionav(*args, cwd=tmp_path)
    assert proc.returncode == 2 and str(sweep) in proc.stderr and "bionav.resume=true" in proc.stderr, proc.stderr
    assert {p: p.stat().st_mtime_ns for p in sweep.glob("*/metrics.json")} == before


@pytest.mark.slow
def test_report_rebuilds_table_and_compares_methods(tmp_path, tiny_folder):
    sweep = tmp_path / "sweep"
    assert run_bionav("-m", "homing=mfdid,sift", "db=folder", f"db.path={tiny_folder}",
                      f"hydra.sweep.dir={sweep}", cwd=tmp_path).returncode == 0
    (sweep / "summary.csv").unlink()
    proc = run_bionav(str(sweep), cwd=tmp_path, module="bionav.report")
    assert proc.returncode == 0, proc.stderr
    assert len(_rows(sweep / "summary.csv")) == 2
    assert "Method comparisons" in proc.stdout and "95% CI AAE*" in proc.stdout
    bad = run_bionav(str(tmp_path / "nothing"), cwd=tmp_path, module="bionav.report")
    assert bad.returncode == 2 and "Traceback" not in bad.stderr


@pytest.mark.slow
def test_single_run_writes_metrics_log_and_plots(tmp_path, tiny_folder):
    run_dir = tmp_path / "run"
    proc = run_bionav("homing=mfdid", "db=folder", f"db.path={tiny_folder}", f"hydra.run.dir={run_dir}", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    metrics = json.loads((run_dir / "metrics.json").read_text())
    assert metrics["status"] == "completed"
    assert metrics["n_images"] == 9 and metrics["n_pairs"] == 72
    for key in ("aae", "mae", "rr", "ms_per_home_vector"):
        assert key in metrics and key in proc.stdout
    assert (run_dir / "plots" / "per_snapshot.png").is_file()
    assert len(list((run_dir / "plots").glob("home_vectors_*.png"))) == 4
    from bionav.logs import read_attachment, read_messages, read_metadata

    topics = {t for t, _, _ in read_messages(run_dir / "run.mcap")}
    assert "/grid_homing/home_vectors" in topics
    assert b"homing:" in read_attachment(run_dir / "run.mcap", "config.yaml")
    assert "mfdid" in read_metadata(run_dir / "run.mcap")["plugins"]["homing"]


def test_missing_real_database_says_where_it_looked(tmp_path):
    proc = run_bionav("db=original", f"data_dir={tmp_path / 'nowhere'}", f"hydra.run.dir={tmp_path / 'r'}", cwd=tmp_path)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    for needle in ("nowhere", "BIONAV_DATA", "sim_original"):
        assert needle in proc.stderr


@pytest.mark.slow
@pytest.mark.parametrize("launcher", ["joblib", "submitit_local"])
def test_parallel_and_cluster_launchers(tmp_path, tiny_folder, launcher):
    sweep = tmp_path / "sweep"
    proc = run_bionav("-m", "homing=mfdid,sift", "db=folder", f"db.path={tiny_folder},{tmp_path / 'missing'}",
                      f"hydra/launcher={launcher}", f"hydra.sweep.dir={sweep}", cwd=tmp_path)
    assert proc.returncode == 1, proc.stderr  # the two jobs on the missing folder fail the sweep
    assert "2 of 4 jobs failed" in proc.stderr.strip().splitlines()[-1]
    rows = _rows(sweep / "summary.csv")
    assert len(rows) == 4
    assert sorted(r["status"] for r in rows) == ["completed", "completed", "failed", "failed"]
