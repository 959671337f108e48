"""``python -m bionav.logs export-ros2 RUN OUT``: written by rosbags, read back by mcap-ros2-support's decoder."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from helpers import assert_fails_cleanly, run_bionav

pytest.importorskip("rosbags")
mcap_ros2 = pytest.importorskip("mcap_ros2.decoder")

from bionav.logs.foxglove import foxglove_time, poses_in_frame  # noqa: E402
from bionav.logs.writer import McapLog  # noqa: E402
from bionav.robot.recording import raw_image_from_array  # noqa: E402


def decoded(bag_dir):
    """Every message of the exported bag's .mcap, decoded by mcap-ros2-support (not bionav, not rosbags)."""
    from mcap.reader import make_reader

    (path,) = list(bag_dir.glob("*.mcap"))
    out = {}
    with open(path, "rb") as f:
        for schema, channel, message, ros in make_reader(f, decoder_factories=[mcap_ros2.DecoderFactory()]) \
                .iter_decoded_messages():
            out.setdefault(channel.topic, []).append((schema.name, message.log_time, ros))
    return out


def _yaw(q):
    return math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))


def test_foxglove_types_become_ros2_types(tmp_path):
    from bionav.logs.ros2 import export_ros2

    ns = 1_700_000_000_123_456_789
    view = (np.arange(6 * 10, dtype=np.uint8).reshape(6, 10) * 4)
    with McapLog(tmp_path / "run.mcap") as log:
        log.attach("config.yaml", b"seed: 7\n", media_type="application/yaml")
        log.write("/views", raw_image_from_array(view, timestamp_ns=ns, frame_id="cell_1_2"),
                  schema_name="foxglove.RawImage", log_time_ns=ns)
        log.write("/pose", {"timestamp": foxglove_time(ns), "frame_id": "world",
                            "pose": {"position": {"x": 1.5, "y": -2.0, "z": 0.0},
                                     "orientation": {"x": 0.0, "y": 0.0, "z": math.sin(0.35), "w": math.cos(0.35)}}},
                  schema_name="foxglove.PoseInFrame", log_time_ns=ns + 1)
        log.write("/homes", poses_in_frame([[0.3, 0.6], [0.9, 0.0], [1.2, 0.3]], [0.5, float("nan"), -2.0],
                                           timestamp_ns=ns, frame_id="grid"),
                  schema_name="foxglove.PosesInFrame", log_time_ns=ns + 2)
        log.write("/result", {"aae": 0.25, "rows": [1, 2]}, schema_name="bionav.Result", log_time_ns=ns + 3)
    proc = run_bionav("export-ros2", str(tmp_path), str(tmp_path / "bag"), module="bionav.logs", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "wrote 4 messages" in proc.stdout
    got = decoded(tmp_path / "bag")
    (name, t, img), = got["/views"]
    assert name == "sensor_msgs/msg/Image" and t == ns and img.encoding == "mono8"
    assert (img.width, img.height, img.step, img.header.frame_id) == (10, 6, 10, "cell_1_2")
    assert img.header.stamp.sec * 10**9 + img.header.stamp.nanosec == ns
    assert np.array_equal(np.frombuffer(bytes(img.data), np.uint8).reshape(6, 10), view)
    (name, _t, pose), = got["/pose"]
    assert name == "geometry_msgs/msg/PoseStamped" and pose.header.frame_id == "world"
    assert (pose.pose.position.x, pose.pose.position.y) == (1.5, -2.0) and _yaw(pose.pose.orientation) == \
        pytest.approx(0.7)
    (name, _t, homes), = got["/homes"]
    assert name == "geometry_msgs/msg/PoseArray" and len(homes.poses) == 2  # the NaN direction left out
    assert [_yaw(p.orientation) for p in homes.poses] == pytest.approx([0.5, -2.0])
    (name, _t, result), = got["/result"]
    assert name == "std_msgs/msg/String" and json.loads(result.data) == {"aae": 0.25, "rows": [1, 2]}
    assert "bionav.config" in (tmp_path / "bag" / "metadata.yaml").read_text()
    # sqlite3 storage: a .db3 that rosbags reads back
    assert export_ros2(tmp_path / "run.mcap", tmp_path / "bag3", storage="sqlite3") == {
        "sensor_msgs/msg/Image": 1, "geometry_msgs/msg/PoseStamped": 1, "geometry_msgs/msg/PoseArray": 1,
        "std_msgs/msg/String": 1}
    assert list((tmp_path / "bag3").glob("*.db3"))
    # bad input: the output exists, the run does not
    proc = run_bionav("export-ros2", str(tmp_path), str(tmp_path / "bag"), module="bionav.logs", cwd=tmp_path)
    assert_fails_cleanly(proc, "already exists", "--force")
    proc = run_bionav("export-ros2", str(tmp_path / "nothing"), str(tmp_path / "b2"), module="bionav.logs",
                      cwd=tmp_path)
    assert_fails_cleanly(proc, "does not exist", "run.mcap")


@pytest.mark.slow
def test_a_grid_homing_run_exported(tmp_path):
    """A real run (a 3 x 3 db=folder, MFDID) with experiment.log_views: its views, their poses
    and every snapshot's home vectors reach the ROS 2 bag."""
    from helpers import write_tiny_folder

    from bionav.logs.reader import read_messages

    folder = write_tiny_folder(tmp_path / "db")
    run = tmp_path / "run"
    proc = run_bionav("db=folder", f"db.path={folder}", "db.spacing_m=0.5", "homing=mfdid", "experiment.log_views=true",
                      f"hydra.run.dir={run}", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    proc = run_bionav("export-ros2", str(run), str(tmp_path / "bag"), module="bionav.logs", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    got = decoded(tmp_path / "bag")
    views = got["/grid_homing/views"]
    assert len(views) == 9 and {v[0] for v in views} == {"sensor_msgs/msg/Image"}
    logged = [m for _t, _n, m in read_messages(run / "run.mcap", topics=["/grid_homing/views"])]
    import base64

    for (_n, _t, img), msg in zip(views, logged):
        assert img.encoding == "32FC1" and bytes(img.data) == base64.b64decode(msg["data"])
    (_n, _t, poses), = got["/grid_homing/view_poses"]
    cells = sorted((round(p.position.x / 0.5), round(p.position.y / 0.5)) for p in poses.poses)
    assert cells == [(x, y) for x in range(3) for y in range(3)]
    rows = [m for _t, _n, m in read_messages(run / "run.mcap", topics=["/grid_homing/snapshot_rows"])]
    arrows = got["/grid_homing/home_vector_poses"]
    assert len(arrows) == len(rows) == 9
    for (_n, _t, arr), row in zip(arrows, rows):
        want = [a for a in row["angles"] if a is not None]
        assert [_yaw(p.orientation) for p in arr.poses] == pytest.approx(want, abs=1e-9)
    assert got["/grid_homing/home_vectors"][0][0] == "std_msgs/msg/String"
