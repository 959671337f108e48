"""``python -m bionav.logs export-ros2 RUN OUT``: a run's log as a ROS 2 bag of standard message types.

Every message of ``run.mcap`` goes to the bag on its own topic at its own log
time; ``rosbags`` writes the bag (CDR messages, ``mcap`` storage by default,
``--storage sqlite3`` for a ``.db3``), so any ROS 2 tool reads it
(``ros2 bag info``, RViz, Foxglove, ``rosbags``, ``mcap-ros2-support``).
Messages on channels with Foxglove's schemas become their ROS 2 equivalents:

=============================  ===============================  =====================================
run.mcap schema                ROS 2 type                        what bionav writes on it
=============================  ===============================  =====================================
``foxglove.RawImage``          ``sensor_msgs/msg/Image``         views (``32FC1``, ``mono8``, ``mono16``)
``foxglove.CompressedImage``   ``sensor_msgs/msg/CompressedImage``
``foxglove.PoseInFrame``       ``geometry_msgs/msg/PoseStamped`` poses (the cleaning robot's true pose)
``foxglove.PosesInFrame``      ``geometry_msgs/msg/PoseArray``   the views' poses; home vectors: one pose
                                                                 per current view, oriented along its
                                                                 home direction
``foxglove.FrameTransform``    ``tf2_msgs/msg/TFMessage``        (on ``/tf``)
any other (``bionav.*``)       ``std_msgs/msg/String``           the message's JSON text, unchanged
=============================  ===============================  =====================================

The run's resolved config travels in the bag's metadata (``custom_data``,
key ``bionav.config``). Positions stay in metres and angles in radians, the
frames as logged (REP 103: x forward, y left, z up; headings CCW).
"""

from __future__ import annotations

import base64
import json
from pathlib import Path

import numpy as np

from bionav.errors import UserError, require_extra

#: Foxglove schema -> ROS 2 message type (everything else: std_msgs/msg/String with the JSON)
ROS2_TYPES = {
    "foxglove.RawImage": "sensor_msgs/msg/Image",
    "foxglove.CompressedImage": "sensor_msgs/msg/CompressedImage",
    "foxglove.PoseInFrame": "geometry_msgs/msg/PoseStamped",
    "foxglove.PosesInFrame": "geometry_msgs/msg/PoseArray",
    "foxglove.FrameTransform": "tf2_msgs/msg/TFMessage",
}
STRING = "std_msgs/msg/String"


class _Builder:
    """ROS 2 messages from Foxglove JSON messages (rosbags' type store)."""

    def __init__(self, typestore) -> None:
        self.ts = typestore

    def m(self, name: str, **fields):
        return self.ts.types[name](**fields)

    def header(self, msg: dict, fallback_ns: int):
        stamp = msg.get("timestamp") or {"sec": fallback_ns // 1_000_000_000, "nsec": fallback_ns % 1_000_000_000}
        time = self.m("builtin_interfaces/msg/Time", sec=int(stamp["sec"]), nanosec=int(stamp["nsec"]))
        return self.m("std_msgs/msg/Header", stamp=time, frame_id=str(msg.get("frame_id", "")))

    def pose(self, p: dict):
        pos, q = p.get("position", {}), p.get("orientation", {})
        return self.m("geometry_msgs/msg/Pose",
                      position=self.m("geometry_msgs/msg/Point", **{k: float(pos.get(k, 0.0)) for k in "xyz"}),
                      orientation=self.m("geometry_msgs/msg/Quaternion",
                                         **{k: float(q.get(k, 1.0 if k == "w" else 0.0)) for k in "xyzw"}))

    def build(self, schema: str, msg: dict, t: int):
        data = lambda: np.frombuffer(base64.b64decode(msg["data"]), np.uint8)  # noqa: E731
        if schema == "foxglove.RawImage":
            return self.m("sensor_msgs/msg/Image", header=self.header(msg, t), height=int(msg["height"]),
                          width=int(msg["width"]), encoding=str(msg["encoding"]), is_bigendian=0,
                          step=int(msg["step"]), data=data())
        if schema == "foxglove.CompressedImage":
            return self.m("sensor_msgs/msg/CompressedImage", header=self.header(msg, t), format=str(msg["format"]),
                          data=data())
        if schema == "foxglove.PoseInFrame":
            return self.m("geometry_msgs/msg/PoseStamped", header=self.header(msg, t), pose=self.pose(msg["pose"]))
        if schema == "foxglove.PosesInFrame":
            return self.m("geometry_msgs/msg/PoseArray", header=self.header(msg, t),
                          poses=[self.pose(p) for p in msg["poses"]])
        if schema == "foxglove.FrameTransform":
            tr, r = msg["translation"], msg["rotation"]
            transform = self.m("geometry_msgs/msg/Transform",
                               translation=self.m("geometry_msgs/msg/Vector3", **{k: float(tr[k]) for k in "xyz"}),
                               rotation=self.m("geometry_msgs/msg/Quaternion", **{k: float(r[k]) for k in "xyzw"}))
            stamped = self.m("geometry_msgs/msg/TransformStamped",
                             header=self.header({"timestamp": msg.get("timestamp"),
                                                 "frame_id": msg.get("parent_frame_id", "")}, t),
                             child_frame_id=str(msg.get("child_frame_id", "")), transform=transform)
            return self.m("tf2_msgs/msg/TFMessage", transforms=[stamped])
        return self.m(STRING, data=json.dumps(msg, separators=(",", ":")))


def _log_path(run) -> Path:
    from bionav.files import user_path

    path = user_path(run)
    if path.is_dir():
        path = path / "run.mcap"
    if not path.exists():
        raise UserError(f"{path} does not exist; give a run directory (it holds run.mcap) or a run.mcap file.")
    return path


def _channels(path: Path) -> dict[str, str]:
    """Topic -> schema name of every channel of a log."""
    from mcap.reader import make_reader

    from bionav.logs.reader import _open

    with _open(path) as f:
        try:
            summary = make_reader(f).get_summary()
        except Exception as exc:  # a damaged summary: recover the log first
            raise UserError(f"{path} cannot be summarised ({type(exc).__name__}); repair it first with "
                            f"`python -m bionav.logs recover {path} repaired.mcap`.") from None
    if summary is None:
        raise UserError(f"{path} has no summary (a run cut short); repair it first with "
                        f"`python -m bionav.logs recover {path} repaired.mcap`.")
    return {c.topic: (summary.schemas[c.schema_id].name if c.schema_id in summary.schemas else "")
            for c in summary.channels.values()}


def export_ros2(run, out, *, storage: str = "mcap", overwrite: bool = False) -> dict[str, int]:
    """Write the messages of a run's ``run.mcap`` as a ROS 2 bag (see the module docstring).

    Parameters
    ----------
    run : path-like
        A run directory or its ``run.mcap``.
    out : path-like
        The ROS 2 bag folder to create.
    storage : {"mcap", "sqlite3"}
        The bag's storage plugin.
    overwrite : bool
        Replace an existing ``out``.

    Returns
    -------
    dict
        Messages written per ROS 2 type.

    Raises
    ------
    UserError
        No run log, a damaged one, ``out`` existing, rosbags missing (its install line named).
    """
    import shutil

    require_extra("rosbags.rosbag2", extra="ros", what="python -m bionav.logs export-ros2")
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    from bionav.files import user_path
    from bionav.logs.reader import read_attachment, read_messages

    src = _log_path(run)
    target = user_path(out)
    if target.exists():
        if not overwrite:
            raise UserError(f"{target} already exists; choose another output folder or pass --force to replace it.")
        shutil.rmtree(target) if target.is_dir() else target.unlink()
    schemas = _channels(src)
    ts = get_typestore(Stores.ROS2_HUMBLE)
    builder = _Builder(ts)
    plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
    counts: dict[str, int] = {}
    with Writer(target, version=9, storage_plugin=plugin) as writer:
        config = read_attachment(src, "config.yaml")
        if config is not None:
            writer.set_custom_data("bionav.config", config.decode("utf-8", "replace"))
        conns = {}
        for topic, t, msg in read_messages(src):
            schema = schemas.get(topic, "")
            msgtype = ROS2_TYPES.get(schema, STRING)
            name = "/tf" if msgtype == "tf2_msgs/msg/TFMessage" else topic
            if name not in conns:
                conns[name] = writer.add_connection(name, msgtype, typestore=ts)
            writer.write(conns[name], int(t), ts.serialize_cdr(builder.build(schema, msg, int(t)), msgtype))
            counts[msgtype] = counts.get(msgtype, 0) + 1
    return counts
