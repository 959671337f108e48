"""A logged cleaning run fed back through its controller reproduces every command exactly."""

from dataclasses import replace

import numpy as np
import pytest
from omegaconf import OmegaConf

from bionav.experiments.cleaning.config import CleaningConfig
from bionav.experiments.cleaning.run import simulate
from bionav.experiments.context import RunContext
from bionav.logs.reader import read_messages
from bionav.logs.writer import McapLog
from bionav.plugins.controllers.random_bounce import RandomConfig, RandomController
from bionav.plugins.controllers.triangulation import TriangulationConfig, TriangulationController
from bionav.robot.controller import LanePlan
from bionav.robot.oracle import GeometricHoming, GeometricHomingConfig, oracle_camera
from bionav.robot.recording import ReplayMismatch, load_logged_runs, replay_episode
from bionav.robot.worldview import oracle_world
from bionav.validation import typed_config

PROG = "bionav.experiments.cleaning_replay"  # as run_main names every command in its messages

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
        ex = typed_config(cfg.experiment, CleaningConfig, key="experiment")
        results = simulate(ex, cfg, ctx, oracle_world(PLAN), PLAN, make_controller, homing)
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


# -- logs recorded before issue 28 (controller.track_width, now experiment.track_width alone) --------------------

def _with_config(src, dst, edit):
    """Copy the log ``src`` to ``dst`` with its attached config.yaml passed through ``edit(dict) -> None``
    (a log recorded by an earlier bionav, whose config had other keys)."""
    import yaml
    from mcap.reader import make_reader
    from mcap.writer import Writer

    with open(src, "rb") as fin, open(dst, "wb") as fout:
        reader = make_reader(fin)
        writer = Writer(fout)
        writer.start(profile="bionav", library="test")
        schemas, channels = {}, {}
        for schema, channel, message in reader.iter_messages(log_time_order=False):
            if schema is not None and schema.id not in schemas:
                schemas[schema.id] = writer.register_schema(schema.name, schema.encoding, schema.data)
            if channel.id not in channels:
                channels[channel.id] = writer.register_channel(channel.topic, channel.message_encoding,
                                                               schemas.get(channel.schema_id, 0), channel.metadata)
            writer.add_message(channels[channel.id], message.log_time, message.data, message.publish_time,
                               message.sequence)
        for a in reader.iter_attachments():
            data = a.data
            if a.name == "config.yaml":
                cfg = yaml.safe_load(data.decode())
                edit(cfg)
                data = yaml.safe_dump(cfg).encode()
            writer.add_attachment(a.create_time, a.log_time, a.name, a.media_type, data)
        for m in reader.iter_metadata():
            writer.add_metadata(m.name, m.metadata)
        writer.finish()
    return dst


@pytest.mark.slow
def test_a_log_recorded_with_the_controllers_track_width_still_replays(tmp_path):
    """Through the documented command: ``python -m bionav.experiments.cleaning_replay RUN_DIR``."""
    from helpers import run_bionav

    run_dir = tmp_path / "run"
    proc = run_bionav("experiment=cleaning", "experiment.vision=oracle", "runs=1", "layout=long_lanes",
                      "layout.n_lanes=2", "layout.lane_length=1.0", "experiment.track_width=0.4",
                      f"hydra.run.dir={run_dir}", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr

    def replay(name, edit):
        path = _with_config(run_dir / "run.mcap", tmp_path / f"{name}.mcap", edit)
        return run_bionav(str(path), cwd=tmp_path, module="bionav.experiments.cleaning_replay")

    def both(cfg):  # as written before issue 28: the controller's belief beside the robot's
        cfg["controller"]["track_width"] = 0.4

    def legacy_only(cfg):
        cfg["controller"]["track_width"] = cfg["experiment"].pop("track_width")

    def neither(cfg):  # the control: without the legacy value the default 0.30 m turns differently
        del cfg["experiment"]["track_width"]

    for name, edit in (("both", both), ("legacy_only", legacy_only)):
        out = replay(name, edit)
        assert out.returncode == 0, out.stderr
        assert "every command identical" in out.stdout and "Traceback" not in out.stderr
        info = [line for line in out.stderr.splitlines() if "legacy keys" in line]
        assert info == [f"INFO: {tmp_path / name}.mcap: recorded with legacy keys, read as today's: "
                        "controller.track_width=0.4 -> experiment.track_width"], out.stderr
    out = replay("neither", neither)
    assert out.returncode == 2 and "Traceback" not in out.stderr
    assert "legacy" not in out.stderr

    def disagree(cfg):  # a run whose controller believed another width than the robot had
        cfg["controller"]["track_width"] = 0.3

    out = replay("disagree", disagree)
    assert out.returncode == 2 and "Traceback" not in out.stderr and out.stdout == ""
    assert out.stderr.startswith(f"{PROG}: error: {tmp_path / 'disagree.mcap'} was recorded with controller.track_width=0.3 "
                                 "and experiment.track_width=0.4"), out.stderr
    assert "Replay it with the bionav version that recorded it (bionav " in out.stderr


def test_a_legacy_track_width_that_disagrees_is_one_clear_error(tmp_path):
    from bionav.errors import UserError
    from bionav.experiments.settings import config_from_recorded

    recorded = OmegaConf.create({"experiment": {"name": "cleaning", "track_width": 0.3},
                                 "controller": {"name": "odometry", "track_width": 0.35}})
    with pytest.raises(UserError) as err:
        config_from_recorded(recorded, source="old/run.mcap", recorded_by="bionav 0.0.9")
    assert str(err.value) == (
        "old/run.mcap was recorded with controller.track_width=0.35 and experiment.track_width=0.3, two values "
        "that are one setting today (experiment.track_width); this bionav cannot reproduce that run. Replay it "
        "with the bionav version that recorded it (bionav 0.0.9).")
    assert recorded.controller.track_width == 0.35  # the recorded config is not modified


def test_a_config_without_legacy_keys_is_read_as_it_is(caplog):
    from bionav.experiments.settings import config_from_recorded

    recorded = OmegaConf.create({"experiment": {"name": "cleaning", "track_width": 0.3}, "controller": {"name": "x"}})
    with caplog.at_level("INFO"):
        assert config_from_recorded(recorded, source="run.mcap") is recorded
    assert caplog.records == []
