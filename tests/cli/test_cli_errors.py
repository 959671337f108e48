"""Bad input on the command line: one clear message, non-zero exit, no traceback."""

import json
import os

import pytest
from helpers import assert_fails_cleanly, run_bionav


def test_help_lists_choices(tmp_path):
    proc = run_bionav("--help", cwd=tmp_path)
    assert proc.returncode == 0
    assert "homing: " in proc.stdout and "sift" in proc.stdout and "mfdid" in proc.stdout
    assert "experiment: " in proc.stdout and "grid_homing" in proc.stdout


def test_unknown_homing_lists_available(tmp_path):
    proc = run_bionav("homing=siftt", cwd=tmp_path)
    assert_fails_cleanly(proc, "unknown homing 'siftt'", "sift", "mfdid")
    assert proc.returncode == 2


def test_unknown_database_lists_available(tmp_path):
    proc = run_bionav("db=sim_nowhere", cwd=tmp_path)
    assert_fails_cleanly(proc, "unknown db 'sim_nowhere'", "sim_original")


def test_wrong_parameter_type(tmp_path):
    proc = run_bionav("homing.window=wide", cwd=tmp_path)
    assert_fails_cleanly(proc, "window")


def test_cfg_job_checks_the_overrides_like_a_run(tmp_path):
    """``--cfg job``'s value ``job`` is not an override: the keys after it are still checked by bionav."""
    proc = run_bionav("homing.serch_radius=3", "--cfg", "job", cwd=tmp_path)
    assert_fails_cleanly(proc, "unknown key homing.serch_radius", "Did you mean homing.search_radius?", code=2)
    proc = run_bionav("experiment.step_length=abc", "--cfg", "job", cwd=tmp_path)
    assert_fails_cleanly(proc, "bad value experiment.step_length=abc", code=2)



@pytest.mark.skipif(os.geteuid() == 0, reason="root can write anywhere")
def test_unwritable_output_dir_nonroot(tmp_path):
    locked = tmp_path / "locked"
    locked.mkdir(mode=0o500)
    proc = run_bionav(f"hydra.run.dir={locked}/run", cwd=tmp_path)
    assert_fails_cleanly(proc, "not writable")


def test_unwritable_output_dir(tmp_path):
    target = tmp_path / "a_file"
    target.write_text("not a directory")
    proc = run_bionav(f"hydra.run.dir={target}/run", cwd=tmp_path)
    assert_fails_cleanly(proc)


def test_failed_run_writes_failed_metrics(tmp_path):
    """A run refused at start into a folder the user made keeps its record there (metrics.json says failed);
    into a new folder it leaves none behind (issue 45)."""
    run_dir = tmp_path / "run"
    run_dir.mkdir()
    proc = run_bionav("experiment=pol_recordings", f"recordings.path={tmp_path / 'nowhere'}", f"hydra.run.dir={run_dir}",
                      cwd=tmp_path)
    assert_fails_cleanly(proc, "nowhere does not exist")
    metrics = json.loads((run_dir / "metrics.json").read_text())
    assert metrics["status"] == "failed" and "nowhere does not exist" in metrics["error"]
    assert (run_dir / "run.mcap").stat().st_size > 0
    fresh = tmp_path / "fresh"
    proc = run_bionav("experiment=pol_recordings", f"recordings.path={tmp_path / 'nowhere'}", f"hydra.run.dir={fresh}",
                      cwd=tmp_path)
    assert_fails_cleanly(proc, "nowhere does not exist", "no run directory was left behind")
    assert not fresh.exists()


def test_an_unknown_experiment_is_refused_before_the_run(tmp_path):
    """``experiment.name`` names no installed experiment plugin: the installed ones listed, no run started."""
    run_dir = tmp_path / "run"
    proc = run_bionav("experiment.name=no_such_experiment", f"hydra.run.dir={run_dir}", cwd=tmp_path)
    assert_fails_cleanly(proc, "no experiment plugin named 'no_such_experiment'", "grid_homing, param_sweep")
    assert not (run_dir / "metrics.json").exists()
