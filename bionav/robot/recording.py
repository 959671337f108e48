"""Recording cleaning runs to ``run.mcap`` and replaying them through a controller.

What a replay needs (and what :class:`EpisodeRecorder` therefore logs):

* per run (``/cleaning/run``): the controller's name and config, the plan, the
  seed of the controller's random generator and of the camera noise, the
  wheel error and the start pose (the latter two only for analysis);
* per tick (``/cleaning/step``): the controller's inputs -- time, odometry
  pose, wall reading, bumper -- and its output (wheel commands, done), plus
  the digest (:func:`bionav.robot.simulator.image_digest`) and true pose of
  every image the controller grabbed during the tick;
* the images themselves when ``log_images`` is on: ``/cleaning/capture``
  (``bionav.Capture``: run, tick, capture index and the exact array, any dtype
  and shape, for replay) and, for 2-D images, ``/cleaning/image``
  (``foxglove.RawImage``, ``32FC1`` brightness 0..1 or ``mono8``/``mono16``,
  for viewing in Foxglove). Without them a replay re-creates each image with
  the run's camera (the renderer is deterministic, the camera noise is seeded
  per run and capture) at the logged true pose and checks it against the
  logged digest.

Log times are the run's wall-clock start (:attr:`bionav.logs.writer.McapLog.start_ns`)
plus simulated time, runs laid end to end.

:func:`replay_episode` feeds the logged observations to a freshly reset
controller and compares every command it emits with the logged one, exactly
(floats round-trip through JSON without loss).
"""

from __future__ import annotations

import base64
from dataclasses import dataclass, field
from typing import Any, Callable, Iterable

import numpy as np

from bionav.errors import UserError
from bionav.robot.controller import Controller, LanePlan, Observation, WallReading
from bionav.robot.kinematics import Pose
from bionav.robot.simulator import image_digest

STEP_TOPIC = "/cleaning/step"
RUN_TOPIC = "/cleaning/run"
IMAGE_TOPIC = "/cleaning/image"
CAPTURE_TOPIC = "/cleaning/capture"
POSE_TOPIC = "/cleaning/true_pose"
CONTROLLER_TOPIC = "/cleaning/controller"
RESULT_TOPIC = "/cleaning/result"

_POSE3 = {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3,
          "description": "(x m, y m, theta rad CCW)"}

STEP_SCHEMA = {
    "type": "object",
    "title": "bionav.CleaningStep",
    "description": "One control tick: the controller's inputs and output.",
    "properties": {
        "run": {"type": "integer"},
        "tick": {"type": "integer"},
        "time": {"type": "number", "description": "seconds since the run's start"},
        "odometry": {**_POSE3, "description": "odometry pose (the controller's input), odometry frame"},
        "true_pose": {**_POSE3, "description": "true pose, world frame (not seen by the controller)"},
        "wall": {"type": ["array", "null"], "description": "(distance m, angle rad) of the wall sensor"},
        "bumper": {"type": "boolean"},
        "command": {"type": "array", "description": "(v_left, v_right) m/s emitted by the controller"},
        "done": {"type": "boolean"},
        "captures": {"type": "array", "description": "images grabbed: {index, digest, true_pose}"},
    },
}

RUN_SCHEMA = {
    "type": "object",
    "title": "bionav.CleaningRun",
    "description": "Everything needed to replay one run besides its steps.",
    "properties": {
        "run": {"type": "integer"},
        "controller": {"type": "string"},
        "controller_config": {"type": "object"},
        "plan": {"type": "object"},
        "controller_seed": {"type": "integer"},
        "camera_seed": {"type": "integer"},
        "wheel_error": {"type": "array"},
        "start": _POSE3,
    },
}

CONTROLLER_SCHEMA = {
    "type": "object",
    "title": "bionav.ControllerInternals",
    "description": "Controller internals: snapshots stored, triangulation fixes (h, e, chosen snapshots), lane events.",
}

CAPTURE_SCHEMA = {
    "type": "object",
    "title": "bionav.Capture",
    "description": "One grabbed image exactly as the controller saw it (little-endian bytes), for replay.",
    "properties": {
        "run": {"type": "integer"},
        "tick": {"type": "integer"},
        "index": {"type": "integer", "description": "capture index within the run"},
        "dtype": {"type": "string", "description": "numpy dtype, e.g. float32"},
        "shape": {"type": "array", "items": {"type": "integer"}},
        "data": {"type": "string", "contentEncoding": "base64"},
    },
    "required": ["run", "tick", "index", "dtype", "shape", "data"],
}


def _stamp(ns: int) -> dict:
    return {"sec": int(ns // 1_000_000_000), "nsec": int(ns % 1_000_000_000)}


def raw_image_from_array(image: np.ndarray, *, timestamp_ns: int, frame_id: str) -> dict:
    """A ``foxglove.RawImage`` message of a single-channel image, in an encoding Foxglove displays.

    Parameters
    ----------
    image : ndarray, shape (H, W)
        Brightness: float (0 = black, 1 = white; float64 is converted to
        float32, Foxglove has no 64-bit encoding), uint8 or uint16.
    timestamp_ns : int
        Nanoseconds since the Unix epoch.
    frame_id : str
        Frame of the camera.

    Returns
    -------
    dict
        Exactly the fields of Foxglove's schema: ``timestamp``, ``frame_id``,
        ``width``, ``height``, ``encoding`` (``32FC1``, ``mono8`` or ``mono16``),
        ``step`` and base64 little-endian ``data``.

    Raises
    ------
    ValueError
        For arrays that are not 2-D, or of another dtype.
    """
    a = np.asarray(image)
    if a.ndim != 2:
        raise ValueError(f"a foxglove.RawImage needs a single-channel image (H, W), not shape {a.shape}")
    if a.dtype.kind == "f":
        enc, dtype = "32FC1", np.dtype("<f4")
    elif a.dtype == np.uint8:
        enc, dtype = "mono8", np.dtype("u1")
    elif a.dtype == np.uint16:
        enc, dtype = "mono16", np.dtype("<u2")
    else:
        raise ValueError(f"cannot log images of dtype {a.dtype} as foxglove.RawImage (float, uint8 or uint16)")
    h, w = a.shape
    data = np.ascontiguousarray(a, dtype=dtype).tobytes()
    return {"timestamp": _stamp(timestamp_ns), "frame_id": frame_id, "width": int(w), "height": int(h),
            "encoding": enc, "step": int(w * dtype.itemsize), "data": base64.b64encode(data).decode()}


def encode_capture(image: np.ndarray) -> dict:
    """``{dtype, shape, data}`` of an array, little-endian and lossless (any dtype, any shape)."""
    a = np.asarray(image)
    data = np.ascontiguousarray(a, dtype=a.dtype.newbyteorder("<")).tobytes()
    return {"dtype": str(a.dtype), "shape": [int(n) for n in a.shape], "data": base64.b64encode(data).decode()}


def decode_capture(message: dict) -> np.ndarray:
    """Inverse of :func:`encode_capture` (also reads the old ``/cleaning/image`` messages with an index)."""
    if "dtype" in message:
        dtype = np.dtype(message["dtype"])
        raw = np.frombuffer(base64.b64decode(message["data"]), dtype=dtype.newbyteorder("<"))
        return raw.astype(dtype).reshape(message["shape"])
    dtype = {"32FC1": "<f4", "64FC1": "<f8"}[message["encoding"]]  # logs written before issue 20
    a = np.frombuffer(base64.b64decode(message["data"]), dtype=dtype).reshape(message["height"], message["width"])
    a = a.astype(np.float32 if message["encoding"] == "32FC1" else np.float64)
    return a[0] if message.get("vector") else a


@dataclass
class EpisodeRecorder:
    """Writes one run's ticks to a log (anything with ``write(topic, message, *, schema_name, schema, log_time_ns)``).

    Parameters
    ----------
    log : McapLog
        The run log.
    run : int
        Run index.
    time_offset_ns : int
        Log time of the run's first tick (runs are laid end to end).
    log_images : bool
        Also log every grabbed image (lossless).
    pose_every : int
        Write a ``foxglove.PoseInFrame`` of the true pose every this many ticks.
    """

    log: Any
    run: int
    time_offset_ns: int = 0
    log_images: bool = False
    pose_every: int = 10
    last_time_ns: int = field(default=0, init=False)

    def __post_init__(self) -> None:
        self.last_time_ns = int(self.time_offset_ns)

    def start(self, meta: dict) -> None:
        """Write the run's ``/cleaning/run`` message."""
        self.log.write(RUN_TOPIC, {"run": self.run, **meta}, schema_name="bionav.CleaningRun", schema=RUN_SCHEMA,
                       log_time_ns=self.time_offset_ns)

    def on_tick(self, tick: int, obs: Observation, cmd, robot) -> None:
        """Callback for :func:`bionav.robot.simulator.run_episode`."""
        ns = self.time_offset_ns + int(round(obs.time * 1e9))
        self.last_time_ns = ns
        captures = []
        for img, pose, index in robot.captures:
            captures.append({"index": index, "digest": image_digest(img), "true_pose": list(pose.as_tuple())})
            if self.log_images:
                self.log.write(CAPTURE_TOPIC, {"run": self.run, "tick": tick, "index": index, **encode_capture(img)},
                               schema_name="bionav.Capture", schema=CAPTURE_SCHEMA, log_time_ns=ns)
                if np.ndim(img) == 2:  # panoramas (not the oracle's pose vectors) also for Foxglove's Image panel
                    self.log.write(IMAGE_TOPIC, raw_image_from_array(img, timestamp_ns=ns, frame_id="camera"),
                                   schema_name="foxglove.RawImage", log_time_ns=ns)
        wall = None if obs.wall is None else [obs.wall.distance, obs.wall.angle]
        self.log.write(STEP_TOPIC, {
            "run": self.run, "tick": tick, "time": obs.time, "odometry": list(obs.odometry.as_tuple()),
            "true_pose": list(robot.pose.as_tuple()), "wall": wall, "bumper": bool(obs.bumper),
            "command": [float(cmd.v_left), float(cmd.v_right)], "done": bool(cmd.done), "captures": captures,
        }, schema_name="bionav.CleaningStep", schema=STEP_SCHEMA, log_time_ns=ns)
        if cmd.info:
            self.log.write(CONTROLLER_TOPIC, {"run": self.run, "tick": tick, "time": obs.time, **cmd.info},
                           schema_name="bionav.ControllerInternals", schema=CONTROLLER_SCHEMA, log_time_ns=ns)
        if self.pose_every and tick % self.pose_every == 0:
            x, y, th = robot.pose.as_tuple()
            self.log.write(POSE_TOPIC, {
                "timestamp": _stamp(ns), "frame_id": "world",
                "pose": {"position": {"x": x, "y": y, "z": 0.0},
                         "orientation": {"x": 0.0, "y": 0.0, "z": float(np.sin(th / 2)), "w": float(np.cos(th / 2))}},
            }, schema_name="foxglove.PoseInFrame", log_time_ns=ns)


@dataclass
class LoggedRun:
    """One run read back from a log: its run message, its steps (tick order) and any logged images."""

    meta: dict
    steps: list[dict]
    images: dict[int, np.ndarray]


def load_logged_runs(messages: Iterable[tuple[str, int, dict]]) -> dict[int, LoggedRun]:
    """Group ``(topic, log_time_ns, message)`` tuples (:func:`bionav.logs.read_messages`) by run."""
    runs: dict[int, LoggedRun] = {}
    for topic, _t, msg in messages:
        if topic not in (RUN_TOPIC, STEP_TOPIC, IMAGE_TOPIC, CAPTURE_TOPIC):
            continue
        if topic == IMAGE_TOPIC and "index" not in msg:  # a view for Foxglove; the exact copy is the capture
            continue
        r = runs.setdefault(int(msg["run"]), LoggedRun({}, [], {}))
        if topic == RUN_TOPIC:
            r.meta = msg
        elif topic == STEP_TOPIC:
            r.steps.append(msg)
        else:
            r.images[int(msg["index"])] = decode_capture(msg)
    for r in runs.values():
        r.steps.sort(key=lambda m: m["tick"])
    return runs


class ReplayMismatch(UserError):
    """A replayed controller did something else than the logged one."""


@dataclass
class ReplayResult:
    """Outcome of a replay: the number of ticks compared and the replayed commands ``(T, 2)``."""

    n_ticks: int
    commands: np.ndarray


def replay_episode(run: LoggedRun, controller: Controller, plan: LanePlan, *, homing=None,
                   camera: Callable[[Pose, int], np.ndarray] | None = None) -> ReplayResult:
    """Feed a logged run back through a controller and check its commands.

    Parameters
    ----------
    run : LoggedRun
        The logged run (:func:`load_logged_runs`).
    controller : Controller
        A controller of the logged kind and config (it is reset here with the
        logged seed).
    plan : LanePlan
        The logged plan.
    homing : HomingMethod, optional
        The homing method of the run (vision controllers).
    camera : callable, optional
        ``camera(true_pose, capture_index) -> image`` to re-create images that
        are not in the log (their digests are checked).

    Returns
    -------
    ReplayResult

    Raises
    ------
    ReplayMismatch
        On the first tick whose command (or image request, or image digest)
        differs from the log.
    """
    controller.reset(plan, homing=homing, rng=np.random.default_rng(int(run.meta["controller_seed"])))
    out = []
    for step in run.steps:
        captures = list(step["captures"])
        used = []

        def grab(captures=captures, used=used, tick=step["tick"]) -> np.ndarray:
            if len(used) >= len(captures):
                raise ReplayMismatch(f"replay: the controller grabbed an image at tick {tick} that the logged run "
                                     f"did not grab; the controller or its config differs from the logged one.")
            cap = captures[len(used)]
            used.append(cap)
            if cap["index"] in run.images:
                img = run.images[cap["index"]]
            elif camera is not None:
                img = camera(Pose(*cap["true_pose"]), int(cap["index"]))
            else:
                raise ReplayMismatch(f"replay: image {cap['index']} of tick {tick} is not in the log and no camera "
                                     f"was given to re-create it; log images (experiment.log_images=true) or pass "
                                     f"the run's camera.")
            if image_digest(img) != cap["digest"]:
                raise ReplayMismatch(f"replay: image {cap['index']} of tick {tick} differs from the logged one "
                                     f"(digest mismatch); the world, camera or renderer changed since the run.")
            return img

        wall = None if step["wall"] is None else WallReading(float(step["wall"][0]), float(step["wall"][1]))
        obs = Observation(time=float(step["time"]), odometry=Pose(*step["odometry"]),
                          camera=grab if run.meta.get("camera", True) else None,
                          wall=wall, bumper=bool(step["bumper"]))
        cmd = controller.step(obs)
        got = (float(cmd.v_left), float(cmd.v_right), bool(cmd.done))
        want = (float(step["command"][0]), float(step["command"][1]), bool(step["done"]))
        if got != want:
            raise ReplayMismatch(f"replay: tick {step['tick']} of run {run.meta.get('run')} gives command {got}, "
                                 f"the log says {want}.")
        if len(used) != len(captures):
            raise ReplayMismatch(f"replay: at tick {step['tick']} the controller grabbed {len(used)} image(s), "
                                 f"the logged run {len(captures)}.")
        out.append(got[:2])
    return ReplayResult(len(out), np.array(out).reshape(-1, 2))
