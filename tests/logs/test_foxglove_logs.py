"""run.mcap as Foxglove reads it: Foxglove's own schemas, supported image encodings, real dates, strict JSON."""

import base64
import json
import time

import numpy as np
import pytest
from helpers import run_bionav
from mcap.reader import make_reader

from bionav.logs.foxglove import RAW_IMAGE_ENCODINGS, foxglove_schema, foxglove_schema_names
from bionav.logs.writer import McapLog
from bionav.robot.recording import decode_capture, encode_capture, raw_image_from_array

jsonschema = pytest.importorskip("jsonschema")


def _strict_json(data: bytes):
    def no_constants(name):
        raise ValueError(f"non-standard JSON constant {name}")

    return json.loads(data, parse_constant=no_constants)


def check_foxglove_messages(path) -> dict[str, int]:
    """Validate every message on a Foxglove-named channel against Foxglove's schema; counts per schema."""
    counts: dict[str, int] = {}
    with open(path, "rb") as f:
        for schema, channel, message in make_reader(f).iter_messages():
            payload = _strict_json(message.data)  # every message, any channel: strict JSON (no NaN)
            if not schema.name.startswith("foxglove."):
                continue
            official = foxglove_schema(schema.name)
            assert json.loads(schema.data) == official, f"{channel.topic}: the stored schema is not Foxglove's"
            jsonschema.Draft7Validator(official).validate(payload)
            if schema.name == "foxglove.RawImage":
                assert payload["encoding"] in RAW_IMAGE_ENCODINGS
                raw = base64.b64decode(payload["data"])
                assert len(raw) == payload["step"] * payload["height"]
            stamp = payload.get("timestamp")
            if stamp is not None:
                assert stamp["sec"] * 1_000_000_000 + stamp["nsec"] == message.log_time
            counts[schema.name] = counts.get(schema.name, 0) + 1
    return counts


def test_vendored_schemas_are_foxglove_json_schemas():
    names = foxglove_schema_names()
    assert {"foxglove.PoseInFrame", "foxglove.RawImage", "foxglove.FrameTransform"} <= set(names)
    raw = foxglove_schema("foxglove.RawImage")
    assert set(raw["required"]) == {"timestamp", "frame_id", "width", "height", "encoding", "step", "data"}
    for name in names:
        jsonschema.Draft7Validator.check_schema(foxglove_schema(name))


def test_writer_uses_foxglove_schema_and_refuses_non_finite(tmp_path):
    path = tmp_path / "t.mcap"
    ns = time.time_ns()
    pose = {"timestamp": {"sec": ns // 10**9, "nsec": ns % 10**9}, "frame_id": "world",
            "pose": {"position": {"x": 1.0, "y": 2.0, "z": 0.0}, "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}}}
    with McapLog(path) as log:
        # a weaker caller schema is replaced by Foxglove's
        log.write("/pose", pose, schema_name="foxglove.PoseInFrame", schema={"type": "object"}, log_time_ns=ns)
        bad = json.loads(json.dumps(pose))
        bad["pose"]["position"]["x"] = float("nan")
        with pytest.raises(ValueError, match="NaN or infinity"):
            log.write("/pose", bad, schema_name="foxglove.PoseInFrame", log_time_ns=ns)
        log.write("/stats", {"aae": float("nan"), "v": np.array([1.0, np.inf]), "ok": 0.5}, schema_name="bionav.Stats")
        with pytest.raises(ValueError, match="no schema"):
            log.write("/x", {}, schema_name="foxglove.NoSuchThing")
    assert check_foxglove_messages(path) == {"foxglove.PoseInFrame": 1}
    with open(path, "rb") as f:
        stats = [_strict_json(m.data) for _, c, m in make_reader(f).iter_messages() if c.topic == "/stats"]
    assert stats == [{"aae": None, "v": [1.0, None], "ok": 0.5}]


def test_raw_image_encodings_and_lossless_captures():
    rng = np.random.default_rng(0)
    f64 = rng.random((4, 6))
    msg = raw_image_from_array(f64, timestamp_ns=1_700_000_000_123_456_789, frame_id="camera")
    assert (msg["encoding"], msg["width"], msg["height"], msg["step"]) == ("32FC1", 6, 4, 24)
    back = np.frombuffer(base64.b64decode(msg["data"]), "<f4").reshape(4, 6)
    np.testing.assert_array_equal(back, f64.astype(np.float32))
    assert msg["timestamp"] == {"sec": 1_700_000_000, "nsec": 123_456_789}
    assert raw_image_from_array(np.zeros((2, 3), np.uint8), timestamp_ns=0, frame_id="c")["encoding"] == "mono8"
    assert raw_image_from_array(np.zeros((2, 3), np.uint16), timestamp_ns=0, frame_id="c")["step"] == 6
    with pytest.raises(ValueError):
        raw_image_from_array(np.zeros(3), timestamp_ns=0, frame_id="c")
    jsonschema.validate(msg, foxglove_schema("foxglove.RawImage"))
    for a in (f64, f64.astype(np.float32), np.array([1.5, -2.0, 3.25]), np.arange(6, dtype=np.uint16).reshape(2, 3)):
        out = decode_capture(encode_capture(a))
        assert out.dtype == a.dtype and out.shape == a.shape
        np.testing.assert_array_equal(out, a)


def test_recorded_panoramas_are_foxglove_images_and_replay_exactly(tmp_path):
    """Rendered panoramas grabbed during ticks: RawImage for Foxglove, exact captures for replay, real dates."""
    from types import SimpleNamespace

    from bionav.logs.reader import read_messages
    from bionav.robot.controller import Command, Observation
    from bionav.robot.kinematics import Pose
    from bionav.robot.recording import EpisodeRecorder, load_logged_runs
    from bionav.robot.simulator import image_digest
    from bionav.testing.pillar_scene import render_pillar_panorama

    views = [render_pillar_panorama((0.5 + 0.2 * k, 0.4), width=96, height=16, supersample=1)[0] for k in range(3)]
    path = tmp_path / "run.mcap"
    before = time.time_ns()
    with McapLog(path) as log:
        recorder = EpisodeRecorder(log, 0, time_offset_ns=log.start_ns, log_images=True)
        recorder.start({"controller": "test"})
        for tick, view in enumerate(views):
            robot = SimpleNamespace(captures=[(view, Pose(0.1 * tick, 0.0, 0.0), tick)], pose=Pose(0.1 * tick, 0.0, 0.0))
            obs = Observation(time=0.5 * tick, odometry=Pose(0.1 * tick, 0.0, 0.0), camera=None, wall=None, bumper=False)
            recorder.on_tick(tick, obs, Command(0.1, 0.1), robot)
    assert check_foxglove_messages(path) == {"foxglove.RawImage": 3, "foxglove.PoseInFrame": 1}
    images = [m for t, _, m in read_messages(path) if t == "/cleaning/image"]
    assert [m["timestamp"]["sec"] * 10**9 + m["timestamp"]["nsec"] for m in images] == [
        log.start_ns + int(0.5e9) * k for k in range(3)]
    assert log.start_ns >= before  # the wall clock of the run, not 1970
    run = load_logged_runs(read_messages(path))[0]
    for k, view in enumerate(views):
        assert image_digest(run.images[k]) == image_digest(view)  # bit-identical for replay


@pytest.mark.slow
def test_oracle_cleaning_log_is_foxglove_valid(tmp_path):
    run_dir = tmp_path / "run"
    proc = run_bionav("experiment=cleaning", "experiment.vision=oracle", "runs=2", "layout=long_lanes",
                      "layout.n_lanes=2", "layout.lane_length=1.0", "experiment.log_images=true",
                      f"hydra.run.dir={run_dir}", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    counts = check_foxglove_messages(run_dir / "run.mcap")
    assert counts.get("foxglove.PoseInFrame", 0) > 0
    assert "foxglove.RawImage" not in counts  # the oracle's pose vectors are no images
    replay = run_bionav(str(run_dir), cwd=tmp_path, module="bionav.experiments.cleaning_replay")
    assert replay.returncode == 0, replay.stderr
