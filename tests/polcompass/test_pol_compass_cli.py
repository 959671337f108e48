"""``python -m bionav experiment=pol_compass ...`` from the command line (installed bionav)."""

import json

import pytest
from helpers import run_bionav

from bionav.logs.reader import read_metadata


def _metrics(run_dir):
    data = json.loads((run_dir / "metrics.json").read_text())
    data.pop("wall_time_s", None)
    return data


@pytest.mark.slow
def test_rotation_then_replay_from_the_command_line(tmp_path):
    rec = tmp_path / "rec"
    proc = run_bionav(
        "experiment=pol_compass", "mode=rotation", "experiment.samples_per_step=2", f"hydra.run.dir={rec}", cwd=tmp_path
    )
    assert proc.returncode == 0, proc.stderr
    assert "heading_rmse_deg" in proc.stdout
    recorded = _metrics(rec)
    assert recorded["status"] == "completed" and recorded["heading_rmse_deg"] <= 1.0
    log = rec / "run.mcap"
    plugins = read_metadata(log)["plugins"]  # the compass homes on nothing: no default homing=sift recorded
    assert "homing" not in plugins and "signature" not in plugins
    assert plugins["sensor"].startswith("polcompass_sim ") and plugins["pantilt"].startswith("sim ")
    rep = tmp_path / "rep"
    proc = run_bionav(
        "experiment=pol_compass",
        "mode=rotation",
        "experiment.samples_per_step=2",
        "sensor=replay",
        f"sensor.path={log}",
        "pantilt=replay",
        f"pantilt.path={log}",
        f"hydra.run.dir={rep}",
        cwd=tmp_path,
    )
    assert proc.returncode == 0, proc.stderr
    assert _metrics(rep) == recorded


@pytest.mark.slow
def test_unknown_mode_and_missing_port_are_clean_errors(tmp_path):
    proc = run_bionav("experiment=pol_compass", "mode=spin", cwd=tmp_path)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert "unknown mode 'spin'" in proc.stderr and "rotation" in proc.stderr
    proc = run_bionav(
        "experiment=pol_compass",
        "sensor=polcompass_serial",
        "sensor.port=/dev/no-such-compass",
        f"hydra.run.dir={tmp_path / 'run'}",
        cwd=tmp_path,
    )
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert "/dev/no-such-compass does not exist" in proc.stderr and "sensor.port" in proc.stderr


@pytest.mark.slow
def test_a_bad_solver_or_calibration_is_refused_by_the_declared_choices(tmp_path):
    """experiment.solver and experiment.calibration are checked once, where the config enters (issue 28)."""
    from helpers import assert_fails_cleanly

    for key, choices in (("solver", "least_squares, two_unit"), ("calibration", "auto, rotation, nominal, file")):
        proc = run_bionav("experiment=pol_compass", f"experiment.{key}=bad", f"hydra.run.dir={tmp_path / key}",
                          cwd=tmp_path)
        assert_fails_cleanly(proc, f"experiment.{key}=bad", choices, code=2)
        assert not (tmp_path / key / "metrics.json").exists()  # refused before the run started
