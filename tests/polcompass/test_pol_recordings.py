"""Recordings of a real POL-OP compass: loader, faults, and ``experiment=pol_recordings`` from the command line."""

import csv
import json
import shutil

import numpy as np
import pytest
from helpers import external_data, run_bionav

from bionav.polcompass.recordings import RecordingError, detect_faults, load_rotation, load_sessions
from bionav.testing.polcompass import write_model_session

COMPASS = external_data() / "celestial-compass"
needs_data = pytest.mark.skipif(
    not COMPASS.is_dir(), reason=f"real compass recordings not found at {COMPASS} (set BIONAV_EXTERNAL_DATA)"
)


def _synthetic_session(root, *, when="13-00__Thursday_12-05-22", rotations=2, n=90, mount_deg=30.0, blind_unit=7,
                       **kw):
    """Rotation files of the fan-8 under the model sky at each sample's time and place (Sardinia, CEST)."""
    return write_model_session(root / "tod_data" / "Thursday_12-05-22" / when, rotations=rotations, samples=n,
                               mount_deg=mount_deg, blind_unit=blind_unit, **kw)


def test_loader_reads_a_rotation_and_rejects_bad_files_naming_file_and_field(tmp_path):
    folder = _synthetic_session(tmp_path, rotations=1)
    rot = load_rotation(folder / "1.json")
    assert rot.counts.shape == (90, 8, 4) and rot.yaw.shape == (90,)
    good = json.loads((folder / "1.json").read_text())
    cases = {
        "layout.json": ({"counts": [1, 2, 3]}, "pol_op_0"),
        "missing_unit.json": ({k: v for k, v in good.items() if k != "pol_op_3"}, "pol_op_3"),
        "nan.json": ({**good, "pol_op_2": [[float("nan"), 1, 1, 1]] + good["pol_op_2"][1:]}, "pol_op_2"),
        "negative.json": ({**good, "pol_op_5": [[-1, 1, 1, 1]] + good["pol_op_5"][1:]}, "pol_op_5"),
        "short_yaw.json": ({**good, "yaw": good["yaw"][:-3]}, "yaw"),
        "list.json": ([1, 2], "top level"),
    }
    for name, (data, field) in cases.items():
        p = tmp_path / name
        p.write_text(json.dumps(data))
        with pytest.raises(RecordingError) as info:
            load_rotation(p)
        assert name in str(info.value) and field in str(info.value), str(info.value)


def test_fault_detection_finds_blind_and_bad_photodiode_units():
    rng = np.random.default_rng(3)
    counts = rng.uniform(1000, 3000, size=(400, 8, 4))
    counts[:, 7, 1] = counts[:, 7, 0]  # blind unit
    counts[:, 7, 3] = counts[:, 7, 2]
    counts[:, 5, 0] *= 4.0  # one photodiode far too bright
    counts[:100, 2, :] = 11500.0  # saturated a quarter of the time: still usable
    faults = detect_faults(counts, saturation_counts=11000, dark_counts=5)
    excluded = {f.unit: f.reason for f in faults if f.excluded}
    assert set(excluded) == {5, 7}, excluded
    assert "blind" in excluded[7] and "bad photodiode" in excluded[5]
    assert faults[2].saturated_fraction == pytest.approx(0.25)


@pytest.mark.slow
def test_experiment_on_synthetic_recordings_recovers_the_heading(tmp_path):
    root = tmp_path / "rec"
    _synthetic_session(root)
    out = tmp_path / "run"
    proc = run_bionav("experiment=pol_recordings", f"recordings.path={root}", f"hydra.run.dir={out}", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["status"] == "completed"
    assert metrics["n_rotations"] == 2 and metrics["n_samples"] == 180
    assert metrics["heading_mae_deg"] < 0.5  # noise-free model sky: the default decoder is exact up to its grid
    assert metrics["ambiguity_resolved_fraction"] == 1.0
    rows = list(csv.DictReader(open(out / "sessions.csv")))
    assert {r["decoder"] for r in rows} == {"sky_fit", "two_unit", "sol", "four_zeros", "eigenvector", "mean_vector"}
    assert all(r["excluded_units"] == "7" and r["condition"] == "tod" and r["time_of_day"] == "13:00" for r in rows)
    for name in ("error_vs_time_of_day", "session_errors", "raw_unit_responses", "clear_vs_canopy", "sim_vs_real",
                 "yaw_reference"):
        assert (out / "plots" / f"{name}.png").stat().st_size > 1000
    from bionav.plugins.sensors.replay import read_topics

    topics = read_topics(out / "run.mcap")
    assert len(topics["/pol_recordings/rotation"]) == 2 and len(topics["/pol_recordings/session"]) == 6


@pytest.mark.slow
def test_bad_file_keeps_good_rows_and_names_file_and_field(tmp_path):
    root = tmp_path / "rec"
    folder = _synthetic_session(root)
    bad = json.loads((folder / "2.json").read_text())
    bad["yaw"] = bad["yaw"][:10]
    (folder / "3.json").write_text(json.dumps(bad))
    out = tmp_path / "run"
    proc = run_bionav("experiment=pol_recordings", f"recordings.path={root}", f"hydra.run.dir={out}",
                      "experiment.compare=[sky_fit]", cwd=tmp_path)
    assert proc.returncode == 2
    assert "3.json" in proc.stderr and "'yaw'" in proc.stderr and "Traceback" not in proc.stderr
    rows = list(csv.DictReader(open(out / "sessions.csv")))
    assert len(rows) == 1 and rows[0]["n_rotations"] == "2"
    proc = run_bionav("experiment=pol_recordings", f"recordings.path={root}", f"hydra.run.dir={tmp_path / 'skip'}",
                      "experiment.compare=[sky_fit]", "recordings.on_bad_file=skip", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    # a session folder whose name does not give the time: named, skipped, the other session still scored
    (folder / "3.json").unlink()
    shutil.copytree(folder, root / "canopy_data" / "somewhere")
    out = tmp_path / "run2"
    proc = run_bionav("experiment=pol_recordings", f"recordings.path={root}", f"hydra.run.dir={out}",
                      "experiment.compare=[sky_fit]", "experiment.simulate=false", cwd=tmp_path)
    assert proc.returncode == 2 and "somewhere" in proc.stderr and "HH-MM__" in proc.stderr, proc.stderr
    rows = list(csv.DictReader(open(out / "sessions.csv")))
    assert [r["time_of_day"] for r in rows] == ["13:00"]


@pytest.mark.slow
def test_bad_options_are_clean_errors(tmp_path):
    root = tmp_path / "rec"
    _synthetic_session(root, rotations=1)
    for args, expect in (
        ([], "recordings.path"),
        ([f"recordings.path={root}", "recordings.tilt_deg=120"], "recordings.tilt_deg"),
        ([f"recordings.path={root}", "decoder=nope"], "decoder"),
        ([f"recordings.path={root}", "decoder.margin=5"], "decoder.margin"),
        ([f"recordings.path={tmp_path / 'absent'}"], "does not exist"),
    ):
        proc = run_bionav("experiment=pol_recordings", *args, f"hydra.run.dir={tmp_path / 'out'}", cwd=tmp_path)
        assert proc.returncode != 0 and expect in proc.stderr and "Traceback" not in proc.stderr, (args, proc.stderr)


@needs_data
def test_a_real_rotation_file_loads_with_the_documented_layout():
    session = COMPASS / "tod_data" / "Thursday_12-05-22" / "17-01__Thursday_12-05-22"
    rot = load_rotation(session / "1.json")
    k = rot.counts.shape[1]
    assert rot.counts.shape[2] == 4 and k == 8 and rot.yaw.size == rot.counts.shape[0] > 300
    np.testing.assert_allclose(np.degrees(rot.file_azimuths), [0, 90, 180, 270, 45, 135, 225, 315], atol=1e-6)
    assert np.ptp(np.unwrap(rot.yaw)) > 2 * np.pi * 0.95  # one full turn
    faults = detect_faults(rot.counts, saturation_counts=11000, dark_counts=5)
    assert faults[7].excluded and "blind" in faults[7].reason  # the recorded sensor's unit 7


@pytest.mark.slow
@needs_data
def test_experiment_on_one_real_session(tmp_path):
    src = COMPASS / "tod_data" / "Thursday_12-05-22" / "17-01__Thursday_12-05-22"
    dst = tmp_path / "rec" / "tod_data" / src.parent.name / src.name
    dst.mkdir(parents=True)
    for name in ("1.json", "2.json"):
        shutil.copy(src / name, dst / name)
    out = tmp_path / "run"
    proc = run_bionav("experiment=pol_recordings", f"recordings.path={tmp_path / 'rec'}", f"hydra.run.dir={out}",
                      "experiment.simulate=false", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["n_rotations"] == 2 and metrics["tod_daylight_mae_deg"] < 8.0
    sessions, errors = load_sessions(tmp_path / "rec")
    assert not errors and len(sessions) == 1


@pytest.mark.slow
def test_pol_compass_rotation_runs_on_recorded_counts_and_replays_exactly(tmp_path):
    folder = _synthetic_session(tmp_path / "rec", rotations=1, n=60, rotation_period_s=0.0)  # one sky time
    sky = ["experiment.sky.time=2022-05-12T13:00:00+02:00", "experiment.sky.latitude_deg=39.2",
           "experiment.sky.longitude_deg=9.1"]
    rec = tmp_path / "a"
    proc = run_bionav("experiment=pol_compass", "sensor=recording", f"sensor.path={folder / '1.json'}", *sky,
                      f"hydra.run.dir={rec}", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    first = json.loads((rec / "metrics.json").read_text())
    assert first["n_samples"] == 60 and first["heading_mae_deg"] < 0.5 and first["axial"] is False
    rep = tmp_path / "b"
    proc = run_bionav("experiment=pol_compass", "sensor=replay", f"sensor.path={rec / 'run.mcap'}", *sky,
                      f"hydra.run.dir={rep}", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    second = json.loads((rep / "metrics.json").read_text())
    assert second["heading_mae_deg"] == first["heading_mae_deg"] and second["n_samples"] == 60
