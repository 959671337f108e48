"""``recordings.calibration_conditions`` and the POL-OP fallback through ``python -m bionav experiment=pol_recordings``."""

import csv
import json

import numpy as np
import pytest
from helpers import run_bionav

from bionav.testing.polcompass import write_model_session


def _session(root, kind, day_folder, when, *, n=120, overflow=False):
    """Two fan-8 rotations under the model sky (CEST, Sardinia), unit 7 polarization-blind; ``overflow``: every
    unit but unit 0 has one photodiode pair overflowing (32768) at every sample."""
    folder = write_model_session(root / kind / day_folder / when, samples=n)
    for f in folder.glob("*.json") if overflow else ():
        data = json.loads(f.read_text())
        counts = np.stack([np.asarray(data[f"pol_op_{k}"], float) for k in range(8)], axis=1)
        counts[:, 1:4, 0:2] = 32768.0
        counts[:, 4:7, 2:4] = 32768.0
        data.update({f"pol_op_{k}": counts[:, k, :].tolist() for k in range(8)})
        f.write_text(json.dumps(data))


@pytest.mark.slow
def test_calibration_applies_only_in_the_listed_conditions(tmp_path):
    rec = tmp_path / "rec"
    _session(rec, "tod_data", "Thursday_12-05-22", "13-00__Thursday_12-05-22")
    _session(rec, "tod_data", "Saturday_14-05-22", "10-00__Saturday_14-05-22")
    _session(rec, "canopy_data", "Sunday_15-05-22", "17-05__Sunday_15-05-22")
    out = tmp_path / "run"
    proc = run_bionav("experiment=pol_recordings", f"recordings.path={rec}", "recordings.calibration=auto",
                      "recordings.calibration_conditions=[tod_daylight]", "experiment.simulate=false",
                      "experiment.compare=[sky_fit]", f"hydra.run.dir={out}", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    rows = {r["condition"] + r["time_of_day"]: r["calibration"] for r in csv.DictReader(open(out / "sessions.csv"))}
    assert rows["canopy17:05"] == "none (canopy not in recordings.calibration_conditions)"
    assert rows["tod13:00"].startswith("auto (other days)") and rows["tod10:00"].startswith("auto (other days)")
    proc = run_bionav("experiment=pol_recordings", f"recordings.path={rec}", "recordings.calibration_conditions=[fog]",
                      f"hydra.run.dir={tmp_path / 'bad'}", cwd=tmp_path)
    assert proc.returncode != 0 and "recordings.calibration_conditions" in proc.stderr
    assert "Traceback" not in proc.stderr


@pytest.mark.slow
def test_overflowing_pairs_are_decoded_from_the_other_pol_op(tmp_path):
    # only unit 0 reads both POL-OPs: per unit nothing is decodable, per POL-OP the model sky gives the heading
    rec = tmp_path / "rec"
    _session(rec, "tod_data", "Thursday_12-05-22", "17-00__Thursday_12-05-22", overflow=True)
    results = {}
    for fallback in ("true", "false"):
        out = tmp_path / fallback
        proc = run_bionav("experiment=pol_recordings", f"recordings.path={rec}", f"decoder.pol_op_fallback={fallback}",
                          "experiment.simulate=false", "experiment.compare=[sky_fit]", f"hydra.run.dir={out}",
                          cwd=tmp_path)
        assert proc.returncode == 0, proc.stderr
        results[fallback] = json.loads((out / "metrics.json").read_text())
    assert results["false"]["tod_daylight_valid_fraction"] == 0.0
    assert results["true"]["tod_daylight_valid_fraction"] == 1.0
    assert results["true"]["tod_daylight_mae_deg"] < 0.5  # noise-free model sky (counts rounded)
