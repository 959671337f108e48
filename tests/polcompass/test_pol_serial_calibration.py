"""``sensor=polcompass_serial sensor.calibration=FILE|none``: a calibration file on the serial compass, against
a fake DLP-IO8-G on a pseudo-terminal, recorded to run.mcap and applied again by ``sensor=replay``."""

import json

import numpy as np
import pytest
from helpers import run_bionav
from omegaconf import OmegaConf
from test_pol_compass_experiment import experiment_config

from bionav.errors import UserError
from bionav.experiments.runner import run_experiment
from bionav.logs import read_messages
from bionav.plugins.sensors.polcompass_serial import PolCompassSerial, PolCompassSerialConfig
from bionav.polcompass import UnitCalibration

SMALL = {"samples_per_step": 1, "fake_devices": True, "pan_range_deg": [-90.0, 90.0], "step_deg": 6.0}
PTU = {"name": "ptu46", "settle_s": 0.02}


def _run(tmp_path, name, exp, sensor):
    cfg = OmegaConf.create({"experiment": exp, "sensor": sensor, "pantilt": PTU, "seed": 0})
    metrics = run_experiment(cfg, tmp_path / name, show_progress=False)
    return {k: v for k, v in metrics.items() if k != "wall_time_s"}, tmp_path / name


@pytest.mark.slow
def test_a_calibration_file_replaces_the_rotation_and_replays_without_the_file(tmp_path):
    # 1. a rotation run over the serial driver calibrates the (simulated, toleranced) units from the rotation
    rotation, rot_dir = _run(tmp_path, "rotation", experiment_config("rotation", **SMALL), {"name": "polcompass_serial"})
    assert rotation["calibration"] == "rotation"
    cal_file = tmp_path / "compass_calibration.json"
    cal_file.write_text((rot_dir / "calibration.json").read_text())
    expected = UnitCalibration.load(cal_file)
    # 2. the same compass with experiment.calibration=nominal: worse without the file, as good with it
    exp = experiment_config("rotation", calibration="nominal", **SMALL)
    nominal, _ = _run(tmp_path, "nominal", exp, {"name": "polcompass_serial"})
    with_file, run_dir = _run(tmp_path, "file", exp, {"name": "polcompass_serial", "calibration": str(cal_file)})
    assert nominal["calibration"] == "nominal" and with_file["calibration"] == "sensor_file"
    assert with_file["heading_rmse_deg"] < nominal["heading_rmse_deg"]
    assert with_file["heading_rmse_deg"] == pytest.approx(rotation["heading_rmse_deg"], abs=1e-9)  # same readings
    applied = UnitCalibration.load(run_dir / "calibration.json")
    np.testing.assert_array_equal(applied.unit_angles, expected.unit_angles)
    np.testing.assert_array_equal(applied.volts_per_decade, expected.volts_per_decade)
    log = run_dir / "run.mcap"
    recorded = [m for _t, _, m in read_messages(log, topics=["/pol_compass/calibration"])]
    assert len(recorded) == 1 and recorded[0]["kind"] == "units" and recorded[0]["source"] == str(cal_file)
    assert recorded[0]["calibration"] == expected.to_dict()
    # 3. the replay applies the recorded calibration: same metrics with the file gone
    cal_file.unlink()
    replayed = _replay_run(tmp_path, exp.copy(), log)
    replayed.pop("wall_time_s", None)
    assert replayed == with_file


def _replay_run(tmp_path, exp, log):
    cfg = OmegaConf.create({"experiment": exp, "sensor": {"name": "replay", "path": str(log)},
                            "pantilt": {"name": "replay", "path": str(log)}, "seed": 0})
    return run_experiment(cfg, tmp_path / "replay2", show_progress=False)


def test_bad_calibration_options_are_clear_errors(tmp_path):
    with pytest.raises(UserError, match="sensor.calibration=auto is not an option"):
        PolCompassSerial(PolCompassSerialConfig(calibration="auto"))
    with pytest.raises(UserError, match=r"sensor\.calibration"):
        PolCompassSerial(PolCompassSerialConfig(calibration=str(tmp_path / "missing.json")))
    two = tmp_path / "two_units.json"
    UnitCalibration.nominal((0.0, 1.0)).save(two)
    with pytest.raises(UserError, match=r"calibrates 2 units, but sensor.lines=\[1, 2, 3\] reads 3"):
        PolCompassSerial(PolCompassSerialConfig(calibration=str(two)))
    broken = tmp_path / "broken.json"
    broken.write_text(json.dumps({"center_v": [2.5]}))
    with pytest.raises(UserError, match="broken.json: field 'volts_per_decade' is missing"):
        PolCompassSerial(PolCompassSerialConfig(calibration=str(broken)))


@pytest.mark.slow
def test_serial_calibration_from_the_command_line(tmp_path):
    cal = tmp_path / "cal.json"
    UnitCalibration.nominal(np.deg2rad([0.0, 60.0, 120.0])).save(cal)
    common = ["experiment=pol_compass", "mode=rotation", "sensor=polcompass_serial", "pantilt=ptu46",
              "experiment.fake_devices=true", "experiment.samples_per_step=1", "experiment.step_deg=9",
              "pantilt.settle_s=0.02"]
    out = tmp_path / "run"
    proc = run_bionav(*common, f"sensor.calibration={cal}", f"hydra.run.dir={out}", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["calibration"] == "sensor_file"
    proc = run_bionav(*common, "sensor.calibration=auto", f"hydra.run.dir={tmp_path / 'bad'}", cwd=tmp_path)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert "sensor.calibration=auto is not an option" in proc.stderr
