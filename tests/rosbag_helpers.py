"""ROS bags for the tests, written by a third-party writer (``rosbags``), never by bionav's own code.

:func:`write_bag` writes one drive (image messages and pose messages) in one
of three containers: ``ros1`` (a ``.bag`` file), ``sqlite3`` (a ROS 2 bag
folder with a ``.db3``) or ``mcap`` (a ROS 2 bag folder with a ``.mcap``).
Images go out as ``sensor_msgs/Image`` (``mono8``, ``mono16``, ``rgb8``,
``bgr8``) or ``sensor_msgs/CompressedImage`` (``png``, ``jpeg``, encoded by
OpenCV); poses as ``nav_msgs/Odometry``, ``geometry_msgs/PoseStamped`` or
``/tf`` (``odom -> base_link``) with a static ``base_link -> camera`` on
``/tf_static``. Extra topics (``Imu``, ``MagneticField``) can be added.
"""

from __future__ import annotations

import math

from pathlib import Path

import numpy as np

CONTAINERS = ("ros1", "sqlite3", "mcap")


def _stores():
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    ros1 = get_typestore(Stores.ROS1_NOETIC)
    if "tf2_msgs/msg/TFMessage" not in ros1.types:  # rosbags' Noetic store has no tf2_msgs: its .msg text
        ros1.register(get_types_from_msg("geometry_msgs/TransformStamped[] transforms", "tf2_msgs/msg/TFMessage"))
    return ros1, get_typestore(Stores.ROS2_HUMBLE)


class BagWriter:
    """A thin wrapper over rosbags' writers: ``add(topic, msgtype)``, ``write(topic, bag_ns, msg)``, ``msg(type, **fields)``."""

    def __init__(self, path: Path, container: str) -> None:
        from rosbags.rosbag1 import Writer as Writer1
        from rosbags.rosbag2 import StoragePlugin, Writer as Writer2

        self.ros1 = container == "ros1"
        self.ts1, self.ts2 = _stores()
        self.ts = self.ts1 if self.ros1 else self.ts2
        if self.ros1:
            self.path = Path(path).with_suffix(".bag")
            self.writer = Writer1(self.path)
        else:
            self.path = Path(path)
            plugin = StoragePlugin.MCAP if container == "mcap" else StoragePlugin.SQLITE3
            self.writer = Writer2(self.path, version=9, storage_plugin=plugin)
        self.writer.open()
        self.conns: dict[str, object] = {}
        self.types: dict[str, str] = {}

    def add(self, topic: str, msgtype: str) -> None:
        if topic not in self.conns:
            self.conns[topic] = self.writer.add_connection(topic, msgtype, typestore=self.ts)
            self.types[topic] = msgtype

    def msg(self, msgtype: str, **fields):
        return self.ts.types[msgtype](**fields)

    def header(self, stamp_ns: int, frame: str):
        time = self.msg("builtin_interfaces/msg/Time", sec=int(stamp_ns // 10**9), nanosec=int(stamp_ns % 10**9))
        extra = {"seq": 0} if self.ros1 else {}
        return self.msg("std_msgs/msg/Header", stamp=time, frame_id=frame, **extra)

    def write(self, topic: str, bag_ns: int, message) -> None:
        msgtype = self.types[topic]
        raw = self.ts.serialize_ros1(message, msgtype) if self.ros1 else self.ts.serialize_cdr(message, msgtype)
        self.writer.write(self.conns[topic], int(bag_ns), raw)

    def close(self) -> Path:
        self.writer.close()
        return self.path

    # -- message builders ---------------------------------------------------------------------
    def image(self, stamp_ns: int, pixels: np.ndarray, encoding: str, frame: str = "camera"):
        """A raw Image (``mono8``, ``mono16``, ``rgb8``, ``bgr8``) or a CompressedImage (``png``, ``jpeg``)."""
        import cv2

        if encoding in ("png", "jpeg"):
            ok, buf = cv2.imencode(".png" if encoding == "png" else ".jpg", pixels)
            assert ok
            return "sensor_msgs/msg/CompressedImage", self.msg(
                "sensor_msgs/msg/CompressedImage", header=self.header(stamp_ns, frame), format=encoding,
                data=np.frombuffer(buf.tobytes(), np.uint8))
        arr = np.ascontiguousarray(pixels)
        h, w = arr.shape[:2]
        return "sensor_msgs/msg/Image", self.msg(
            "sensor_msgs/msg/Image", header=self.header(stamp_ns, frame), height=h, width=w, encoding=encoding,
            is_bigendian=0, step=arr.strides[0], data=np.frombuffer(arr.tobytes(), np.uint8))

    def _pose(self, x: float, y: float, yaw: float):
        p = self.msg("geometry_msgs/msg/Point", x=float(x), y=float(y), z=0.0)
        q = self.msg("geometry_msgs/msg/Quaternion", x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))
        return self.msg("geometry_msgs/msg/Pose", position=p, orientation=q)

    def odometry(self, stamp_ns: int, x: float, y: float, yaw: float):
        cov = np.zeros(36)
        twist = self.msg("geometry_msgs/msg/Twist", linear=self.msg("geometry_msgs/msg/Vector3", x=0.0, y=0.0, z=0.0),
                         angular=self.msg("geometry_msgs/msg/Vector3", x=0.0, y=0.0, z=0.0))
        return "nav_msgs/msg/Odometry", self.msg(
            "nav_msgs/msg/Odometry", header=self.header(stamp_ns, "odom"), child_frame_id="base_link",
            pose=self.msg("geometry_msgs/msg/PoseWithCovariance", pose=self._pose(x, y, yaw), covariance=cov),
            twist=self.msg("geometry_msgs/msg/TwistWithCovariance", twist=twist, covariance=cov))

    def pose_stamped(self, stamp_ns: int, x: float, y: float, yaw: float):
        return "geometry_msgs/msg/PoseStamped", self.msg(
            "geometry_msgs/msg/PoseStamped", header=self.header(stamp_ns, "map"), pose=self._pose(x, y, yaw))

    def tf(self, stamp_ns: int, transforms):
        """``transforms``: ``[(parent, child, x, y, yaw), ...]`` at one stamp."""
        msgs = []
        for parent, child, x, y, yaw in transforms:
            t = self.msg("geometry_msgs/msg/Transform",
                         translation=self.msg("geometry_msgs/msg/Vector3", x=float(x), y=float(y), z=0.0),
                         rotation=self.msg("geometry_msgs/msg/Quaternion", x=0.0, y=0.0, z=math.sin(yaw / 2),
                                           w=math.cos(yaw / 2)))
            msgs.append(self.msg("geometry_msgs/msg/TransformStamped", header=self.header(stamp_ns, parent),
                                 child_frame_id=child, transform=t))
        return "tf2_msgs/msg/TFMessage", self.msg("tf2_msgs/msg/TFMessage", transforms=msgs)

    def imu(self, stamp_ns: int, yaw: float):
        v = self.msg("geometry_msgs/msg/Vector3", x=0.0, y=0.0, z=0.0)
        q = self.msg("geometry_msgs/msg/Quaternion", x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))
        return "sensor_msgs/msg/Imu", self.msg(
            "sensor_msgs/msg/Imu", header=self.header(stamp_ns, "imu"), orientation=q,
            orientation_covariance=np.zeros(9), angular_velocity=v, angular_velocity_covariance=np.zeros(9),
            linear_acceleration=self.msg("geometry_msgs/msg/Vector3", x=0.0, y=0.0, z=9.81),
            linear_acceleration_covariance=np.zeros(9))

    def magnetic_field(self, stamp_ns: int, field_xyz):
        f = self.msg("geometry_msgs/msg/Vector3", x=float(field_xyz[0]), y=float(field_xyz[1]), z=float(field_xyz[2]))
        return "sensor_msgs/msg/MagneticField", self.msg(
            "sensor_msgs/msg/MagneticField", header=self.header(stamp_ns, "imu"), magnetic_field=f,
            magnetic_field_covariance=np.zeros(9))

    def put(self, topic: str, bag_ns: int, built) -> None:
        """Write a ``(msgtype, message)`` pair from a builder above."""
        msgtype, message = built
        self.add(topic, msgtype)
        self.write(topic, bag_ns, message)


def write_drive(path: Path, container: str, *, images, poses, encoding: str = "mono8", pose_kind: str = "odom",
                image_topic: str = "/camera/image", pose_topic: str | None = None, extra=None) -> Path:
    """Write a drive: ``images`` = ``[(stamp_ns, pixels), ...]``, ``poses`` = ``[(stamp_ns, x, y, yaw), ...]``.

    Messages are written in stamp order with the bag time equal to the stamp (plus 1 ms for the
    images: a camera's delivery delay). ``pose_kind``: ``odom`` (``/odom``), ``pose`` (``/pose``),
    ``tf`` (``/tf`` odom -> base_link, ``/tf_static`` base_link -> camera at the origin).
    ``extra(writer)`` may add more messages. Returns the bag's path.
    """
    w = BagWriter(path, container)
    topic = pose_topic or {"odom": "/odom", "pose": "/pose", "tf": "/tf"}[pose_kind]
    events = [(int(t), 1, ("pose", (x, y, yaw))) for t, x, y, yaw in poses]
    events += [(int(t) + 1_000_000, 0, ("image", (int(t), px))) for t, px in images]
    if pose_kind == "tf":
        w.put("/tf_static", 0, w.tf(0, [("base_link", "camera", 0.0, 0.0, 0.0)]))
    for bag_ns, _order, (kind, payload) in sorted(events, key=lambda e: (e[0], e[1])):
        if kind == "image":
            stamp, pixels = payload
            w.put(image_topic, bag_ns, w.image(stamp, pixels, encoding))
        elif pose_kind == "odom":
            w.put(topic, bag_ns, w.odometry(bag_ns, *payload))
        elif pose_kind == "pose":
            w.put(topic, bag_ns, w.pose_stamped(bag_ns, *payload))
        else:
            w.put(topic, bag_ns, w.tf(bag_ns, [("odom", "base_link", *payload)]))
    if extra is not None:
        extra(w)
    return w.close()


#: the test drive's grid: cells of 0.3 m, cell (0, 0) at (-0.5, -0.4) in the pillar room
CELL_M = 0.3
ORIGIN = (-0.5, -0.4)
T0_NS = 1_700_000_000 * 10**9


def lawnmower(nx: int = 4, ny: int = 3) -> list[tuple[int, int]]:
    """Cells of a boustrophedon drive: along x, up one row, back."""
    return [(i, j) for j in range(ny) for i in (range(nx) if j % 2 == 0 else range(nx - 1, -1, -1))]


def drive_poses(cells, *, rate_hz: float = 20.0, offset_ns: int = 7_000_000, yaw=None, seconds_per_cell: float = 1.0):
    """Poses along the drive (straight segments between cell centres at constant speed), stamped
    ``offset_ns`` after the images' seconds so no pose stamp coincides with an image stamp.

    The position at time t is exactly linear within each segment, so interpolating between two poses of
    one segment gives the true position; at a corner the interpolation cuts it (by less than one pose
    step). Returns ``[(stamp_ns, x, y, yaw), ...]`` covering the first to the last image."""
    per = int(seconds_per_cell * 1e9)
    step = int(1e9 / rate_hz)
    out = []
    t = T0_NS - step + offset_ns
    end = T0_NS + (len(cells) - 1) * per + step
    while t <= end:
        k = min(max((t - T0_NS) // per, 0), len(cells) - 2)
        f = (t - T0_NS - k * per) / per
        (i0, j0), (i1, j1) = cells[k], cells[k + 1]
        x = ORIGIN[0] + CELL_M * (i0 + f * (i1 - i0))
        y = ORIGIN[1] + CELL_M * (j0 + f * (j1 - j0))
        out.append((t, x, y, 0.0 if yaw is None else yaw(t)))
        t += step
    return out


def pillar_views(cells, *, width: int = 96, height: int = 16, headings=None):
    """8-bit views rendered in the pillar room at the cell centres (column 0 along ``headings[k]``, CCW)."""
    from bionav.testing import render_pillar_panorama

    out = []
    for k, (i, j) in enumerate(cells):
        h = 0.0 if headings is None else float(headings[k])
        img, _ = render_pillar_panorama((ORIGIN[0] + i * CELL_M, ORIGIN[1] + j * CELL_M), heading=h, width=width,
                                        height=height, supersample=1)
        out.append(np.uint8(np.rint(img * 255.0)))
    return out


def robot_bag(path: Path, *, container: str = "ros1", width: int = 288, height: int = 50) -> Path:
    """The bag docs/ros.md works on: a robot's boustrophedon over 5 x 4 cells of 0.3 m in the pillar room.

    A view every 0.1 m of the drive (``/camera/image``, mono8 panoramas, column 0 along the heading,
    azimuth counter-clockwise), odometry at 20 Hz (``/odom``) and the same poses on ``/tf``
    (odom -> base_link, with base_link -> camera on ``/tf_static``), an IMU (``/imu/data``) and a
    magnetometer (``/imu/mag``) at 10 Hz; the robot faces along each lane (yaw 0 or pi).
    """
    from bionav.testing import render_pillar_panorama

    cells = lawnmower(5, 4)
    knots = np.array([(ORIGIN[0] + i * CELL_M, ORIGIN[1] + j * CELL_M) for i, j in cells])
    seg = np.linalg.norm(np.diff(knots, axis=0), axis=1)
    s_knot = np.concatenate([[0.0], np.cumsum(seg)])
    speed = 0.1  # m/s

    def pose(t_ns):
        s = min(max((t_ns - T0_NS) / 1e9 * speed, 0.0), s_knot[-1])
        k = int(min(np.searchsorted(s_knot, s, side="right") - 1, len(seg) - 1))
        f = (s - s_knot[k]) / seg[k]
        x, y = knots[k] + f * (knots[k + 1] - knots[k])
        d = knots[k + 1] - knots[k]
        return float(x), float(y), math.atan2(d[1], d[0])

    w = BagWriter(path, container)
    w.put("/tf_static", T0_NS - 10**9, w.tf(T0_NS - 10**9, [("base_link", "camera", 0.0, 0.0, 0.0)]))
    end = T0_NS + int(s_knot[-1] / speed * 1e9)
    for k, t in enumerate(range(T0_NS - 10**8 + 3 * 10**6, end + 10**8, 5 * 10**7)):
        x, y, yaw = pose(t)
        w.put("/odom", t, w.odometry(t, x, y, yaw))
        w.put("/tf", t, w.tf(t, [("odom", "base_link", x, y, yaw)]))
        if k % 2 == 0:
            w.put("/imu/data", t, w.imu(t, yaw + 0.2))
            w.put("/imu/mag", t, w.magnetic_field(t, (2e-5 * math.sin(yaw), 2e-5 * math.cos(yaw), -4e-5)))
    for t in range(T0_NS, end + 1, 10**9):  # one view per second: every 0.1 m
        x, y, yaw = pose(t)
        img, _ = render_pillar_panorama((x, y), heading=yaw, width=width, height=height, supersample=1)
        w.put("/camera/image", t + 2 * 10**7, w.image(t, np.uint8(np.rint(img * 255)), "mono8"))
    return w.close()
