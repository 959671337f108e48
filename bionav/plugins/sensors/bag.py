"""``sensor=bag``: a robot's own recording (a ROS bag) played into an experiment as a sensor.

``sensor.path`` names a ROS 1 ``.bag``, a ROS 2 bag folder or a ROS 2
``.mcap`` / ``.db3`` file, ``sensor.topic`` one topic of it (without a topic
the error lists the bag's sensor topics with types and counts). Each
:meth:`BagSensor.read` returns the topic's next message, in the bag's order,
as a raw reading (JSON-ready dict):

``sensor_msgs/Imu``
    ``{"stamp_ns", "frame_id", "orientation": [x, y, z, w], "angular_velocity": [rad/s x3],
    "linear_acceleration": [m/s^2 x3], "yaw", "heading_deg"}``; ``yaw`` is the heading of the
    IMU's x axis projected onto the horizontal plane, radians counter-clockwise from east
    (REP 103, ENU), ``heading_deg`` the same as a compass bearing, degrees clockwise from north
    (:func:`bionav.geometry.azimuth_to_compass`), the key the TCM2 compass's readings carry, so
    the bag can stand in for the reference compass (``experiment.reference``).
``sensor_msgs/MagneticField``
    ``{"stamp_ns", "frame_id", "magnetic_field_t": [x, y, z], "yaw", "heading_deg"}``: the
    heading of a level magnetometer (no tilt compensation), ``yaw = atan2(B_x, B_y)`` counter-
    clockwise from magnetic east: the horizontal field points to magnetic north.
``sensor_msgs/Image`` / ``sensor_msgs/CompressedImage``
    Foxglove's ``foxglove.RawImage`` / ``foxglove.CompressedImage`` messages of the same pixels
    (base64 data), which :func:`reading_image` turns back into a grey view.

Readings depend on the bag alone, so two runs give the same readings, and the
run's ``run.mcap`` replays them with ``sensor=replay`` like any sensor's.
The bag is streamed: one message in memory at a time.
"""

from __future__ import annotations

import base64
import math
from dataclasses import dataclass

import numpy as np

from bionav.errors import UserError
from bionav.geometry import azimuth_to_compass
from bionav.plugins.sensors.base import SensorPlugin

IMU_SCHEMA = {
    "type": "object",
    "title": "sensor_msgs/Imu as a bionav reading",
    "properties": {
        "stamp_ns": {"type": "integer", "description": "header.stamp, ns since the epoch"},
        "frame_id": {"type": "string"},
        "orientation": {"type": "array", "items": {"type": "number"}, "description": "quaternion x, y, z, w (ENU)"},
        "angular_velocity": {"type": "array", "items": {"type": "number"}, "description": "rad/s"},
        "linear_acceleration": {"type": "array", "items": {"type": "number"}, "description": "m/s^2"},
        "yaw": {"type": "number", "description": "heading of the x axis, radians CCW from east"},
        "heading_deg": {"type": "number", "description": "compass bearing, degrees clockwise from north"},
    },
    "required": ["stamp_ns", "yaw", "heading_deg"],
}
MAGNETIC_SCHEMA = {
    "type": "object",
    "title": "sensor_msgs/MagneticField as a bionav reading",
    "properties": {
        "stamp_ns": {"type": "integer"},
        "frame_id": {"type": "string"},
        "magnetic_field_t": {"type": "array", "items": {"type": "number"}, "description": "tesla, sensor frame"},
        "yaw": {"type": "number", "description": "heading of the x axis, radians CCW from magnetic east (level)"},
        "heading_deg": {"type": "number", "description": "magnetic bearing, degrees clockwise from magnetic north"},
    },
    "required": ["stamp_ns", "magnetic_field_t", "yaw", "heading_deg"],
}


@dataclass
class BagSensorConfig:
    """Parameters of ``sensor=bag``: ``path`` (the bag), ``topic`` (Imu, MagneticField, Image or
    CompressedImage), ``loop`` (start again at the end instead of stopping)."""

    path: str = ""
    topic: str = ""
    loop: bool = False


def _vec(v) -> list[float]:
    return [float(v.x), float(v.y), float(v.z)]


def _stamp(ns: int) -> dict:
    return {"sec": int(ns // 1_000_000_000), "nsec": int(ns % 1_000_000_000)}


def reading_of(msg, msgtype: str) -> dict:
    """The raw reading of one deserialised bag message (see the module docstring)."""
    from bionav.db.bag.poses import yaw_from_quaternions
    from bionav.db.bag.reader import header_ns

    ns = header_ns(msg)
    frame = str(msg.header.frame_id)
    if msgtype == "sensor_msgs/msg/Imu":
        o = msg.orientation
        q = [float(o.x), float(o.y), float(o.z), float(o.w)]
        yaw = float(yaw_from_quaternions(np.array(q))[0])
        return {"stamp_ns": ns, "frame_id": frame, "orientation": q, "angular_velocity": _vec(msg.angular_velocity),
                "linear_acceleration": _vec(msg.linear_acceleration), "yaw": yaw,
                "heading_deg": math.degrees(float(azimuth_to_compass(yaw)))}
    if msgtype == "sensor_msgs/msg/MagneticField":
        b = _vec(msg.magnetic_field)
        yaw = math.atan2(b[0], b[1])
        return {"stamp_ns": ns, "frame_id": frame, "magnetic_field_t": b, "yaw": yaw,
                "heading_deg": math.degrees(float(azimuth_to_compass(yaw)))}
    data = base64.b64encode(np.asarray(msg.data, np.uint8).tobytes()).decode("ascii")
    if msgtype == "sensor_msgs/msg/CompressedImage":
        return {"timestamp": _stamp(ns), "frame_id": frame, "format": str(msg.format), "data": data}
    return {"timestamp": _stamp(ns), "frame_id": frame, "width": int(msg.width), "height": int(msg.height),
            "encoding": str(msg.encoding), "step": int(msg.step), "data": data}


def reading_image(reading: dict) -> np.ndarray:
    """The grey view ``(H, W)`` float32 in ``[0, 1]`` of an image reading (decoded as ``db=bag`` decodes it)."""
    from bionav.db.bag.images import ImageMessage, decode

    raw = np.frombuffer(base64.b64decode(reading["data"]), np.uint8)
    stamp = int(reading["timestamp"]["sec"]) * 1_000_000_000 + int(reading["timestamp"]["nsec"])
    if "format" in reading:
        m = ImageMessage(stamp, 0, True, reading["format"], 0, 0, 0, False, raw)
    else:
        m = ImageMessage(stamp, 0, False, reading["encoding"], int(reading["width"]), int(reading["height"]),
                         int(reading["step"]), False, raw)
    return decode(m, "sensor=bag")


class BagSensor(SensorPlugin):
    """Messages of one bag topic as sensor readings (see the module docstring)."""

    Config = BagSensorConfig
    schema_name = "bionav.BagReading"
    schema = {"type": "object"}

    _SCHEMAS = {
        "sensor_msgs/msg/Imu": ("bionav.ImuReading", IMU_SCHEMA),
        "sensor_msgs/msg/MagneticField": ("bionav.MagneticFieldReading", MAGNETIC_SCHEMA),
        "sensor_msgs/msg/Image": ("foxglove.RawImage", None),
        "sensor_msgs/msg/CompressedImage": ("foxglove.CompressedImage", None),
    }

    def __init__(self, config: BagSensorConfig) -> None:
        super().__init__(config)
        self._bag = None
        self._stream = None
        self._topic = None
        self._played = 0

    def open(self) -> None:
        from bionav.db.bag.reader import SENSOR_TYPES, open_bag

        if self._bag is not None:
            return
        if not self.config.path:
            raise UserError(f"sensor=bag needs the bag: set {self.config_key('path')}=BAG (a ROS 1 .bag, a ROS 2 bag "
                            f"folder or a .mcap / .db3 file) and {self.config_key('topic')}=TOPIC.")
        bag = open_bag(self.config.path, key=self.config_key("path"))
        try:
            self._topic = bag.topic(self.config.topic, key=self.config_key("topic"), types=SENSOR_TYPES,
                                    what="sensor (Imu, MagneticField, Image)")
        except UserError:
            bag.close()
            raise
        self._bag = bag
        self.schema_name, self.schema = self._SCHEMAS[self._topic.msgtype]
        self._restart()

    def _restart(self) -> None:
        self._stream = self._bag.messages([self._topic.name])
        self._played = 0

    def close(self) -> None:
        bag, self._bag, self._stream = self._bag, None, None
        if bag is not None:
            bag.close()

    def read(self) -> dict:
        self.open()
        item = next(self._stream, None)
        if item is None:
            if not self.config.loop or self._played == 0:
                raise UserError(f"sensor=bag has played all {self._played} messages of {self._topic.name} in "
                                f"{self.config.path}; ask for fewer readings or set {self.config_key('loop')}=true.")
            self._restart()
            item = next(self._stream)
        self._played += 1
        _name, msgtype, _t, msg = item
        return reading_of(msg, msgtype)
