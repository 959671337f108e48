"""Opening a ROS bag and streaming its messages (the ``rosbags`` library does the reading).

One bag is a ROS 1 ``.bag`` file, a ROS 2 bag folder (``metadata.yaml`` plus
its ``.db3`` or ``.mcap`` files), or a single ROS 2 ``.mcap`` / ``.db3``
file. :func:`open_bag` checks the path, opens it with
``rosbags.highlevel.AnyReader`` (message definitions from the bag; the latest
ROS 2 type store for bags that carry none) and turns every failure of the
library into one :class:`~bionav.errors.UserError` naming the bag, the reason
and the repair. :meth:`Bag.messages` streams deserialised messages of the
topics asked for in the bag's time order: nothing is read whole.

Conventions: times are integer nanoseconds since the Unix epoch; message
types are ROS 2 style names (``sensor_msgs/msg/Image``), also for ROS 1 bags.
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator

from bionav.errors import UserError, require_extra

#: image message types ``db.image_topic`` accepts
IMAGE_TYPES = ("sensor_msgs/msg/Image", "sensor_msgs/msg/CompressedImage")
#: pose message types ``db.pose_topic`` accepts (the tf types: ``/tf``, with ``/tf_static`` read as well)
TF_TYPES = ("tf2_msgs/msg/TFMessage", "tf/msg/tfMessage")
POSE_TYPES = ("nav_msgs/msg/Odometry", "geometry_msgs/msg/PoseStamped",
              "geometry_msgs/msg/PoseWithCovarianceStamped") + TF_TYPES
#: message types ``sensor=bag`` replays
SENSOR_TYPES = ("sensor_msgs/msg/Imu", "sensor_msgs/msg/MagneticField") + IMAGE_TYPES
BAG_SUFFIXES = (".bag", ".mcap", ".db3")
INSTALL_HINT = "ros"


@dataclass(frozen=True)
class Topic:
    """One topic of a bag: its name, message type and message count."""

    name: str
    msgtype: str
    count: int

    def describe(self) -> str:
        return f"{self.name} ({self.msgtype}, {self.count} message{'' if self.count == 1 else 's'})"


def _kind(path: Path) -> str:
    if path.is_dir():
        return "ROS 2 bag folder"
    return {".bag": "ROS 1 bag", ".mcap": "ROS 2 bag (mcap)", ".db3": "ROS 2 bag (sqlite3)"}[path.suffix]


def _check_path(path: Path, key: str) -> None:
    """Refuse what cannot be a bag before the library sees it (one message, the fix named)."""
    from bionav.files import not_a_regular_file

    if not path.exists():
        raise UserError(f"the bag {path} does not exist; point {key} at a ROS 1 .bag file, a ROS 2 bag folder "
                        "(with metadata.yaml) or a ROS 2 .mcap / .db3 file.")
    if path.is_dir():
        if not (path / "metadata.yaml").is_file():
            inner = sorted(p.name for p in path.iterdir() if p.suffix in (".mcap", ".db3"))[:3]
            hint = (f" It holds {', '.join(inner)}: point {key} at one of them, or rebuild metadata.yaml with "
                    "`ros2 bag reindex`." if inner else " Point it at the bag folder (the one with metadata.yaml).")
            raise UserError(f"{path} is a folder without metadata.yaml, so not a ROS 2 bag folder.{hint}")
        return
    why = not_a_regular_file(path)
    if why:
        raise UserError(f"the bag {path} {why}; point {key} at a bag file or a ROS 2 bag folder.")
    if path.suffix not in BAG_SUFFIXES:
        raise UserError(f"{path} is not a ROS bag by its name (expected .bag for ROS 1, .mcap or .db3 for ROS 2, "
                        f"or a ROS 2 bag folder); point {key} at the bag, or rename the file if it is one.")
    if path.stat().st_size == 0:
        raise UserError(f"the bag {path} is empty (0 bytes); record it again or point {key} at another bag.")


def _repair_hint(path: Path, reason: str) -> str:
    """The fix for a bag the library refused, from the kind of bag and the library's reason."""
    low = reason.lower()
    ros1 = path.suffix == ".bag"
    if "version" in low and ("support" in low or "unsupported" in low):
        return ("this bag format version is not one the installed rosbags reads: upgrade it "
                "(pip install -U rosbags), or convert the bag with `rosbags-convert` / `ros2 bag convert`")
    if "encoding json" in low or "serialization format" in low:
        return ("it holds no ROS messages (a bionav run.mcap is JSON: replay it with sensor=replay "
                "sensor.path=run.mcap, inspect it with python -m bionav.logs info)")
    if ros1:
        repair = f"rebuild its index with `rosbag reindex {path.name}`"
    elif path.suffix == ".mcap" or (path.is_dir() and any(path.glob("*.mcap"))):
        repair = "rewrite it with `mcap recover IN -o OUT` (the mcap command-line tool) or `ros2 bag reindex`"
    else:
        repair = "recover the database with `sqlite3 IN .recover | sqlite3 OUT`, then `ros2 bag reindex`"
    return (f"the file looks cut short or damaged (a recording that was killed, an interrupted copy): "
            f"{repair}, or copy it again")


def _library_errors():
    """The exception types rosbags raises for bad bags (plus what its storage back-ends raise)."""
    import struct

    from rosbags.highlevel import AnyReaderError
    from rosbags.rosbag1 import ReaderError as Reader1Error
    from rosbags.rosbag2 import ReaderError as Reader2Error

    errors = [AnyReaderError, Reader1Error, Reader2Error, struct.error, EOFError, OSError, ValueError, KeyError,
              IndexError, TypeError, AssertionError, UnicodeDecodeError]
    try:
        import apsw

        errors.append(apsw.Error)
    except ImportError:  # pragma: no cover - rosbags requires apsw
        pass
    try:
        from rosbags.serde import SerdeError

        errors.append(SerdeError)
    except ImportError:  # pragma: no cover
        pass
    return tuple(errors)


class Bag:
    """An open ROS bag: its topics and a stream of its messages (use as a context manager).

    Parameters
    ----------
    path : path-like
        A ROS 1 ``.bag``, a ROS 2 bag folder, or a ROS 2 ``.mcap`` / ``.db3`` file.
    key : str
        The config key that named the bag (``db.path``, ``sensor.path``), for messages.

    Raises
    ------
    UserError
        The path is missing, not a bag, empty, of an unknown format version,
        cut short or damaged (the message names the repair), or rosbags is not
        installed (the message names ``pip install "bionav[ros]"``).
    """

    def __init__(self, path, *, key: str = "db.path") -> None:
        from bionav.files import user_path

        require_extra("rosbags.highlevel", extra=INSTALL_HINT, what=f"reading ROS bags ({key}=...)")
        from rosbags.highlevel import AnyReader
        from rosbags.typesys import Stores, get_typestore

        self.path = user_path(path)
        self.key = key
        _check_path(self.path, key)
        self.kind = _kind(self.path)
        self._errors = _library_errors()
        try:
            self._reader = AnyReader([self.path], default_typestore=get_typestore(Stores.LATEST))
            self._reader.open()
        except UserError:
            raise
        except self._errors as exc:
            reason = " ".join(str(a) for a in getattr(exc, "args", ()) if a) or type(exc).__name__
            raise UserError(f"cannot read the {self.kind} {self.path}: {reason.rstrip('.')}; "
                            f"{_repair_hint(self.path, reason)}.") from None
        self.topics: dict[str, Topic] = {
            name: Topic(name, info.msgtype or "(several types)", int(info.msgcount))
            for name, info in self._reader.topics.items()
        }

    # -- topics -----------------------------------------------------------------------------------
    def of_types(self, types) -> list[Topic]:
        """The topics whose message type is one of ``types``, by name (without ``/tf_static``: it is read with
        ``/tf``, never a pose topic of its own)."""
        return [t for _, t in sorted(self.topics.items())
                if t.msgtype in types and not t.name.rstrip("/").endswith("tf_static")]

    def topic(self, value: str | None, *, key: str, types, what: str, also=()) -> Topic:
        """The topic ``key=value`` names, checked: present, of one of ``types``, holding messages.

        ``also`` are further ``(label, types)`` groups listed in the message when
        the key is not set (the image topic's message lists pose topics too).

        Raises
        ------
        UserError
            ``value`` is empty (the message lists the candidate topics with types
            and counts and names ``key``), not in the bag (closest names
            suggested), of another type, or without messages.
        """
        candidates = self.of_types(types)
        menu = "; ".join(t.describe() for t in candidates) or "none"
        if not value:
            extra = "".join(f"; its {label} topics: " + ("; ".join(t.describe() for t in self.of_types(ts)) or "none")
                            for label, ts in also)
            example = f" e.g. {key}={candidates[0].name}" if candidates else ""
            raise UserError(f"{key} is not set: say which topic of the {self.kind} {self.path} holds the {what}. "
                            f"Its {what} topics: {menu}{extra}. Set {key}=TOPIC{example}.")
        if value not in self.topics:
            close = difflib.get_close_matches(value, list(self.topics), n=1, cutoff=0.6)
            guess = f" Did you mean {key}={close[0]}?" if close else ""
            raise UserError(f"{key}={value}: the {self.kind} {self.path} has no topic {value!r}.{guess} "
                            f"Its {what} topics: {menu}.")
        topic = self.topics[value]
        if topic.msgtype not in types:
            raise UserError(f"{key}={value} is a {topic.msgtype} topic, not {what} ({' or '.join(types)}); "
                            f"its {what} topics: {menu}.")
        if topic.count == 0:
            raise UserError(f"{key}={value} holds no messages in {self.path}; choose another topic: {menu}.")
        return topic

    # -- messages ---------------------------------------------------------------------------------
    def messages(self, topics, *, start: int | None = None,
                 stop: int | None = None) -> Iterator[tuple[str, str, int, object]]:
        """Yield ``(topic, msgtype, bag_time_ns, message)`` of ``topics`` in the bag's time order.

        ``start`` / ``stop``: only messages the bag recorded at ``start <= t < stop`` (ns; the
        bag's index finds them without reading the rest).

        Messages are read and deserialised one at a time (memory does not grow
        with the bag). A bag that breaks off mid-way raises a
        :class:`~bionav.errors.UserError` naming the topic, how many of its
        messages were read and the repair.
        """
        wanted = set(topics)
        conns = [c for c in self._reader.connections if c.topic in wanted]
        seen = 0
        stream = self._reader.messages(connections=conns, start=start, stop=stop)
        while True:
            try:
                conn, t, raw = next(stream)
                msg = self._reader.deserialize(raw, conn.msgtype)
            except StopIteration:
                return
            except self._errors as exc:
                reason = " ".join(str(a) for a in getattr(exc, "args", ()) if a) or type(exc).__name__
                raise UserError(f"the {self.kind} {self.path} breaks off after {seen} messages of "
                                f"{', '.join(sorted(wanted))}: {reason.rstrip('.')}; "
                                f"{_repair_hint(self.path, reason)}.") from None
            seen += 1
            yield conn.topic, conn.msgtype, int(t), msg

    def close(self) -> None:
        reader, self._reader = getattr(self, "_reader", None), None
        if reader is not None and reader.stack is not None:
            reader.close()

    def __enter__(self) -> "Bag":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def open_bag(path, *, key: str = "db.path") -> Bag:
    """Open a ROS bag (:class:`Bag`); close it with ``with`` or :meth:`Bag.close`."""
    return Bag(path, key=key)


def stamp_ns(stamp) -> int:
    """A ROS time (``builtin_interfaces/Time`` or ROS 1 ``time``: ``sec``, ``nanosec``) in nanoseconds."""
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def header_ns(msg) -> int:
    """The ``header.stamp`` of a message, in nanoseconds."""
    return stamp_ns(msg.header.stamp)
