"""Hostile ROS bags through the user's door (``python -m bionav db=bag ...``): one clear message, exit 2, no traceback.

Every bag here is written by rosbags' writers and then damaged the way bags get damaged: cut short,
of a format version nobody reads, with misspelt or wrong topics, stamps that jump back, a camera that
changes its encoding or size, poses from another clock.
"""

from __future__ import annotations

import shutil

import numpy as np
import pytest
from helpers import assert_fails_cleanly, run_bionav
from rosbag_helpers import CELL_M, T0_NS, drive_poses, lawnmower, pillar_views, write_drive

pytest.importorskip("rosbags")

CELLS = lawnmower()
TOPICS = ("db.image_topic=/camera/image", "db.pose_topic=/odom", f"db.grid_cell_m={CELL_M}")


@pytest.fixture(scope="module")
def good(tmp_path_factory):
    """One well-formed drive per container, and the views."""
    root = tmp_path_factory.mktemp("bags")
    views = pillar_views(CELLS, width=48, height=8)
    images = [(T0_NS + k * 10**9, v) for k, v in enumerate(views)]
    bags = {c: write_drive(root / f"drive_{c}", c, images=images, poses=drive_poses(CELLS)) for c in
            ("ros1", "sqlite3", "mcap")}
    return root, views, bags


def _fails(tmp_path, *args, needles, code=2):
    proc = run_bionav("db=bag", *args, f"hydra.run.dir={tmp_path / 'run'}", cwd=tmp_path, timeout=300)
    return assert_fails_cleanly(proc, *needles, code=code)


def _truncated(src, dst, fraction=0.6):
    data = src.read_bytes()
    dst.write_bytes(data[: int(len(data) * fraction)])
    return dst


@pytest.mark.slow
def test_no_topic_lists_the_topics_and_names_the_keys(tmp_path, good):
    _root, _views, bags = good
    msg = _fails(tmp_path, f"db.path={bags['mcap']}", f"db.grid_cell_m={CELL_M}",
                 needles=("db.image_topic and db.pose_topic are not set", "/camera/image (sensor_msgs/msg/Image, 12 "
                          "messages)", "/odom (nav_msgs/msg/Odometry", "Set db.image_topic=TOPIC db.pose_topic=TOPIC"))
    assert "Pose topics:" in msg and "Image topics:" in msg


@pytest.mark.slow
@pytest.mark.parametrize("args,needles", [
    (("db.image_topic=/camera/imag", "db.pose_topic=/odom"),
     ("has no topic '/camera/imag'", "Did you mean db.image_topic=/camera/image?")),
    (("db.image_topic=/camera/image", "db.pose_topic=/nothing"), ("db.pose_topic=/nothing", "has no topic",
                                                                  "/odom (nav_msgs/msg/Odometry")),
    (("db.image_topic=/odom", "db.pose_topic=/odom"),
     ("db.image_topic=/odom is a nav_msgs/msg/Odometry topic, not image", "/camera/image (sensor_msgs/msg/Image")),
    (("db.image_topic=/camera/image", "db.pose_topic=/camera/image"),
     ("db.pose_topic=/camera/image is a sensor_msgs/msg/Image topic, not pose",)),
])
def test_missing_misspelt_and_mistyped_topics(tmp_path, good, args, needles):
    _fails(tmp_path, f"db.path={good[2]['ros1']}", f"db.grid_cell_m={CELL_M}", *args, needles=needles)


@pytest.mark.slow
@pytest.mark.parametrize("container,needles", [
    ("ros1", ("cannot read the ROS 1 bag", "rosbag reindex")),
    ("mcap", ("cannot read the ROS 2 bag (mcap)", "mcap recover")),
    ("sqlite3", ("cannot read the ROS 2 bag (sqlite3)", ".recover")),
])
def test_truncated_bags(tmp_path, good, container, needles):
    src = good[2][container]
    if container == "ros1":
        bag = _truncated(src, tmp_path / "cut.bag")
    else:
        inner = next(src.glob("*.mcap" if container == "mcap" else "*.db3"))
        bag = _truncated(inner, tmp_path / f"cut{inner.suffix}")
    _fails(tmp_path, f"db.path={bag}", *TOPICS, needles=(*needles, "cut short"))


@pytest.mark.slow
def test_unknown_bag_versions(tmp_path, good):
    data = good[2]["ros1"].read_bytes()
    assert data.startswith(b"#ROSBAG V2.0\n")
    (tmp_path / "v9.bag").write_bytes(b"#ROSBAG V9.9\n" + data[13:])
    _fails(tmp_path, f"db.path={tmp_path / 'v9.bag'}", *TOPICS,
           needles=("cannot read the ROS 1 bag", "version", "pip install -U rosbags"))
    folder = shutil.copytree(good[2]["sqlite3"], tmp_path / "v99")
    meta = folder / "metadata.yaml"
    meta.write_text(meta.read_text().replace("version: 9", "version: 99", 1))
    _fails(tmp_path, f"db.path={folder}", *TOPICS, needles=("ROS 2 bag folder", "version 99", "ros2 bag convert"))


@pytest.mark.slow
def test_not_a_bag(tmp_path, good):
    (tmp_path / "notes.txt").write_text("hello")
    _fails(tmp_path, f"db.path={tmp_path / 'notes.txt'}", *TOPICS, needles=("is not a ROS bag by its name",))
    (tmp_path / "empty.bag").write_bytes(b"")
    _fails(tmp_path, f"db.path={tmp_path / 'empty.bag'}", *TOPICS, needles=("is empty",))
    loose = tmp_path / "loose"
    loose.mkdir()
    shutil.copy(next(good[2]["mcap"].glob("*.mcap")), loose / "x.mcap")
    _fails(tmp_path, f"db.path={loose}", *TOPICS, needles=("without metadata.yaml", "x.mcap", "db.path"))
    _fails(tmp_path, f"db.path={tmp_path / 'nowhere.bag'}", *TOPICS, needles=("does not exist", "db.path"))
    _fails(tmp_path, *TOPICS, needles=("db=bag needs the bag: pass db.path=BAG",))
    _fails(tmp_path, f"db.path={good[2]['mcap']}", "db.image_topic=/camera/image", "db.pose_topic=/odom",
           needles=("db.grid_cell_m=METRES",))


@pytest.mark.slow
def test_stamps_that_jump_back(tmp_path, good):
    from rosbag_helpers import BagWriter

    _root, views, _bags = good
    w = BagWriter(tmp_path / "jump", "mcap")
    for t, x, y, yaw in drive_poses(CELLS):
        w.put("/odom", t, w.odometry(t, x, y, yaw))
    for k, v in enumerate(views):  # recorded in order; the camera's clock jumps back 30 s at image 6
        t = T0_NS + k * 10**9
        w.put("/camera/image", t + 10**6, w.image(t - (30 * 10**9 if k >= 6 else 0), v, "mono8"))
    bag = w.close()
    _fails(tmp_path, f"db.path={bag}", *TOPICS,
           needles=("image stamps of /camera/image go back in time by 29.000 s at message 6", "db.stamps=bag"))


@pytest.mark.slow
def test_images_changing_encoding_or_size(tmp_path, good):
    _root, views, _bags = good
    images = [(T0_NS + k * 10**9, v if k < 5 else np.ascontiguousarray(v[:, ::2])) for k, v in enumerate(views)]
    bag = write_drive(tmp_path / "size", "sqlite3", images=images, poses=drive_poses(CELLS))
    _fails(tmp_path, f"db.path={bag}", *TOPICS, needles=("change at message 5", "mono8 48 x 8", "mono8 24 x 8",
                                                          "db.on_bad_image=skip"))
    from rosbag_helpers import BagWriter

    w = BagWriter(tmp_path / "enc", "ros1")
    for k, v in enumerate(views):
        t = T0_NS + k * 10**9
        w.put("/camera/image", t, w.image(t, v if k % 2 else np.stack([v] * 3, axis=-1), "mono8" if k % 2 else "rgb8"))
    for t, x, y, yaw in drive_poses(CELLS):
        w.put("/odom", t, w.odometry(t, x, y, yaw))
    bag = w.close()
    _fails(tmp_path, f"db.path={bag}", *TOPICS, needles=("change at message 1", "rgb8", "mono8"))
    proc = run_bionav("db=bag", f"db.path={bag}", *TOPICS, "db.on_bad_image=skip", "experiment.snapshots=[0]",
                      f"hydra.run.dir={tmp_path / 'skip'}", cwd=tmp_path, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert "6 image(s) of another encoding or size than the first left out" in proc.stdout + proc.stderr


@pytest.mark.slow
def test_poses_from_another_clock(tmp_path, good):
    _root, views, _bags = good
    poses = [(t + 3600 * 10**9, x, y, yaw) for t, x, y, yaw in drive_poses(CELLS)]
    bag = write_drive(tmp_path / "clock", "mcap", images=[(T0_NS + k * 10**9, v) for k, v in enumerate(views)],
                      poses=poses)
    _fails(tmp_path, f"db.path={bag}", *TOPICS,
           needles=("none of the 12 images of /camera/image", "db.pose_tolerance_s=0.1", "db.stamps=bag"))


@pytest.mark.slow
def test_missing_rosbags_names_the_install_line(tmp_path, good):
    blocker = tmp_path / "site" / "rosbags"
    blocker.mkdir(parents=True)
    (blocker / "__init__.py").write_text("raise ImportError('rosbags is blocked for this test')\n")
    proc = run_bionav("db=bag", f"db.path={good[2]['mcap']}", *TOPICS, f"hydra.run.dir={tmp_path / 'run'}",
                      cwd=tmp_path, env={"PYTHONPATH": str(tmp_path / "site")})
    assert_fails_cleanly(proc, "needs the Python package 'rosbags'", 'pip install "bionav[ros]"', code=2)
