"""The robot's planar pose along a bag, interpolated to any stamp.

Sources (``db.pose_topic``): ``nav_msgs/Odometry`` (``pose.pose``),
``geometry_msgs/PoseStamped`` (``pose``), ``geometry_msgs/PoseWithCovarianceStamped``
(``pose.pose``), or the transform tree (``/tf`` with ``/tf_static``): the
pose of ``db.pose_frame`` in ``db.world_frame``, composed along the tree.

Conventions (REP 103/105): positions in metres in the world frame, x forward
/ east, y left / north; the heading is the direction of the body's x axis
projected onto the world's x-y plane, radians counter-clockwise from world
+x (``atan2``), the same rule for every source.

Interpolation to an image stamp ``t`` (:meth:`PoseTrack.at`): ``t0`` is the
last pose stamp at or before ``t``, ``t1`` the first at or after; the stamp
is *covered* when both exist and ``t - t0 <= tolerance`` and ``t1 - t <=
tolerance`` (``db.pose_tolerance_s``). Positions are interpolated linearly
between ``t0`` and ``t1``, headings on the circle (the shorter way round);
each transform of a tf chain is interpolated so (rotations by slerp, which
is the same for planar motion) and the chain composed at ``t``. Uncovered
stamps get no pose: the caller leaves their images out and counts them.

Stamps: ``header.stamp`` (``db.stamps=header``) or the time the bag recorded
the message (``db.stamps=bag``). Pose stamps that go back in time by up to
the tolerance are sorted; a larger step back (a clock jump, two recordings
in one bag) is an error naming the message and the fix.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from bionav.db.bag.reader import TF_TYPES, header_ns, stamp_ns
from bionav.errors import UserError
from bionav.geometry import wrap_angle

NS = 1_000_000_000


def yaw_from_quaternions(q: np.ndarray) -> np.ndarray:
    """Heading of the body x axis projected onto the x-y plane, radians CCW from +x; ``q`` is ``(N, 4)`` x, y, z, w."""
    q = np.asarray(q, np.float64).reshape(-1, 4)
    x, y, z, w = q.T
    return np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def bracket(t: np.ndarray, query: np.ndarray, tolerance_ns: int):
    """Bracketing samples of each query stamp: ``(lo, hi, fraction, covered)`` (see the module docstring)."""
    n = len(t)
    q = np.asarray(query, np.int64)
    lo = np.searchsorted(t, q, side="right") - 1
    hi = np.searchsorted(t, q, side="left")
    covered = (lo >= 0) & (hi < n)
    lo, hi = np.clip(lo, 0, max(n - 1, 0)), np.clip(hi, 0, max(n - 1, 0))
    if n:
        covered &= (q - t[lo] <= tolerance_ns) & (t[hi] - q <= tolerance_ns)
    span = (t[hi] - t[lo]).astype(np.float64) if n else np.zeros(len(q))
    frac = np.divide((q - t[lo]).astype(np.float64) if n else np.zeros(len(q)), span,
                     out=np.zeros(len(q)), where=span > 0)
    return lo, hi, frac, covered


def ordered(t: np.ndarray, *, topic: str, tolerance_ns: int, what: str = "pose") -> np.ndarray:
    """The order that sorts stamps ``t`` (stable); refuses a step back of more than the tolerance."""
    t = np.asarray(t, np.int64)
    if len(t) > 1:
        back = np.flatnonzero(np.diff(t) < -tolerance_ns)
        if back.size:
            i = int(back[0]) + 1
            raise UserError(
                f"the {what} stamps of {topic} go back in time by {(t[i - 1] - t[i]) / 1e9:.3f} s at message {i} "
                f"({t[i - 1] / 1e9:.3f} s, then {t[i] / 1e9:.3f} s; {back.size} such step(s)): a clock jump or two "
                "recordings in one bag. Use the times the bag recorded with db.stamps=bag, or split the bag into its "
                "recordings (rosbags-convert / ros2 bag convert with a time range)."
            )
    return np.argsort(t, kind="stable")


@dataclass
class PoseTrack:
    """Planar poses of one topic: ``t_ns (N,)`` sorted, ``xy (N, 2)`` metres, ``yaw (N,)`` radians CCW from +x."""

    topic: str
    t_ns: np.ndarray
    xy: np.ndarray
    yaw: np.ndarray
    world_frame: str
    body_frame: str

    def at(self, query_ns, tolerance_ns: int):
        """``(xy (M, 2), yaw (M,), covered (M,))`` at the query stamps (NaN where not covered)."""
        lo, hi, f, covered = bracket(self.t_ns, query_ns, tolerance_ns)
        if not len(self.t_ns):
            return np.full((len(f), 2), np.nan), np.full(len(f), np.nan), covered
        xy = self.xy[lo] + f[:, None] * (self.xy[hi] - self.xy[lo])
        yaw = wrap_angle(self.yaw[lo] + f * wrap_angle(self.yaw[hi] - self.yaw[lo]))
        xy[~covered] = np.nan
        yaw = np.where(covered, yaw, np.nan)
        return xy, yaw, covered

    @property
    def span_s(self) -> tuple[float, float]:
        return (self.t_ns[0] / NS, self.t_ns[-1] / NS) if len(self.t_ns) else (float("nan"), float("nan"))


def _pose_of(msg, msgtype: str):
    pose = msg.pose if msgtype == "geometry_msgs/msg/PoseStamped" else msg.pose.pose
    p, o = pose.position, pose.orientation
    return (float(p.x), float(p.y)), (float(o.x), float(o.y), float(o.z), float(o.w))


def read_pose_track(bag, topic, *, stamps: str, tolerance_ns: int, world_frame: str | None) -> PoseTrack:
    """Every pose of an Odometry / PoseStamped / PoseWithCovarianceStamped topic, sorted by stamp."""
    t, xy, quat, frames, child = [], [], [], set(), ""
    for _name, msgtype, bag_ns, msg in bag.messages([topic.name]):
        t.append(header_ns(msg) if stamps == "header" else bag_ns)
        p, q = _pose_of(msg, msgtype)
        xy.append(p)
        quat.append(q)
        frames.add(str(msg.header.frame_id))
        child = str(getattr(msg, "child_frame_id", "") or child)
    if len(frames) > 1:
        raise UserError(f"the poses of {topic.name} are given in several frames ({', '.join(sorted(frames))}); "
                        "a database needs one world frame: choose a topic with one frame, or use /tf with "
                        "db.world_frame=... db.pose_frame=....")
    frame = frames.pop() if frames else ""
    if world_frame and frame and world_frame.lstrip("/") != frame.lstrip("/"):
        raise UserError(f"db.world_frame={world_frame}, but the poses of {topic.name} are in frame {frame!r}; set "
                        f"db.world_frame={frame} (or null), or take the poses from /tf to change frames.")
    t = np.asarray(t, np.int64)
    order = ordered(t, topic=topic.name, tolerance_ns=tolerance_ns)
    return PoseTrack(topic.name, t[order], np.asarray(xy, np.float64).reshape(-1, 2)[order],
                     yaw_from_quaternions(np.asarray(quat).reshape(-1, 4))[order], frame, child)


# -------------------------------------------------------------------------------------------- tf
@dataclass
class _Edge:
    t_ns: list = field(default_factory=list)
    trans: list = field(default_factory=list)
    quat: list = field(default_factory=list)


def _collect_tf(bag, topics, stamps: str):
    """``(dynamic, static)``: per ``(parent, child)`` the stamps, translations and rotations."""
    dynamic: dict[tuple[str, str], _Edge] = {}
    static: dict[tuple[str, str], _Edge] = {}
    for name, _msgtype, bag_ns, msg in bag.messages([t.name for t in topics]):
        target = static if name.rstrip("/").endswith("tf_static") else dynamic
        for tf in msg.transforms:
            key = (str(tf.header.frame_id).lstrip("/"), str(tf.child_frame_id).lstrip("/"))
            e = target.setdefault(key, _Edge())
            tr, r = tf.transform.translation, tf.transform.rotation
            e.t_ns.append(stamp_ns(tf.header.stamp) if stamps == "header" else bag_ns)
            e.trans.append((float(tr.x), float(tr.y), float(tr.z)))
            e.quat.append((float(r.x), float(r.y), float(r.z), float(r.w)))
    return dynamic, static


def _parents(edges) -> dict[str, str]:
    parent: dict[str, str] = {}
    for p, c in edges:
        if c in parent and parent[c] != p:
            raise UserError(f"the transform tree gives frame {c!r} two parents ({parent[c]!r} and {p!r}); a tf tree "
                            "has one parent per frame: fix the recording or choose other frames.")
        parent[c] = p
    return parent


def _chain(frame: str, parent: dict[str, str]) -> list[tuple[str, str]]:
    """Edges from the root down to ``frame``."""
    out, seen = [], {frame}
    while frame in parent:
        out.append((parent[frame], frame))
        frame = parent[frame]
        if frame in seen:
            raise UserError(f"the transform tree has a loop through frame {frame!r}; fix the recording.")
        seen.add(frame)
    return out[::-1]


@dataclass
class TfTrack:
    """The pose of ``body_frame`` in ``world_frame`` from a transform tree (see the module docstring)."""

    topic: str
    world_frame: str
    body_frame: str
    world_chain: list  # edges root -> world frame
    body_chain: list  # edges root -> body frame
    edges: dict  # (parent, child) -> (t_ns (N,), trans (N, 3), quat (N, 4)) sorted; N == 1 and t None: static

    def _edge_at(self, key, query, tolerance_ns):
        from scipy.spatial.transform import Rotation

        t, trans, quat = self.edges[key]
        if t is None:
            return Rotation.from_quat(np.repeat(quat, len(query), axis=0)), np.repeat(trans, len(query), axis=0), \
                np.ones(len(query), bool)
        lo, hi, f, covered = bracket(t, query, tolerance_ns)
        r0 = Rotation.from_quat(quat[lo])
        delta = (r0.inv() * Rotation.from_quat(quat[hi])).as_rotvec()
        return r0 * Rotation.from_rotvec(f[:, None] * delta), trans[lo] + f[:, None] * (trans[hi] - trans[lo]), covered

    def _compose(self, chain, query, tolerance_ns):
        from scipy.spatial.transform import Rotation

        rot = Rotation.identity(len(query))
        pos = np.zeros((len(query), 3))
        ok = np.ones(len(query), bool)
        for key in chain:
            r, p, c = self._edge_at(key, query, tolerance_ns)
            pos = pos + rot.apply(p)
            rot = rot * r
            ok &= c
        return rot, pos, ok

    def at(self, query_ns, tolerance_ns: int):
        """``(xy (M, 2), yaw (M,), covered (M,))``: the body frame in the world frame at the query stamps."""
        query = np.asarray(query_ns, np.int64)
        rw, pw, okw = self._compose(self.world_chain, query, tolerance_ns)
        rb, pb, okb = self._compose(self.body_chain, query, tolerance_ns)
        inv = rw.inv()
        pos = inv.apply(pb - pw)
        x_axis = (inv * rb).apply(np.array([1.0, 0.0, 0.0]))
        covered = okw & okb
        xy = np.where(covered[:, None], pos[:, :2], np.nan)
        yaw = np.where(covered, np.arctan2(x_axis[:, 1], x_axis[:, 0]), np.nan)
        return xy, yaw, covered


def _frames_menu(parent: dict[str, str]) -> str:
    return ", ".join(f"{c} (parent {p})" for c, p in sorted(parent.items())) or "none"


def read_tf_track(bag, topic, *, stamps: str, tolerance_ns: int, world_frame: str | None,
                  pose_frame: str | None) -> TfTrack:
    """The tf tree of ``topic`` (and ``/tf_static``) as a :class:`TfTrack` from ``world_frame`` to ``pose_frame``."""
    statics = [t for t in bag.topics.values()
               if t.msgtype in TF_TYPES and t.name.rstrip("/").endswith("tf_static") and t.name != topic.name]
    dynamic, static = _collect_tf(bag, [topic, *statics], stamps)
    parent = _parents(list(dynamic) + list(static))
    body = (pose_frame or "base_link").lstrip("/")
    if body not in parent:
        key = "db.pose_frame" + ("" if pose_frame else " (default base_link)")
        raise UserError(f"{key}: the transform tree of {topic.name} has no frame {body!r}; its frames: "
                        f"{_frames_menu(parent)}. Set db.pose_frame=FRAME (the robot's, e.g. base_link or the camera's).")
    body_chain = _chain(body, parent)
    world = (world_frame or body_chain[0][0]).lstrip("/")
    world_chain = _chain(world, parent)
    root_b, root_w = body_chain[0][0], (world_chain[0][0] if world_chain else world)
    if root_b != root_w:
        raise UserError(f"db.world_frame={world} and db.pose_frame={body} are not connected by the transform tree of "
                        f"{topic.name} (roots {root_w!r} and {root_b!r}); its frames: {_frames_menu(parent)}.")
    edges = {}
    for key in set(body_chain) | set(world_chain):
        if key in static and key not in dynamic:
            e = static[key]
            edges[key] = (None, np.asarray(e.trans[-1:], np.float64), np.asarray(e.quat[-1:], np.float64))
            continue
        e = dynamic[key]
        t = np.asarray(e.t_ns, np.int64)
        order = ordered(t, topic=f"{topic.name} ({key[0]} -> {key[1]})", tolerance_ns=tolerance_ns)
        edges[key] = (t[order], np.asarray(e.trans, np.float64)[order], np.asarray(e.quat, np.float64)[order])
    return TfTrack(topic.name, world, body, world_chain, body_chain, edges)


def read_poses(bag, topic, *, stamps: str, tolerance_ns: int, world_frame: str | None, pose_frame: str | None):
    """The pose track of ``topic`` (:class:`PoseTrack`, or :class:`TfTrack` for a tf topic)."""
    if topic.msgtype in TF_TYPES:
        return read_tf_track(bag, topic, stamps=stamps, tolerance_ns=tolerance_ns, world_frame=world_frame,
                             pose_frame=pose_frame)
    return read_pose_track(bag, topic, stamps=stamps, tolerance_ns=tolerance_ns, world_frame=world_frame)
