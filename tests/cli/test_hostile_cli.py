"""Hostile input to ``python -m bionav`` (issue 32): odd output directories, finished runs, the cache
variable, unquoted overrides, Optuna settings that the sweeper would reject with a traceback, a closed
pipe; and what every run prints and logs.

Each refusal is checked by :func:`helpers.assert_fails_cleanly`: non-zero exit, no traceback, one
paragraph naming the problem and the fix, a bounded time; where something was recorded before, it is
checked to be intact.
"""

from __future__ import annotations

import json

import pytest
from helpers import REFUSAL_S, assert_fails_cleanly, run_bionav, run_into_closed_pipe, run_tiny


@pytest.fixture(scope="module")
def finished(tiny, tmp_path_factory):
    """A finished run (its metrics.json and run.mcap are what the refusals must keep)."""
    root = tmp_path_factory.mktemp("finished")
    proc = run_tiny(tiny, f"hydra.run.dir={root / 'run'}", cwd=root)
    assert proc.returncode == 0, proc.stderr
    return proc, root / "run"


@pytest.mark.slow
def test_a_run_prints_its_directory_last_and_logs_to_cli_log(finished):
    proc, run_dir = finished
    assert proc.stdout.strip().splitlines()[-1] == f"run directory: {run_dir}"
    log = (run_dir / "cli.log").read_text()
    assert f"grid_homing started in {run_dir}" in log
    assert "grid_homing completed in" in log and "aae=" in log


def test_a_finished_run_is_not_overwritten(finished, tmp_path):
    _proc, run_dir = finished
    before = {p.name: p.read_bytes() for p in (run_dir / "metrics.json", run_dir / "run.mcap")}
    proc = run_bionav("homing=sift", f"hydra.run.dir={run_dir}", cwd=tmp_path)
    assert_fails_cleanly(proc, str(run_dir), "finished run", "hydra.run.dir=", "bionav.resume=true", code=2,
                         max_seconds=REFUSAL_S)
    assert {p.name: p.read_bytes() for p in (run_dir / "metrics.json", run_dir / "run.mcap")} == before


def test_resume_keeps_a_finished_run_and_prints_its_directory(finished, tiny, tmp_path):
    _proc, run_dir = finished
    before = (run_dir / "run.mcap").read_bytes()
    proc = run_tiny(tiny, f"hydra.run.dir={run_dir}", "bionav.resume=true", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip().splitlines()[-1] == f"run directory: {run_dir}"
    assert (run_dir / "run.mcap").read_bytes() == before


def test_a_finished_sweep_is_not_overwritten(tmp_path):
    sweep = tmp_path / "sweep"
    (sweep / "0").mkdir(parents=True)
    (sweep / "0" / "metrics.json").write_text(json.dumps({"status": "completed", "aae": 1.0}))
    (sweep / "summary.csv").write_text("job,status\n0,completed\n")
    proc = run_bionav("-m", "homing=sift,mfdid", f"hydra.sweep.dir={sweep}", cwd=tmp_path)
    assert_fails_cleanly(proc, str(sweep), "hydra.sweep.dir=", "bionav.resume=true", code=2, max_seconds=REFUSAL_S)
    assert json.loads((sweep / "0" / "metrics.json").read_text())["aae"] == 1.0


@pytest.mark.parametrize("value", ["''", "' '"])
def test_an_empty_run_dir_is_refused(tmp_path, value):
    proc = run_bionav(f"hydra.run.dir={value}", cwd=tmp_path)
    assert_fails_cleanly(proc, "hydra.run.dir", "names no directory", "hydra.run.dir=outputs/", code=2,
                         max_seconds=REFUSAL_S)
    assert list(tmp_path.iterdir()) == []  # nothing written into the current directory


def test_a_300_character_directory_name_is_refused(tmp_path):
    proc = run_bionav(f"hydra.run.dir={tmp_path / ('a' * 300)}", cwd=tmp_path)
    assert_fails_cleanly(proc, "File name too long", "hydra.run.dir=", code=2, max_seconds=REFUSAL_S)


@pytest.mark.slow
@pytest.mark.parametrize("case", ["file", "empty", "proc"])
def test_bionav_cache_that_cannot_hold_a_cache(tmp_path, case):
    value = {"file": str(tmp_path / "a_file"), "empty": "", "proc": "/proc/bionav"}[case]
    (tmp_path / "a_file").write_text("x")
    proc = run_bionav(f"hydra.run.dir={tmp_path / 'run'}", cwd=tmp_path, env={"BIONAV_CACHE": value})
    needle = {"file": "is a file, not a folder", "empty": "set but empty", "proc": "virtual file system"}[case]
    assert_fails_cleanly(proc, "BIONAV_CACHE", needle, "export BIONAV_CACHE=", code=2, max_seconds=REFUSAL_S)
    assert not (tmp_path / "run" / "run.mcap").exists()  # refused before any rendering


def test_an_unquoted_tilde_is_explained(tmp_path):
    proc = run_bionav("experiment=pol_recordings", "recordings.path=~/recs", f"hydra.run.dir={tmp_path / 'r'}",
                      cwd=tmp_path)
    assert_fails_cleanly(proc, "recordings.path=~/recs", "quoted", code=2, max_seconds=REFUSAL_S)


OPTUNA = ("-m", "hydra/sweeper=optuna", "hydra.sweeper.n_trials=1", "homing.lowpass_sigma=interval(0.01,0.1)")


@pytest.mark.parametrize("override, needles", [
    ("hydra.sweeper.direction=sideways", ("hydra.sweeper.direction=sideways", "minimize or maximize")),
    ("hydra.sweeper.n_trials=0", ("hydra.sweeper.n_trials=0", "at least one trial")),
    ("homing.vertical_sigma=interval(0.5,0.1)", ("lower bound", "homing.vertical_sigma=interval(0.1,0.5)")),
])
@pytest.mark.slow
def test_optuna_settings_that_would_crash_the_sweeper(tmp_path, override, needles):
    proc = run_bionav(*OPTUNA, override, f"hydra.sweep.dir={tmp_path / 's'}", cwd=tmp_path)
    assert_fails_cleanly(proc, *needles, code=2, max_seconds=REFUSAL_S)
    assert not (tmp_path / "s").exists()


@pytest.mark.slow
def test_optuna_objective_naming_a_missing_metric(tmp_path, tiny):
    proc = run_tiny(tiny, *OPTUNA, "objective.metric=nosuch", f"hydra.sweep.dir={tmp_path / 's'}", cwd=tmp_path)
    assert_fails_cleanly(proc, "objective.metric=nosuch", "aae", code=2, max_seconds=300)
    assert json.loads((tmp_path / "s" / "0" / "metrics.json").read_text())["status"] == "completed"  # kept


def test_help_into_a_closed_pipe_ends_quietly(tmp_path):
    proc = run_into_closed_pipe("--help", module="bionav", cwd=tmp_path)
    assert proc.returncode == 141, proc.stderr
    assert "Traceback" not in proc.stderr and "BrokenPipeError" not in proc.stderr, proc.stderr


@pytest.mark.slow
def test_tilde_in_the_run_dir_is_the_home_folder(tmp_path, tiny):
    home = tmp_path / "home"
    home.mkdir()
    proc = run_tiny(tiny, 'hydra.run.dir="~/myrun"', "experiment.snapshots=[0]", cwd=tmp_path,
                    env={"HOME": str(home)})
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip().splitlines()[-1] == f"run directory: {home / 'myrun'}"
    assert (home / "myrun" / "metrics.json").is_file() and not (tmp_path / "~").exists()


@pytest.mark.parametrize("name, kind", [("metrics.json", "fifo"), ("metrics.json", "list"),
                                        (".bionav.lock", "garbage")])
@pytest.mark.slow
def test_odd_files_in_the_run_directory_do_not_block_or_crash(tmp_path, tiny, name, kind):
    """A FIFO or a list as metrics.json, a lock file that bionav did not write: no hang, no traceback."""
    import os

    run_dir = tmp_path / "run"
    run_dir.mkdir()
    if kind == "fifo":
        os.mkfifo(run_dir / name)
    else:
        (run_dir / name).write_text("[1, 2]" if kind == "list" else '{"pid": "abc"}')
    proc = run_tiny(tiny, f"hydra.run.dir={run_dir}", "experiment.snapshots=[0]", cwd=tmp_path)
    assert proc.seconds < 300 and "Traceback" not in proc.stderr, proc.stderr
    if kind == "fifo":  # the run replaces the FIFO with its own metrics.json
        assert proc.returncode == 0, proc.stderr
        assert json.loads((run_dir / "metrics.json").read_text())["status"] == "completed"
    else:
        assert proc.returncode == 0, proc.stderr
