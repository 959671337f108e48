"""Stability measures, 2-D scans through the sensor plugins, and experiment=contrast_scan on a small grid."""

import numpy as np
import pytest
from omegaconf import OmegaConf
from spectral_ctx import FakeContext, run_with

from bionav.light.clouds import CloudLayer
from bionav.light.daylight import SkyState
from bionav.plugins.sensors.fakes.spectral5 import FakeSpectral5
from bionav.plugins.sensors.spectral5 import Spectral5Serial, Spectral5Sim
from bionav.spectral.scan import DirectPanTilt, ScanGrid, feature_images, run_scan, stability_series
from bionav.spectral.sensor_model import LogSensorModel
from bionav.spectral.stability import stability_measures
from bionav.world.worlds.garden import backyard_scene


def test_stability_measures_hand_computed():
    a = np.array([1.0, 2.0, 3.0, 4.0])
    b = np.array([1.0, 2.0, 3.0, 6.0])
    m = stability_measures(a, b)
    assert m["MSE"] == pytest.approx(1.0) and m["RMSD"] == pytest.approx(1.0)
    assert m["logNRMSD"] == pytest.approx(np.log10(1 / 3))
    assert m["PSNR"] == pytest.approx(10 * np.log10(16.0))
    assert m["CorrCoeff"] == pytest.approx(2.0 / np.sqrt(1.25 * 3.5))
    assert m["logMSEstd"] == pytest.approx(np.log10(1 / np.sqrt(1.25 * 3.5)))
    assert m["logMSEvar"] == pytest.approx(np.log10(1 / 1.25))
    same = stability_measures(a, a)
    assert same["MSE"] == 0 and same["logMSEvar"] == -np.inf and same["CorrCoeff"] == pytest.approx(1.0)


def test_contrasts_are_invariant_to_a_global_intensity_change():
    """Log signals: brighter light adds the same count offset to every channel; contrasts cancel it."""
    rng = np.random.default_rng(0)
    scan0 = rng.uniform(1000, 3000, (6, 9, 5))
    scans = np.stack([scan0, scan0 + 150.0])
    rows = stability_series(scans)
    for r in rows:
        if "-" in r["feature"]:
            assert r["MSE"] == pytest.approx(0.0, abs=1e-18)
        else:
            assert r["MSE"] == pytest.approx(150.0**2)
    imgs = feature_images(scan0)
    np.testing.assert_allclose(imgs["UV-IR"], scan0[..., 0] - scan0[..., 4])


@pytest.fixture(scope="module")
def scene():
    sky = SkyState.from_time("2009-06-17T13:00:00+02:00", clouds=CloudLayer(cover=0.4, optical_depth=25.0, seed=1))
    return backyard_scene(sky, seed=2)


def test_scan_column_by_column_matches_the_scene(scene):
    grid = ScanGrid.from_steps(n_pan=6, pan_step=np.deg2rad(10), n_tilt=4, tilt_step=np.deg2rad(10),
                               tilt_start=np.deg2rad(-20))
    sensor = Spectral5Sim(Spectral5Sim.Config(noise_counts=0.0))
    pantilt = DirectPanTilt()
    for dev in (sensor, pantilt):
        dev.attach_simulation(scene, np.random.default_rng(0))
    moves = []
    img = run_scan(sensor, pantilt, grid, on_move=moves.append)
    assert img.shape == (4, 6, 6)
    # column by column: all tilts of the first pan first, tilt ascending
    assert [m["pan"] for m in moves[:4]] == [grid.pans[0]] * 4
    assert [m["tilt"] for m in moves[:4]] == list(grid.tilts)
    model = LogSensorModel(noise_counts=0.0)
    p, t = grid.angles()
    for r, c in [(0, 0), (3, 5), (1, 2)]:
        want = np.clip(np.rint(model.ideal_counts(scene.band_radiance(p[r, c], t[r, c]))), 0, 4095)
        np.testing.assert_array_equal(img[r, c, :5], want)
    assert p[0, 0] == grid.pans[0] and t[0, 0] == grid.tilts[-1]  # row 0 = highest tilt


def test_serial_scan_through_the_fake_board_equals_the_simulation(scene):
    grid = ScanGrid.from_steps(n_pan=3, pan_step=np.deg2rad(20), n_tilt=3, tilt_step=np.deg2rad(15),
                               tilt_start=np.deg2rad(-10))
    sim = Spectral5Sim(Spectral5Sim.Config(noise_counts=0.0))
    sim.attach_simulation(scene, np.random.default_rng(0))
    pantilt = DirectPanTilt(scene)
    reference = run_scan(sim, pantilt, grid)
    with FakeSpectral5(source=sim.measure) as fake:
        with Spectral5Serial(Spectral5Serial.Config(port=fake.port, timeout_s=1.0)) as serial_sensor:
            readings = []
            img = run_scan(serial_sensor, pantilt, grid, on_reading=readings.append)
    np.testing.assert_array_equal(img, reference)
    assert len(readings) == 9 and len(readings[0]["counts"][0]) == 6
    assert fake.commands.count(b"M1") == 9


@pytest.mark.slow
def test_contrast_scan_experiment_small(tmp_path):
    cfg = OmegaConf.create({
        "seed": 0,
        "sensor": {"name": "spectral5_sim"},
        "experiment": {
            "name": "contrast_scan", "times": ["2009-06-17T11:27:04+02:00", "2009-06-17T18:44:09+02:00"],
            "cloud_cover": [0.9, 0.2], "cloud_optical_depth": [40, 10], "n_pan": 12, "pan_step_deg": 15.0,
            "n_tilt": 6, "tilt_step_deg": 12.0, "tilt_start_deg": -30.0, "scan_minutes": 5.0, "sigma": 30.0,
            "learn": {"name": "sim_natural", "seed": 0, "n_objects": 80, "n_sky": 80},
        },
    })

    class Ctx(FakeContext):
        def plugin(self, kind, node):
            assert kind == "sensor" and node.name == "spectral5_sim"
            return Spectral5Sim(Spectral5Sim.Config())

    ctx = Ctx(tmp_path)
    m = run_with(cfg, ctx)
    assert m["n_scans"] == 2 and m["n_readings"] == 2 * 12 * 6
    assert set(m["logMSEvar"]) == {"UV", "B", "G", "R", "IR", "UV-B", "UV-G", "UV-R", "UV-IR", "B-G", "B-R",
                                   "B-IR", "G-R", "G-IR", "R-IR"}
    # the scene's sky is known in simulation: the UV-IR line separates it well
    assert m["sky_accuracy"]["UV-IR"] > 0.85
    topics = [t for t, _, _ in ctx.log.messages]
    assert topics.count("/sensor/raw") == 144 and topics.count("/pantilt/state") == 144
    assert topics.count("/contrast_scan/sky_truth") == 2
    for f in ("stability.csv", "scans.npz", "plots/stability.png", "plots/stability_separated.png", "plots/separation_first.png",
              "plots/scans/channels_01.png"):
        assert (tmp_path / f).is_file(), f
    data = np.load(tmp_path / "scans.npz")
    assert data["counts"].shape == (2, 6, 12, 6)


def _small_scan_cfg():
    return OmegaConf.create({
        "seed": 0,
        "sensor": {"name": "spectral5_sim"},
        "experiment": {
            "name": "contrast_scan", "times": ["2009-06-17T11:27:04+02:00", "2009-06-17T19:24:41+02:00"],
            "cloud_cover": [0.8, 0.3], "cloud_optical_depth": [30, 15], "n_pan": 7, "pan_step_deg": 20.0,
            "n_tilt": 5, "tilt_step_deg": 15.0, "tilt_start_deg": -30.0, "scan_minutes": 5.0,
            "learn": {"name": "sim_natural", "seed": 0, "n_objects": 60, "n_sky": 60}, "plots": False,
        },
    })


def test_recorded_scan_replays_to_identical_metrics(tmp_path):
    """Record a simulated session in a real run.mcap, replay it with sensor=replay pantilt=replay."""
    from bionav.experiments.context import RunContext
    from bionav.logs.writer import McapLog
    from bionav.plugins.sensors.replay import Replay, ReplayConfig

    class Ctx(RunContext):
        def __init__(self, d, make):
            d.mkdir()
            super().__init__(dir=d, log=McapLog(d / "run.mcap"), rng=np.random.default_rng(0), cfg=None,
                             show_progress=False)
            self.make = make

        def plugin(self, kind, node, **kw):
            return self.make(kind)

    live = Ctx(tmp_path / "live", lambda kind: Spectral5Sim(Spectral5Sim.Config()))
    m1 = run_with(_small_scan_cfg(), live)
    live.log.close()

    cfg = _small_scan_cfg()
    cfg.sensor = {"name": "replay", "path": str(tmp_path / "live" / "run.mcap")}
    cfg.pantilt = {"name": "replay", "path": str(tmp_path / "live" / "run.mcap")}
    replay = Ctx(tmp_path / "replay", lambda kind: Replay(ReplayConfig(path=str(tmp_path / "live" / "run.mcap"))))
    m2 = run_with(cfg, replay)
    replay.log.close()
    assert m1 == m2 and "sky_accuracy" in m2
    np.testing.assert_array_equal(np.load(tmp_path / "live" / "scans.npz")["counts"],
                                  np.load(tmp_path / "replay" / "scans.npz")["counts"])


def test_scan_with_the_simulated_ptu46_quantisation(scene):
    """pantilt=sim quantises poses to 185.1428 arc-seconds; prefetched columns still serve the reads."""
    from bionav.plugins.sensors.pantilt_sim import PanTiltSim, PanTiltSimConfig

    grid = ScanGrid.from_steps(n_pan=4, pan_step=np.deg2rad(2.0), n_tilt=3, tilt_step=np.deg2rad(3.0),
                               tilt_start=np.deg2rad(-3.0))
    sensor = Spectral5Sim(Spectral5Sim.Config(noise_counts=0.0))
    ptu = PanTiltSim(PanTiltSimConfig())
    for dev in (sensor, ptu):
        dev.attach_simulation(scene, np.random.default_rng(0))
    moves = []
    direct = run_scan(sensor, ptu, grid, on_move=moves.append)
    res = np.deg2rad(185.1428 / 3600)
    assert all(abs(m["pan"] / res - round(m["pan"] / res)) < 1e-9 for m in moves)
    from bionav.experiments.contrast_scan.run import _reached

    calls = []
    original = scene.render
    scene.render = lambda *a, **k: (calls.append(1), original(*a, **k))[1]
    try:
        prefetched = run_scan(sensor, ptu, grid, before_column=lambda j: scene.prefetch(
            *_reached(ptu, np.full(3, grid.pans[j]), grid.tilts)))
    finally:
        del scene.render
    np.testing.assert_array_equal(prefetched, direct)
    assert len(calls) == 4  # one render per column: every read was served from the prefetch


def test_contrast_scan_over_the_serial_drivers_and_fakes(tmp_path, scene):
    """experiment=contrast_scan with sensor=spectral5_serial and pantilt=ptu46 against fakes on ptys."""
    from bionav.plugins.sensors.fakes.ptu46 import FakePTU46
    from bionav.plugins.sensors.ptu46 import PTU46, PTU46Config

    sim = Spectral5Sim(Spectral5Sim.Config(noise_counts=0.0))
    sim.attach_simulation(scene, None)
    ptu_fake = FakePTU46(scene.set_pose)
    ptu_fake.start()
    board = FakeSpectral5(source=sim.measure)
    try:
        cfg = _small_scan_cfg()
        cfg.experiment.n_pan, cfg.experiment.n_tilt = 4, 3
        cfg.experiment.times = cfg.experiment.times[:1]
        cfg.experiment.cloud_cover, cfg.experiment.cloud_optical_depth = 0.8, 30.0
        cfg.sensor = {"name": "spectral5_serial", "port": board.port}
        cfg.pantilt = {"name": "ptu46", "port": ptu_fake.port}

        class Ctx(FakeContext):
            def plugin(self, kind, node, **kw):
                if node.name == "ptu46":
                    return PTU46(PTU46Config(port=node.port, settle_s=0.02))
                return Spectral5Serial(Spectral5Serial.Config(port=node.port, timeout_s=1.0))

        ctx = Ctx(tmp_path)
        m = run_with(cfg, ctx)
    finally:
        board.close()
        ptu_fake.stop()
    assert m["n_scans"] == 1 and m["n_readings"] == 12 and "sky_accuracy" not in m
    assert board.commands.count(b"M1") == 12
    counts = np.load(tmp_path / "scans.npz")["counts"][0]
    # the pixels are what the simulated sensor sees at the PTU's reached poses
    states = [msg for topic, msg, _ in ctx.log.messages if topic == "/pantilt/state"]
    model = LogSensorModel(noise_counts=0.0)
    last = states[2]  # first column, highest tilt -> row 0
    want = np.clip(np.rint(model.ideal_counts(scene.band_radiance(last["pan"], last["tilt"]))), 0, 4095)
    np.testing.assert_array_equal(counts[0, 0, :5], want)
