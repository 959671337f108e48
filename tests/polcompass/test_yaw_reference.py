"""The logged yaw's reference runs (``recordings.reference``): restarts found in the yaw, offsets fitted per run."""

import csv
import json

import numpy as np
import pytest
from helpers import external_data, run_bionav

from bionav.polcompass.sessions import session_errors
from bionav.light import SkyModel, sun_position
from bionav.polcompass.array import PolArray, counts_from_stokes, stokes_from_sky
from bionav.polcompass.array_calibration import yaw_run_shifts
from bionav.polcompass.recordings import load_rotation, yaw_restarts

COMPASS = external_data() / "celestial-compass"
FILE_AZIMUTHS = np.deg2rad([0.0, 90.0, 180.0, 270.0, 45.0, 135.0, 225.0, 315.0])


def _turn(n=90, start_deg=0.6, rest=0):
    """One rotation's yaw (radians): ``rest`` samples at ``start_deg``, then a full turn from there."""
    turn = np.deg2rad(start_deg) + np.linspace(0.0, 2.0 * np.pi, n - rest, endpoint=False)
    return np.concatenate([np.full(rest, np.deg2rad(start_deg)), turn])


def test_a_restart_is_a_file_whose_yaw_starts_at_rest_at_zero():
    cases = [
        _turn(start_deg=0.6, rest=6),  # first file: always a run of its own
        _turn(start_deg=0.5, rest=6),  # back at the controller's stop, 0.5 degrees off zero: same reference
        _turn(start_deg=0.0, rest=6),  # at rest at zero: the odometry restarted
        _turn(start_deg=0.0, rest=0),  # at zero but already turning: not at rest
        _turn(start_deg=-0.2, rest=6),  # at rest just below zero: restarted
        _turn(start_deg=359.9, rest=6),  # at rest at zero, logged as 2 pi - 0.002 rad: restarted
        _turn(start_deg=0.45, rest=6),  # at rest, but where the controller stops: same reference
    ]
    assert yaw_restarts(cases).tolist() == [True, False, True, False, True, True, False]
    assert yaw_restarts(cases, zero_deg=0.5).tolist() == [True, True, True, False, True, True, True]
    assert yaw_restarts([]).shape == (0,)


def test_session_errors_fit_one_offset_per_run():
    yaw = np.linspace(0.0, 6.0, 300)
    shift = np.deg2rad(10.0)
    runs = np.repeat([0, 0, 1], 100)
    decoded = yaw + 0.3 + np.where(runs == 1, shift, 0.0)
    decoded[5] = np.nan
    err, c = session_errors(decoded, yaw, runs=runs)
    assert c == pytest.approx(0.3)
    assert np.abs(err[np.isfinite(decoded)]).max() < 1e-12 and err[5] == pytest.approx(np.pi / 2)
    # one offset for the session: the circular mean of 2/3 at 0 and 1/3 at 10 degrees, by hand
    err1, c1 = session_errors(decoded, yaw)
    mean = np.arctan2(np.sin(shift), 2.0 + np.cos(shift))
    assert c1 == pytest.approx(0.3 + mean, abs=1e-3)
    assert np.degrees(np.abs(err1[np.isfinite(decoded)])).max() == pytest.approx(np.degrees(shift - mean), abs=0.1)


def test_yaw_run_shifts_find_the_unlogged_turn_from_the_counts():
    """Three runs of one sky; the robot restarted its yaw 7 degrees (run 1) and -4 degrees (run 2) turned."""
    arr = PolArray.fan8()
    sun = sun_position("2022-05-12T11:00:00+02:00", latitude_deg=39.2, longitude_deg=9.1)
    sky = SkyModel(sun, max_degree=0.5)
    rng = np.random.default_rng(5)
    yaw = np.concatenate([_turn(400, start_deg=0.0, rest=6)] * 3)
    runs = np.repeat([0, 1, 2], 400)
    turned = np.deg2rad(np.array([0.0, 7.0, -4.0]))[runs]
    inten, q, u = stokes_from_sky(sky, arr, 0.4 + turned + yaw)
    counts = counts_from_stokes(3000.0 * inten, q, u, arr) * (1.0 + 0.01 * rng.standard_normal((1200, 8, 4)))
    valid = np.ones((1200, 8), bool)
    shifts = np.degrees(yaw_run_shifts(counts, yaw, valid, runs))
    assert shifts[0] == 0.0 and shifts[1:] == pytest.approx([7.0, -4.0], abs=0.1)
    beyond = yaw_run_shifts(counts, yaw, valid, runs, max_shift_deg=5.0)  # run 1 turned further than searched
    assert np.isnan(beyond[1]) and np.degrees(beyond[2]) == pytest.approx(-4.0, abs=0.1)
    valid[runs == 2] = False  # a run with nothing readable cannot be placed
    shifts = yaw_run_shifts(counts, yaw, valid, runs)
    assert np.degrees(shifts[1]) == pytest.approx(7.0, abs=0.1) and np.isnan(shifts[2])


def _session_with_a_restart(root, shift_deg=10.0, n=90):
    """Three rotations under the model sky; the third restarts the yaw at zero with the robot ``shift_deg`` turned."""
    arr = PolArray.fan8()
    sun = sun_position("2022-05-12T13:00:00+02:00", latitude_deg=39.2, longitude_deg=9.1)
    sky = SkyModel(sun, max_degree=0.5)
    folder = root / "tod_data" / "Thursday_12-05-22" / "13-00__Thursday_12-05-22"
    folder.mkdir(parents=True)
    mount = np.deg2rad(30.0)
    for r, (start, extra) in enumerate([(0.6, 0.0), (0.5, 0.0), (0.0, shift_deg)]):
        yaw = _turn(n, start_deg=start, rest=6)
        inten, q, u = stokes_from_sky(sky, arr, mount + np.deg2rad(extra) + yaw)
        counts = np.round(counts_from_stokes(3000.0 * inten, q, u, arr))
        data = {f"pol_op_{k}": counts[:, k, :].tolist() for k in range(8)}
        data["azimuths"] = list(map(float, FILE_AZIMUTHS))
        data["yaw"] = list(map(float, yaw))
        (folder / f"{r + 1}.json").write_text(json.dumps(data))
    return folder


@pytest.mark.slow
def test_the_reference_option_scores_a_restarted_yaw_by_its_runs(tmp_path):
    """Known answer: the restart's 10 degrees cost 4.4 degrees MAE with one offset per session, nothing per run."""
    _session_with_a_restart(tmp_path / "rec")
    shift = np.deg2rad(10.0)
    mean = np.degrees(np.arctan2(np.sin(shift), 2.0 + np.cos(shift)))  # the session offset's share of the shift
    expected = {"session": (1, (2 * mean + (10.0 - mean)) / 3.0), "stitched": (2, 0.0), "yaw_run": (2, 0.0),
                "rotation": (3, 0.0)}
    for reference, (runs, mae) in expected.items():
        out = tmp_path / reference
        proc = run_bionav("experiment=pol_recordings", f"recordings.path={tmp_path / 'rec'}", f"hydra.run.dir={out}",
                          f"recordings.reference={reference}", "experiment.simulate=false", "experiment.compare=[]",
                          cwd=tmp_path)
        assert proc.returncode == 0, proc.stderr
        metrics = json.loads((out / "metrics.json").read_text())
        assert metrics["reference"] == reference
        assert metrics["heading_mae_deg"] == pytest.approx(mae, abs=0.4), reference
        rows = list(csv.DictReader(open(out / "sessions.csv")))
        assert [int(r["reference_runs"]) for r in rows] == [runs]
        assert f"recordings.reference={reference}" in (out / "summary.md").read_text()
        if reference == "stitched":  # the counts alone turn the restarted run back by the robot's 10 degrees
            first, second = map(float, rows[0]["yaw_run_shifts_deg"].split())
            assert first == 0.0 and second == pytest.approx(10.0, abs=0.3)


@pytest.mark.skipif(not COMPASS.is_dir(), reason=f"real compass recordings not found at {COMPASS} (set BIONAV_EXTERNAL_DATA)")
def test_the_real_canopy_session_restarts_its_yaw_twice():
    """15 May 17:40: files 5 and 9 start at rest at -0.09 and -0.01 degrees, the others at 0.4-0.6 degrees."""
    folder = COMPASS / "canopy_data" / "Sunday_15-05-22" / "17-40__Sunday_15-05-22"
    yaws = [load_rotation(folder / f"{i}.json").yaw for i in range(1, 13)]
    assert np.flatnonzero(yaw_restarts(yaws)).tolist() == [0, 4, 8]
