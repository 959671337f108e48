"""Deviation curves (compass swinging) on known curves, and the held-out study on real recordings."""

import json
import shutil

import numpy as np
import pytest
from helpers import external_data, run_bionav

from bionav.geometry import wrap_angle
from bionav.polcompass.deviation import corrected_heading, deviation_from_errors, fourier_basis, pooled_deviation

COMPASS = external_data() / "celestial-compass"


def test_a_known_curve_is_recovered_and_removed():
    rng = np.random.default_rng(3)
    phi = rng.uniform(-np.pi, np.pi, 2000)
    truth = np.deg2rad([1.5, -1.0, 0.0, -0.5])  # a1, b1, a2, b2
    dev = fourier_basis(phi, 2) @ truth
    np.testing.assert_allclose(dev, np.deg2rad(1.5 * np.cos(phi) - np.sin(phi) - 0.5 * np.sin(2 * phi)), atol=1e-12)
    errors = dev + np.deg2rad(0.2) * rng.standard_normal(phi.size)
    errors[:50] = np.pi - 0.1  # the wrong member of the eq. 4.6 pair: left out (|error| > 30 degrees)
    coef = deviation_from_errors(phi, errors, n_harmonics=2)
    np.testing.assert_allclose(np.degrees(coef), np.degrees(truth), atol=0.05)
    heading = wrap_angle(1.0 + dev)  # true heading 1 rad plus the deviation
    np.testing.assert_allclose(corrected_heading(heading, phi, truth), 1.0, atol=1e-12)
    assert np.isnan(corrected_heading(np.array([np.nan]), np.array([0.3]), truth)).all()
    np.testing.assert_array_equal(corrected_heading(heading, phi, None), heading)


def test_the_tilt_form_gives_the_tilt_and_scales_with_the_sun_elevation():
    # a mount tilt beta towards the device azimuth phi0 reads the sun's azimuth off by beta tan(h) sin(phi - phi0)
    rng = np.random.default_rng(5)
    phi = rng.uniform(-np.pi, np.pi, 1000)
    beta, phi0 = np.deg2rad(2.5), np.deg2rad(40.0)
    coef_true = beta * np.array([-np.sin(phi0), np.cos(phi0)])  # sin(phi - phi0) = cos(phi) (-sin phi0) + sin(phi) cos phi0
    for elevation_deg in (20.0, 60.0):
        scale = np.tan(np.deg2rad(elevation_deg))
        errors = beta * scale * np.sin(phi - phi0)
        coef = deviation_from_errors(phi, errors, n_harmonics=1, scale=scale)
        np.testing.assert_allclose(coef, coef_true, atol=1e-12)
        assert np.degrees(np.hypot(*coef)) == pytest.approx(2.5)
        np.testing.assert_allclose(corrected_heading(0.5 + errors, phi, coef, scale=scale), 0.5, atol=1e-12)


def test_pooling_is_the_median_and_too_few_samples_give_none():
    assert deviation_from_errors(np.zeros(5), np.zeros(5), n_harmonics=2) is None
    pooled = pooled_deviation([np.array([1.0, 0.0]), None, np.array([3.0, 2.0]), np.array([2.0, 10.0])])
    np.testing.assert_array_equal(pooled, [2.0, 2.0])
    assert pooled_deviation([None]) is None


@pytest.mark.slow
@pytest.mark.skipif(not COMPASS.is_dir(), reason=f"real compass recordings not found at {COMPASS} (set BIONAV_EXTERNAL_DATA)")
def test_deviation_bench_learns_on_the_other_day(tmp_path):
    from bionav.polcompass import recordings_config as pr
    from bionav.polcompass import sessions as ps
    from bionav.plugins.decoders.sky_fit import SkyFit, SkyFitConfig
    from bionav.polcompass.decoders import heading_from_sun

    days = {"12-05-22": "17-01__Thursday_12-05-22", "14-05-22": "08-30__Saturday_14-05-22"}
    for day, folder in days.items():
        src = next((COMPASS / "tod_data").glob(f"*{day}/{folder}"))
        shutil.copytree(src, tmp_path / "rec" / "tod_data" / src.parent.name / folder)
    proc = run_bionav("--recordings", str(tmp_path / "rec"), "--harmonics", "1", cwd=tmp_path,
                      module="bionav.bench.decoders.deviation")
    assert proc.returncode == 0, proc.stderr
    lines = [json.loads(line) for line in proc.stdout.splitlines()]
    daylight = lines[0]
    assert daylight["condition"] == "tod_daylight" and len(lines) == 2
    # the same numbers in-process: each session corrected with the curve of the *other* day's session
    rc = pr.recordings_config({"path": str(tmp_path / "rec")})
    prepared, _ = ps.prepared_sessions(rc)
    dec = SkyFit(SkyFitConfig())
    out = []
    for d in prepared:
        phi = dec.decode(d.evectors, d.valid, array=d.array, sun_elevation=float(d.sun.elevation)).azimuth
        heading = heading_from_sun(phi, d.sun.azimuth)
        out.append((heading, phi, ps.session_errors(heading, d.yaw)[0], d.yaw))
    before = np.concatenate([o[2] for o in out])
    after = []
    for i, (heading, phi, _err, yaw) in enumerate(out):
        other = out[1 - i]
        curve = deviation_from_errors(other[1], other[2], n_harmonics=1)
        after.append(ps.session_errors(corrected_heading(heading, phi, curve), yaw)[0])
    assert daylight["n_samples"] == before.size
    assert daylight["mae_deg"] == pytest.approx(np.degrees(np.mean(np.abs(before))), abs=1e-3)
    assert daylight["mae_deviation_removed_deg"] == pytest.approx(np.degrees(np.mean(np.abs(np.concatenate(after)))),
                                                                  abs=1e-3)
    assert len(lines[1]["curve_all_days_deg"]) == 2
    # with the self-calibration, the "before" numbers are those of experiment=pol_recordings recordings.calibration=auto
    proc = run_bionav("--recordings", str(tmp_path / "rec"), "--harmonics", "1", "--form", "tilt", "--calibration", "auto",
                      cwd=tmp_path, module="bionav.bench.decoders.deviation")
    assert proc.returncode == 0, proc.stderr
    tilt = json.loads(proc.stdout.splitlines()[0])
    assert tilt["form"] == "tilt" and tilt["calibration"] == "auto"
    # ... with the angle calibration alone; "after" those of its default calibration parts, angles and mount tilt
    for parts, key in (("[angles]", "mae_deg"), ("[angles,tilt]", "mae_deviation_removed_deg")):
        out = tmp_path / f"run{len(parts)}"
        run = run_bionav("experiment=pol_recordings", f"recordings.path={tmp_path / 'rec'}", "recordings.calibration=auto",
                         f"recordings.calibration_parts={parts}", "experiment.simulate=false",
                         "experiment.compare=[sky_fit]", f"hydra.run.dir={out}", cwd=tmp_path)
        assert run.returncode == 0, run.stderr
        metrics = json.loads((out / "metrics.json").read_text())
        assert tilt[key] == pytest.approx(metrics["tod_daylight_mae_deg"], abs=1e-3)
    assert "mount_tilt_deg" in json.loads((out / "calibration.json").read_text())
    assert tilt["mae_deg"] != pytest.approx(daylight["mae_deg"], abs=1e-3)  # the calibration was applied
    assert tilt["mae_deviation_removed_deg"] != pytest.approx(tilt["mae_deg"], abs=1e-3)  # and the tilt


def test_deviation_bench_refuses_a_bad_harmonics_count(tmp_path):
    proc = run_bionav("--recordings", str(tmp_path), "--harmonics", "0", cwd=tmp_path,
                      module="bionav.bench.decoders.deviation")
    assert proc.returncode == 2 and "--harmonics" in proc.stderr and "Traceback" not in proc.stderr


def _rotation_files(root, day_folder, when, date, *, n=120, mount_deg=30.0):
    """Two fan-8 rotations under the model sky at ``date`` ``when`` (CEST, Sardinia), unit 7 polarization-blind."""
    from bionav.light import SkyModel, sun_position
    from bionav.polcompass.array import PolArray, counts_from_stokes, stokes_from_sky

    arr = PolArray.fan8()
    sun = sun_position(f"{date}T{when[:2]}:{when[3:5]}:00+02:00", latitude_deg=39.2, longitude_deg=9.1)
    folder = root / "tod_data" / day_folder / when
    folder.mkdir(parents=True)
    for r in range(2):
        yaw = np.linspace(-np.pi, np.pi, n, endpoint=False) + 0.01 * r
        inten, q, u = stokes_from_sky(SkyModel(sun, max_degree=0.5), arr, np.deg2rad(mount_deg) + yaw)
        counts = np.round(counts_from_stokes(3000.0 * inten, q, u, arr))
        counts[:, 7, 1], counts[:, 7, 3] = counts[:, 7, 0], counts[:, 7, 2]
        data = {f"pol_op_{k}": counts[:, k, :].tolist() for k in range(8)}
        data["azimuths"] = np.deg2rad([0.0, 90.0, 180.0, 270.0, 45.0, 135.0, 225.0, 315.0]).tolist()
        data["yaw"] = yaw.tolist()
        (folder / f"{r + 1}.json").write_text(json.dumps(data))


def test_pol_recordings_learns_a_mount_tilt_from_the_other_days_and_removes_it(tmp_path):
    from bionav.polcompass import recordings_config as pr
    from bionav.polcompass import sessions as ps
    from bionav.plugins.decoders.sky_fit import SkyFit, SkyFitConfig
    from bionav.polcompass.decoders import SunEstimate

    class Tilted(SkyFit):  # the decoder of a sensor tilted by (a, b): azimuths off by tan(h) (a cos phi + b sin phi)
        tilt = np.deg2rad([1.5, -2.0])

        def decode(self, evectors, valid, *, array, sun_elevation):
            est = super().decode(evectors, valid, array=array, sun_elevation=sun_elevation)
            dev = np.tan(sun_elevation) * (fourier_basis(est.azimuth, 1) @ self.tilt)
            return SunEstimate(wrap_angle(est.azimuth - dev), est.alternative, est.resolved)

    _rotation_files(tmp_path, "Thursday_12-05-22", "13-00__Thursday_12-05-22", "2022-05-12")
    _rotation_files(tmp_path, "Thursday_12-05-22", "17-00__Thursday_12-05-22", "2022-05-12")
    _rotation_files(tmp_path, "Saturday_14-05-22", "10-00__Saturday_14-05-22", "2022-05-14")
    rc = pr.recordings_config({"path": str(tmp_path), "calibration_parts": ["tilt"]})
    prepared, bad = ps.prepared_sessions(rc)
    assert not bad and len(prepared) == 3
    dec = Tilted(SkyFitConfig())
    # learned on 12 May only (14 May left out), from the logged yaw: the tilt the decoder was given
    tilt = ps.mount_tilt(prepared, rc, None, dec, leave_out_day="2022-05-14")
    np.testing.assert_allclose(np.degrees(tilt), [1.5, -2.0], atol=0.1)
    held_out = next(d for d in prepared if d.session.day == "2022-05-14")
    before = ps.session_errors(ps.decode_session(dec, held_out)[0], held_out.yaw)[0]
    after = ps.session_errors(ps.decode_session(dec, held_out, tilt)[0], held_out.yaw)[0]
    assert np.degrees(np.mean(np.abs(before))) > 1.0 > 10 * np.degrees(np.mean(np.abs(after)))
    assert ps.mount_tilt(prepared, rc, None, dec, leave_out_day="2022-05-12") is not None


def test_a_calibration_file_keeps_its_mount_tilt_and_old_files_have_none(tmp_path):
    from dataclasses import replace

    from bionav.polcompass.array_calibration import ArrayCalibration

    k, p = 8, 4
    cal = ArrayCalibration(np.ones((k, p)), np.full((k, p), 0.01), np.zeros((k, p)), np.full((k, p), 0.01),
                           np.zeros(k), np.full(k, np.nan), np.ones(k, bool), np.full(k, 3), ["a", "b", "c"])
    cal.save(tmp_path / "old.json")
    assert "mount_tilt_deg" not in json.loads((tmp_path / "old.json").read_text())
    assert ArrayCalibration.load(tmp_path / "old.json").mount_tilt is None
    replace(cal, mount_tilt=np.deg2rad([1.25, -0.5])).save(tmp_path / "tilt.json")
    assert json.loads((tmp_path / "tilt.json").read_text())["mount_tilt_deg"] == pytest.approx([1.25, -0.5])
    np.testing.assert_allclose(ArrayCalibration.load(tmp_path / "tilt.json").mount_tilt, np.deg2rad([1.25, -0.5]))
