"""``python -m bionav.bench --method bag``: reading a ROS bag into a grid database (``db=bag``).

The row times :func:`bionav.db.bag.grid.load_bag_database` in a fresh
subprocess on a bag of compressed camera images and odometry, and reports
the bag's size, the wall and CPU time of the load (interpreter start-up
excluded), the throughput in MB of bag per wall second, and the peak
resident memory of the subprocess (``ru_maxrss``), with the 1-minute load
average before and after. Goals on 2 cores: >= 100 MB/s of compressed
images, <= 500 MB resident for a 4 GB bag.

Without ``--bag`` a bag is written first (by ``rosbags``, in a temporary
folder removed afterwards): ``--bag-gb`` GB of JPEG frames
(``--bag-frame W H`` pixels, textured, ~10 distinct frames re-sent), a robot
driving a boustrophedon over a square of 20 m at 1 m/s with odometry at 50 Hz,
in ``--bag-storage`` (``mcap`` default, ``sqlite3``, ``ros1``); the grid has
cells of 0.5 m, so about 1,700 views are decoded whatever the bag's size, each
unfolded as a mirror frame to ``--bag-unfold`` (561 x 81, the thesis' size).
MB/s is given per wall second and per CPU second of the loading process: on a
machine shared with other work the CPU figure is the one to compare.
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bionav.errors import UserError
from bionav.machine import machine_label

#: the child that loads the bag: prints its own wall and CPU seconds and the database's size
_LOADER = r"""
import json, sys, time
from bionav.db.bag.grid import load_bag_database
from bionav.db.config import DatabaseConfig
args = json.loads(sys.argv[1])
c0, w0 = time.process_time(), time.perf_counter()
from bionav.db.config import UnfoldConfig
if "unfold" in args:
    args["unfold"] = UnfoldConfig(**args["unfold"])
db = load_bag_database(DatabaseConfig(name="bench", source="bag", **args))
print(json.dumps({"wall_s": time.perf_counter() - w0, "cpu_s": time.process_time() - c0, "n_views": len(db),
                  "n_messages": db.meta["n_messages"], "grid": list(db.grid_shape)}))
"""
SIDE_M = 20.0
SPEED = 1.0
CELL_M = 0.5


def add_bag_arguments(parser) -> None:
    group = parser.add_argument_group("--method bag (ROS bag to grid database)")
    group.add_argument("--bag", default=None, metavar="PATH",
                       help="bag: time this bag (with --bag-topics) instead of writing one")
    group.add_argument("--bag-topics", nargs=2, default=["/camera/image/compressed", "/odom"],
                       metavar=("IMAGE", "POSE"), help="bag: its image and pose topics")
    group.add_argument("--bag-cell", type=float, default=CELL_M, help="bag: db.grid_cell_m (default 0.5)")
    group.add_argument("--bag-gb", type=float, default=0.5, help="bag: size of the written bag in GB (default 0.5)")
    group.add_argument("--bag-frame", type=int, nargs=2, default=[1280, 960], metavar=("W", "H"),
                       help="bag: JPEG frame size of the written bag (default 1280 960)")
    group.add_argument("--bag-storage", choices=("mcap", "sqlite3", "ros1"), default="mcap",
                       help="bag: container of the written bag (default mcap)")
    group.add_argument("--bag-unfold", type=int, nargs=2, default=[561, 81], metavar=("W", "H"),
                       help="bag: unfold the frames as mirror frames to W x H panoramas (db.unfold; default 561 81, "
                            "the thesis' size; 0 0 keeps the frames as panoramas)")


def _frames(width: int, height: int, n: int = 10) -> list[bytes]:
    import cv2
    import numpy as np

    rng = np.random.default_rng(0)
    out = []
    for _ in range(n):
        img = cv2.GaussianBlur(rng.random((height, width)).astype(np.float32), (0, 0), 3.0)
        img = (img - img.min()) / (np.ptp(img) + 1e-9)
        out.append(cv2.imencode(".jpg", np.uint8(img * 255), [cv2.IMWRITE_JPEG_QUALITY, 95])[1].tobytes())
    return out


def _position(s: float):
    """Boustrophedon over a SIDE_M square, lanes CELL_M apart, at path length ``s`` metres (wraps)."""
    lane_len = SIDE_M + CELL_M
    lanes = int(SIDE_M / CELL_M) + 1
    s = s % (lane_len * lanes)
    k, r = int(s // lane_len), s % lane_len
    if r <= SIDE_M:
        x = r if k % 2 == 0 else SIDE_M - r
        return x, k * CELL_M
    return (SIDE_M if k % 2 == 0 else 0.0), k * CELL_M + (r - SIDE_M)


def write_bench_bag(path: Path, *, gb: float, frame, storage: str) -> Path:
    """Write the benchmark's bag (see the module docstring) with rosbags; returns its path."""
    import math

    import numpy as np
    from rosbags.typesys import Stores, get_typestore

    frames = _frames(*frame)
    n = max(2, int(gb * 1e9 / np.mean([len(f) for f in frames])))
    ts = get_typestore(Stores.ROS1_NOETIC if storage == "ros1" else Stores.ROS2_HUMBLE)
    types = ts.types
    if storage == "ros1":
        from rosbags.rosbag1 import Writer

        writer, ser, path = Writer(path.with_suffix(".bag")), ts.serialize_ros1, path.with_suffix(".bag")
    else:
        from rosbags.rosbag2 import StoragePlugin, Writer

        writer = Writer(path, version=9, storage_plugin=StoragePlugin.MCAP if storage == "mcap" else
                        StoragePlugin.SQLITE3)
        ser = ts.serialize_cdr
    extra = {"seq": 0} if storage == "ros1" else {}
    rate = 50.0
    duration = SIDE_M * (SIDE_M / CELL_M + 1) * 1.2 / SPEED  # the whole boustrophedon once
    t0 = 1_700_000_000 * 10**9

    def header(ns, frame_id):
        return types["std_msgs/msg/Header"](stamp=types["builtin_interfaces/msg/Time"](sec=ns // 10**9,
                                                                                   nanosec=ns % 10**9),
                                            frame_id=frame_id, **extra)

    with writer:
        cam = writer.add_connection("/camera/image/compressed", "sensor_msgs/msg/CompressedImage", typestore=ts)
        odom = writer.add_connection("/odom", "nav_msgs/msg/Odometry", typestore=ts)
        zero = types["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0)
        twist = types["geometry_msgs/msg/TwistWithCovariance"](
            twist=types["geometry_msgs/msg/Twist"](linear=zero, angular=zero), covariance=np.zeros(36))
        n_poses = int(duration * rate) + 2
        image_every = (n_poses - 2) / n
        j = 0
        for i in range(n_poses):
            t = t0 + int(i * 1e9 / rate)
            x, y = _position(SPEED * i / rate)
            pose = types["geometry_msgs/msg/Pose"](position=types["geometry_msgs/msg/Point"](x=x, y=y, z=0.0),
                                                   orientation=types["geometry_msgs/msg/Quaternion"](
                                                       x=0.0, y=0.0, z=0.0, w=1.0))
            msg = types["nav_msgs/msg/Odometry"](header=header(t, "odom"), child_frame_id="base_link",
                                                 pose=types["geometry_msgs/msg/PoseWithCovariance"](
                                                     pose=pose, covariance=np.zeros(36)), twist=twist)
            writer.write(odom, t, ser(msg, "nav_msgs/msg/Odometry"))
            while j < n and math.floor(j * image_every) <= i and i < n_poses - 1:
                ti = t + int(0.3 * 1e9 / rate)
                data = np.frombuffer(frames[j % len(frames)], np.uint8)
                img = types["sensor_msgs/msg/CompressedImage"](header=header(ti, "camera"), format="jpeg", data=data)
                writer.write(cam, ti, ser(img, "sensor_msgs/msg/CompressedImage"))
                j += 1
    return path


def _size(path: Path) -> int:
    return sum(p.stat().st_size for p in path.rglob("*") if p.is_file()) if path.is_dir() else path.stat().st_size


def bag_rows(args) -> list[dict]:
    """The benchmark row (see the module docstring)."""
    from bionav.errors import require_extra

    require_extra("rosbags", extra="ros", what="python -m bionav.bench --method bag")
    with tempfile.TemporaryDirectory(prefix="bionav-bench-bag-") as tmp:
        if args.bag is None:
            w0 = time.perf_counter()
            bag = write_bench_bag(Path(tmp) / "bench", gb=args.bag_gb, frame=args.bag_frame, storage=args.bag_storage)
            write_s = time.perf_counter() - w0
            image_topic, pose_topic = "/camera/image/compressed", "/odom"
        else:
            bag, write_s = Path(args.bag), None
            image_topic, pose_topic = args.bag_topics
        size = _size(bag)
        config = {"path": str(bag), "image_topic": image_topic, "pose_topic": pose_topic, "grid_cell_m": args.bag_cell}
        if min(args.bag_unfold) > 0:
            config["unfold"] = {"enabled": True, "size": list(args.bag_unfold), "inner_radius": 0.1 * min(args.bag_frame),
                                "outer_radius": 0.45 * min(args.bag_frame)}
        load0 = os.getloadavg()[0]
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        w0 = time.perf_counter()
        proc = subprocess.run([sys.executable, "-c", _LOADER, json.dumps(config)], capture_output=True, text=True)
        wall = time.perf_counter() - w0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        if proc.returncode != 0:
            raise UserError(f"reading the bag {bag} failed: {proc.stderr.strip().splitlines()[-1:]}")
        inner = json.loads(proc.stdout.strip().splitlines()[-1])
    return [{"method": "bag", "variant": "given" if args.bag else args.bag_storage, "bag_mb": round(size / 1e6, 1),
             "n_messages": inner["n_messages"], "n_views": inner["n_views"], "grid": inner["grid"],
             "wall_s": round(inner["wall_s"], 2), "cpu_s": round(inner["cpu_s"], 2),
             "process_wall_s": round(wall, 2),
             "process_cpu_s": round(after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime, 2),
             "mb_per_s": round(size / 1e6 / inner["wall_s"], 1), "mb_per_cpu_s": round(size / 1e6 / inner["cpu_s"], 1),
             "peak_rss_mb": round(after.ru_maxrss / 1024, 1), "unfold": list(args.bag_unfold),
             "write_s": None if write_s is None else round(write_s, 1), "load_before": round(load0, 2),
             "load_after": round(os.getloadavg()[0], 2), "machine": machine_label()}]
