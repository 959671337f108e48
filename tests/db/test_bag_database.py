"""db=bag: ROS bags written by rosbags' writers (ROS 1, ROS 2 sqlite3, ROS 2 mcap) read as grid databases.

The drive is a boustrophedon over 4 x 3 cells of the pillar room; the views are rendered at the cell
centres, the poses sampled at 20 Hz, 7 ms off the images' stamps. The database from the bag must equal
``db=folder`` of the same images bit for bit.
"""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest
from rosbag_helpers import CELL_M, ORIGIN, T0_NS, drive_poses, lawnmower, pillar_views, write_drive

pytest.importorskip("rosbags")

from bionav.db.bag.grid import bin_views, load_bag_database  # noqa: E402
from bionav.db.bag.poses import PoseTrack, bracket  # noqa: E402
from bionav.db.config import DatabaseConfig  # noqa: E402
from bionav.db.folder import load_folder  # noqa: E402

CELLS = lawnmower()


def _pixels(u8: np.ndarray, encoding: str) -> np.ndarray:
    """What the camera publishes for an 8-bit grey view in ``encoding`` (colour: three different channels)."""
    if encoding == "mono16":
        return u8.astype(np.uint16) * 257
    if encoding in ("rgb8", "bgr8"):
        rgb = np.stack([u8, u8 // 2, 255 - u8], axis=-1)
        return rgb if encoding == "rgb8" else rgb[..., ::-1].copy()
    return u8


def _write_folder(folder, views, encoding):
    """The same views as files, written the way the camera would store them."""
    folder.mkdir()
    for (i, j), u8 in zip(CELLS, views):
        px = _pixels(u8, encoding)
        if encoding == "rgb8":
            px = px[..., ::-1].copy()  # OpenCV writes BGR
        if encoding in ("png", "jpeg"):
            ok, buf = cv2.imencode(".png" if encoding == "png" else ".jpg", u8)
            (folder / f"{i}_{j}.{'png' if encoding == 'png' else 'jpg'}").write_bytes(buf.tobytes())
        else:
            cv2.imwrite(str(folder / f"{i}_{j}.png"), px)
    return folder


def _bag_cfg(path, **kw):
    base = dict(name="bag", source="bag", path=str(path), image_topic="/camera/image", pose_topic="/odom",
                grid_cell_m=CELL_M, azimuth="counterclockwise")
    base.update(kw)
    return DatabaseConfig(**base)


@pytest.fixture(scope="module")
def views():
    return pillar_views(CELLS)


COMBOS = [("ros1", "mono8", "odom"), ("ros1", "jpeg", "tf"), ("ros1", "rgb8", "pose"),
          ("sqlite3", "png", "odom"), ("sqlite3", "mono16", "tf"), ("sqlite3", "bgr8", "pose"),
          ("mcap", "mono8", "tf"), ("mcap", "jpeg", "odom"), ("mcap", "png", "pose"), ("mcap", "rgb8", "odom")]


@pytest.mark.parametrize("container,encoding,pose_kind", COMBOS)
def test_bag_database_equals_folder_bit_for_bit(tmp_path, views, container, encoding, pose_kind):
    images = [(T0_NS + k * 10**9, _pixels(v, encoding)) for k, v in enumerate(views)]
    if encoding in ("png", "jpeg"):
        images = [(t, v) for (t, _), v in zip(images, views)]
    bag = write_drive(tmp_path / "drive", container, images=images, poses=drive_poses(CELLS), encoding=encoding,
                      pose_kind=pose_kind)
    topic = {"odom": "/odom", "pose": "/pose", "tf": "/tf"}[pose_kind]
    db = load_bag_database(_bag_cfg(bag, pose_topic=topic))
    folder = _write_folder(tmp_path / "folder", views, encoding)
    ref = load_folder(DatabaseConfig(name="bag", source="folder", path=str(folder), azimuth="counterclockwise",
                                     spacing_m=CELL_M), folder)
    assert db.images.dtype == ref.images.dtype == np.float32
    assert np.array_equal(db.images, ref.images)
    assert np.array_equal(db.positions, ref.positions)
    assert db.grid_shape == ref.grid_shape == (4, 3)
    assert db.geometry == ref.geometry and db.spacing_m == ref.spacing_m
    assert np.all(db.headings == 0)
    # every view was binned to the cell it was taken at; none left out
    assert db.meta["n_uncovered"] == 0 and db.meta["n_missing_cells"] == 0
    assert max(db.meta["offsets_m"]) < 0.02  # corners cut by less than one pose step (0.3 m / 20)
    assert db.meta["origin_m"] == pytest.approx(list(ORIGIN), abs=0.02)


def test_headings_align_views_to_the_world_frame(tmp_path):
    """A robot turning on the spot: views taken at headings of whole columns, aligned to world +x bit for bit;
    db.align=false keeps the robot frame and records the heading."""
    width = 96
    cells = CELLS[:6]
    headings = [2 * math.pi * k * 7 / width for k in range(len(cells))]  # whole columns
    robot_views = pillar_views(cells, headings=headings)
    world_views = pillar_views(cells)

    def yaw(t):
        k = min(max((t - T0_NS) / 1e9, 0.0), len(cells) - 1)
        lo = int(min(k, len(cells) - 2))
        return headings[lo] + (k - lo) * (headings[lo + 1] - headings[lo])

    bag = write_drive(tmp_path / "turn", "mcap", images=[(T0_NS + k * 10**9, v) for k, v in enumerate(robot_views)],
                      poses=drive_poses(cells, rate_hz=1000, offset_ns=0, yaw=yaw))
    aligned = load_bag_database(_bag_cfg(bag))
    raw = load_bag_database(_bag_cfg(bag, align=False))
    order = [cells.index(tuple(p)) for p in aligned.positions]
    assert np.array_equal(aligned.images, np.stack(world_views)[order].astype(np.float32) / np.float32(255))
    assert np.all(aligned.headings == 0)
    assert np.allclose(raw.headings, np.mod(np.array(headings)[order], 2 * math.pi), atol=1e-9)
    assert np.array_equal(raw.images, np.stack(robot_views)[order].astype(np.float32) / np.float32(255))


def test_poses_covering_part_of_the_drive_leave_images_out(tmp_path, views, caplog):
    poses = [p for p in drive_poses(CELLS) if p[0] <= T0_NS + 7 * 10**9 + 10**8]  # until just after image 7
    bag = write_drive(tmp_path / "part", "sqlite3", images=[(T0_NS + k * 10**9, v) for k, v in enumerate(views)],
                      poses=poses)
    with caplog.at_level("WARNING"):
        db = load_bag_database(_bag_cfg(bag))
    assert len(db) == 8 and db.meta["n_uncovered"] == 4
    assert "4 of 12 images left out" in caplog.text and "db.pose_tolerance_s=0.1" in caplog.text


def test_tf_chain_with_a_static_camera_offset(tmp_path, views):
    """/tf odom -> base_link plus /tf_static base_link -> camera 0.1 m ahead: db.pose_frame=camera."""
    from rosbag_helpers import BagWriter

    w = BagWriter(tmp_path / "tf", "mcap")
    w.put("/tf_static", T0_NS - 10**9, w.tf(T0_NS - 10**9, [("base_link", "camera", 0.1, 0.0, 0.0)]))
    yaw = math.pi / 2  # the robot faces +y: the camera sits 0.1 m further along y
    for t, x, y, _ in drive_poses(CELLS):
        w.put("/tf", t, w.tf(t, [("odom", "base_link", x, y - 0.1, yaw)]))
    for k, v in enumerate(views):
        w.put("/camera/image", T0_NS + k * 10**9, w.image(T0_NS + k * 10**9, v, "mono8"))
    bag = w.close()
    db = load_bag_database(_bag_cfg(bag, pose_topic="/tf", pose_frame="camera", world_frame="odom", align=False))
    want = np.array([(ORIGIN[0] + i * CELL_M, ORIGIN[1] + j * CELL_M) for i, j in CELLS])
    got = np.array(db.meta["world_xy"])
    order = [CELLS.index(tuple(p)) for p in db.positions]
    assert np.allclose(got, want[order], atol=0.02)
    assert np.allclose(db.headings, yaw)


def test_interpolation_rule_closed_form():
    t = np.array([0, 100, 200], np.int64)
    track = PoseTrack("/odom", t, np.array([[0.0, 0.0], [1.0, 2.0], [1.0, 2.0]]),
                      np.array([math.pi - 0.1, -math.pi + 0.1, 0.0]), "odom", "base_link")
    xy, yaw, covered = track.at([25, 150, 200, 250, -1], tolerance_ns=80)
    assert covered.tolist() == [True, True, True, False, False]
    assert xy[0] == pytest.approx([0.25, 0.5])
    # heading on the circle: from pi - 0.1 to -pi + 0.1 the short way, through pi
    assert yaw[0] == pytest.approx(math.pi - 0.05)
    assert yaw[1] == pytest.approx(-math.pi / 2 + 0.05)
    assert yaw[2] == pytest.approx(0.0)
    lo, hi, f, ok = bracket(t, np.array([100, 160]), 60)
    assert ok.tolist() == [True, True] and f.tolist() == [0.0, 0.6]
    assert bracket(t, np.array([100, 140]), 30)[3].tolist() == [True, False]  # 40 ns from the last pose


def test_binning_keeps_the_view_nearest_each_cell_centre():
    xy = np.array([[0.0, 0.0], [0.02, 0.0], [0.29, 0.01], [0.31, 0.0], [0.6, 0.35]])
    stamps = np.arange(5)
    chosen, cells, shape, origin, offsets, outside = bin_views(xy, stamps, cell_m=0.3)
    assert shape == (3, 2) and outside == 0
    assert cells.tolist() == [[0, 0], [1, 0], [2, 1]]
    assert chosen.tolist() == [0, 3, 4]  # (0.31, 0) is nearer (0.3, 0) than (0.29, 0.01)
    assert offsets == pytest.approx([0.0, 0.01, 0.05])
    chosen, cells, shape, *_rest, outside = bin_views(xy, stamps, cell_m=0.3, origin=[0.3, 0.0], grid_shape=[2, 1])
    assert cells.tolist() == [[0, 0]] and outside == 3  # two views left of the origin, one above the grid


@pytest.mark.parametrize("container", ["ros1", "sqlite3", "mcap"])
def test_few_views_read_through_the_time_index(tmp_path, views, container):
    """Decoding 1 of 12 messages reads it through the bag's time index; all 12: one pass. Same pixels."""
    from bionav.db.bag.reader import open_bag
    from bionav.db.bag.views import WINDOW_SHARE, decode_views, index_views

    bag = write_drive(tmp_path / "d", container, images=[(T0_NS + k * 10**9, v) for k, v in enumerate(views)],
                      poses=drive_poses(CELLS), encoding="png")
    with open_bag(bag) as b:
        index = index_views(b, _bag_cfg(bag))
        assert 1 * WINDOW_SHARE < len(index.index) <= 12 * WINDOW_SHARE
        kept, few = decode_views(b, index, [7, 2], skip=False)
        _all, every = decode_views(b, index, list(range(12)), skip=False)
    assert kept == [7, 2]
    assert np.array_equal(few[0], every[7]) and np.array_equal(few[1], every[2])
    assert np.array_equal(every[7], views[7].astype(np.float32) / np.float32(255))
