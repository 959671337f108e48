"""The views of a bag: every image message's stamp and pose first, then only the images needed, decoded.

Reading is two streams over the bag. :func:`index_views` reads the pose
topic (:mod:`bionav.db.bag.poses`) and the image topic's messages one at a
time, keeping of each image only its stamps, encoding and size (so memory
grows with the number of messages, not their bytes), and interpolates a pose
to every image stamp. :func:`decode_views` then reads back only the images a
database keeps (through the bag's time index) and decodes them
(:mod:`bionav.db.bag.images`).

Images whose stamp the poses do not cover (``db.pose_tolerance_s``) are left
out and counted in the log; images whose encoding or size differs from the
first are an error (``db.on_bad_image=skip``: left out and counted).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from bionav.db.bag.images import check_encoding, decode, image_message
from bionav.db.bag.poses import NS, ordered, read_poses
from bionav.db.bag.reader import IMAGE_TYPES, POSE_TYPES, header_ns
from bionav.errors import UserError

log = logging.getLogger(__name__)

#: decode by the time index when fewer than one message in this many is wanted, else in one pass
WINDOW_SHARE = 8


@dataclass
class ViewIndex:
    """Stamps and poses of the usable images of one topic, in stamp order.

    Attributes
    ----------
    topic : Topic
    index : ndarray, shape (N,), int
        Position of each image on its topic (0-based).
    stamp_ns, bag_ns : ndarray, shape (N,), int
        The stamp used (``db.stamps``) and the time the bag recorded the message.
    xy : ndarray, shape (N, 2)
        Interpolated position, metres, world frame.
    yaw : ndarray, shape (N,)
        Interpolated heading of the robot, radians CCW from world +x.
    n_messages, n_uncovered, n_odd : int
        Messages on the topic; left out because no pose covers them; left out as odd (skip).
    signature : tuple
        Kind, encoding and raw size shared by the images.
    """

    topic: object
    index: np.ndarray
    stamp_ns: np.ndarray
    bag_ns: np.ndarray
    xy: np.ndarray
    yaw: np.ndarray
    n_messages: int
    n_uncovered: int
    n_odd: int
    signature: tuple
    pose_topic: str
    world_frame: str
    message_bag_ns: np.ndarray  # the bag's record time of every message on the topic, in topic order


def check_topics(bag, cfg):
    """The checked image and pose topics (one message lists both kinds when a key is missing)."""
    missing = [k for k, v in (("db.image_topic", cfg.image_topic), ("db.pose_topic", cfg.pose_topic)) if not v]
    if missing:
        images = "; ".join(t.describe() for t in bag.of_types(IMAGE_TYPES)) or "none"
        poses = "; ".join(t.describe() for t in bag.of_types(POSE_TYPES)) or "none"
        raise UserError(f"{' and '.join(missing)} {'is' if len(missing) == 1 else 'are'} not set: say which topics of "
                        f"the {bag.kind} {bag.path} hold the views and the poses. Image topics: {images}. Pose topics: "
                        f"{poses}. Set {' '.join(k + '=TOPIC' for k in missing)}.")
    image = bag.topic(cfg.image_topic, key="db.image_topic", types=IMAGE_TYPES, what="image")
    pose = bag.topic(cfg.pose_topic, key="db.pose_topic", types=POSE_TYPES, what="pose")
    return image, pose


def index_views(bag, cfg) -> ViewIndex:
    """Stamps and interpolated poses of every image of ``db.image_topic`` (see the module docstring).

    Raises
    ------
    UserError
        A missing, misspelt or wrongly typed topic; images of changing encoding or size
        (unless ``db.on_bad_image=skip``); stamps that jump back; no image covered by the poses.
    """
    image_topic, pose_topic = check_topics(bag, cfg)
    tol = int(round(cfg.pose_tolerance_s * NS))
    track = read_poses(bag, pose_topic, stamps=cfg.stamps, tolerance_ns=tol, world_frame=cfg.world_frame,
                       pose_frame=cfg.pose_frame)
    skip = cfg.on_bad_image == "skip"
    stamps, bag_times, index, every = [], [], [], []
    first, odd = None, 0
    for i, (_name, msgtype, bag_ns, msg) in enumerate(bag.messages([image_topic.name])):
        every.append(bag_ns)
        t = header_ns(msg) if cfg.stamps == "header" else bag_ns
        m = image_message(msg, msgtype, stamp_ns=t, index=i)
        if first is None:
            check_encoding(m, image_topic.name)
            first = m
        elif m.signature != first.signature:
            if not skip:
                raise UserError(f"the images of {image_topic.name} change at {m.describe()}: the first was "
                                f"{first.describe()}; a database needs one camera stream of one encoding and size. "
                                "Choose a topic with one stream, or leave the odd images out with db.on_bad_image=skip.")
            odd += 1
            continue
        stamps.append(t)
        bag_times.append(bag_ns)
        index.append(i)
    if first is None:
        raise UserError(f"{image_topic.name} in {bag.path} holds no messages that can be read; choose another "
                        "db.image_topic.")
    n_messages = len(stamps) + odd
    stamps, bag_times, index = (np.asarray(a, np.int64) for a in (stamps, bag_times, index))
    order = ordered(stamps, topic=image_topic.name, tolerance_ns=tol, what="image")
    stamps, bag_times, index = stamps[order], bag_times[order], index[order]
    xy, yaw, covered = track.at(stamps, tol)
    n_uncovered = int((~covered).sum())
    _log_coverage(image_topic.name, pose_topic.name, stamps, covered, cfg.pose_tolerance_s, odd)
    if not covered.any():
        span = getattr(track, "span_s", None)
        poses = f" (poses from {span[0]:.3f} s to {span[1]:.3f} s)" if span else ""
        raise UserError(f"none of the {len(stamps)} images of {image_topic.name} (stamps {stamps[0] / NS:.3f} s to "
                        f"{stamps[-1] / NS:.3f} s) has a pose of {pose_topic.name} within db.pose_tolerance_s="
                        f"{cfg.pose_tolerance_s:g} s before and after it{poses}. Check that both topics come from one "
                        "recording and one clock (db.stamps=bag uses the bag's record times), or raise "
                        "db.pose_tolerance_s." if len(stamps) else f"{image_topic.name} holds no usable images.")
    return ViewIndex(image_topic, index[covered], stamps[covered], bag_times[covered], xy[covered], yaw[covered],
                     n_messages, n_uncovered, odd, first.signature, pose_topic.name, track.world_frame,
                     np.asarray(every, np.int64))


def _log_coverage(image_topic: str, pose_topic: str, stamps, covered, tolerance_s: float, odd: int) -> None:
    if odd:
        log.warning("%s: %d image(s) of another encoding or size than the first left out (db.on_bad_image=skip)",
                    image_topic, odd)
    n_out = int((~covered).sum())
    if n_out:
        out = stamps[~covered] / NS
        log.warning("%s: %d of %d images left out: no pose of %s within db.pose_tolerance_s=%g s before and after "
                    "them (their stamps %.3f s to %.3f s)", image_topic, n_out, len(stamps), pose_topic,
                    tolerance_s, out.min(), out.max())
    else:
        log.info("%s: all %d images have a pose of %s", image_topic, len(stamps), pose_topic)


def _map(fn, items: list) -> list:
    """``[fn(x) for x in items]`` on up to 2 threads of this process's CPUs (decoding releases the GIL)."""
    from bionav.machine import usable_cpus

    threads = min(2, usable_cpus(), len(items))
    if threads < 2:
        return [fn(x) for x in items]
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(threads) as pool:
        return list(pool.map(fn, items))


def decode_views(bag, views: ViewIndex, which, *, skip: bool, shape=None):
    """Decode the images ``which`` (positions in ``views``): ``(kept positions, frames)`` in the order given.

    Only those messages are read, by their record times in the bag's index. Images whose decoded size
    differs from ``shape`` (default: the first's) are an error (``skip``: left out, logged).
    """
    which = [int(w) for w in which]
    wanted = {}
    for w in which:
        wanted.setdefault(int(views.bag_ns[w]), {})[int(views.index[w])] = w
    found: dict[int, object] = {}
    topic = views.topic.name
    times = sorted(wanted)
    # a few images: each read through the bag's time index; many: one pass over the topic from the first to the last
    windows = [(t, t + 1) for t in times] if len(times) * WINDOW_SHARE < len(views.message_bag_ns) else \
        [(times[0], times[-1] + 1)]
    for start, stop in windows:
        position = int(np.searchsorted(views.message_bag_ns, start))  # the topic's first message recorded at start
        for _name, msgtype, bag_ns, msg in bag.messages([topic], start=start, stop=stop):
            w = wanted.get(bag_ns, {}).get(position)
            position += 1
            if w is None:
                continue
            found[w] = image_message(msg, msgtype, stamp_ns=int(views.stamp_ns[w]), index=position - 1)
    frames = dict(zip(found, _map(lambda m: decode(m, topic), list(found.values()))))
    kept, out = [], []
    for w in which:
        f = frames.get(w)
        if f is None:
            raise UserError(f"{topic}: image message {int(views.index[w])} was indexed but cannot be read back from "
                            f"{bag.path}; the bag changed while it was read, or its index is damaged (reindex it).")
        if shape is None:
            shape = f.shape
        elif f.shape != shape:
            if not skip:
                raise UserError(f"{topic}: image message {int(views.index[w])} decodes to {f.shape[1]} x {f.shape[0]} "
                                f"pixels, the first to {shape[1]} x {shape[0]}; a database needs one size. Leave such "
                                "images out with db.on_bad_image=skip.")
            log.warning("%s: image message %d (%d x %d) left out: another size than the first", topic,
                        int(views.index[w]), f.shape[1], f.shape[0])
            continue
        kept.append(w)
        out.append(f)
    return kept, out
