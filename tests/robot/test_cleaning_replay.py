"""A logged cleaning run fed back through its controller reproduces every command exactly."""

from dataclasses import replace

import numpy as np
import pytest
from omegaconf import OmegaConf

from bionav.experiments.cleaning import oracle_world, simulate
from bionav.experiments.context import RunContext
from bionav.logs.reader import read_messages
from bionav.logs.writer import McapLog
from bionav.plugins.controllers.random_bounce import RandomConfig, RandomController
from bionav.plugins.controllers.triangulation import TriangulationConfig, TriangulationController
from bionav.robot.controller import LanePlan
from bionav.robot.oracle import GeometricHoming, GeometricHomingConfig, oracle_camera
from bionav.robot.recording import ReplayMismatch, load_logged_runs, replay_episode

PLAN = LanePlan(n_lanes=3, lane_length=1.2)

EXPERIMENT = {
    "runs": 2, "wheel_error": 0.05, "track_width": 0.30, "robot_radius": 0.17, "start_position_std": 0.01,
    "start_heading_std_deg": 1.0, "dt": 0.1, "time_limit_factor": 3.0, "raster_cell": 0.01, "raster_margin": 0.5,
    "log_images": False,
}


def record(tmp_path, make_controller, homing, *, log_images=False, name="triangulation"):
    cfg = OmegaConf.create({"experiment": {**EXPERIMENT, "log_images": log_images}, "controller": {"name": name},
                            "seed": 3})
    path = tmp_path / "run.mcap"
    with McapLog(path) as log:
        ctx = RunContext(dir=tmp_path, log=log, rng=np.random.default_rng(3), cfg=cfg, show_progress=False)
        results = simulate(cfg, ctx, oracle_world(PLAN), PLAN, make_controller, homing)
    return results, load_logged_runs(read_messages(path))


def test_replay_triangulation_exactly(tmp_path):
    cfg = TriangulationConfig()
    homing = GeometricHoming(GeometricHomingConfig(angle_noise_deg=4.0, compass_noise_deg=2.0, seed=5))
    results, runs = record(tmp_path, lambda: TriangulationController(cfg), homing)
    assert sorted(runs) == [0, 1]
    assert runs[0].meta["wheel_error"] == [0.05, -0.05] and runs[1].meta["wheel_error"] == [-0.05, 0.05]
    for k, run in runs.items():
        out = replay_episode(run, TriangulationController(cfg), PLAN, homing=homing, camera=oracle_camera)
        assert out.n_ticks == len(results[k].episode.time)
        # bit-identical to what the controller sent during the run (before motor clipping)
        logged = np.array([s["command"] for s in run.steps])
        np.testing.assert_array_equal(out.commands, logged)
        assert any(s["captures"] for s in run.steps)
    # another controller config does not reproduce the run
    with pytest.raises(ReplayMismatch):
        replay_episode(runs[0], TriangulationController(replace(cfg, fix_gain=0.4)), PLAN, homing=homing,
                       camera=oracle_camera)
    # without images in the log and without a camera the replay says what is missing
    with pytest.raises(ReplayMismatch, match="not in the log"):
        replay_episode(runs[0], TriangulationController(cfg), PLAN, homing=homing)


def test_replay_from_logged_images(tmp_path):
    cfg = TriangulationConfig()
    homing = GeometricHoming(GeometricHomingConfig(angle_noise_deg=4.0, seed=1))
    _, runs = record(tmp_path, lambda: TriangulationController(cfg), homing, log_images=True)
    assert runs[1].images
    out = replay_episode(runs[1], TriangulationController(cfg), PLAN, homing=homing)  # no camera needed
    np.testing.assert_array_equal(out.commands, np.array([s["command"] for s in runs[1].steps]))


def test_replay_random_uses_logged_seed(tmp_path):
    cfg = RandomConfig()
    _, runs = record(tmp_path, lambda: RandomController(cfg), None, name="random")
    out = replay_episode(runs[0], RandomController(cfg), PLAN)
    np.testing.assert_array_equal(out.commands, np.array([s["command"] for s in runs[0].steps]))
    bad = runs[0]
    bad.meta["controller_seed"] += 1
    with pytest.raises(ReplayMismatch):
        replay_episode(bad, RandomController(cfg), PLAN)
