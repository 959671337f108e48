"""A simulated differential-drive cleaning robot and the control loop that drives it.

The simulator owns the *true* pose; the controller only gets an
:class:`~bionav.robot.controller.Observation` (odometry, camera, wall sensor,
bumper). The wheels really turn at the commanded speeds times ``1 + e`` (the
static wheel error of :class:`~bionav.robot.kinematics.DriveModel`); the
odometry integrates the commanded speeds, so it does not know the error.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from bionav.robot.controller import Command, Controller, Observation, WallReading
from bionav.robot.floorplan import FloorPlan
from bionav.robot.kinematics import DriveModel, Pose, integrate_pose

Camera = Callable[[Pose, int], np.ndarray]
"""``camera(true_pose, capture_index) -> image``: renders the robot's view."""


def image_digest(image: np.ndarray) -> str:
    """SHA-256 (hex, first 16 bytes) of an image's dtype, shape and bytes; identifies it in logs."""
    a = np.ascontiguousarray(image)
    h = hashlib.sha256()
    h.update(str(a.dtype).encode())
    h.update(str(a.shape).encode())
    h.update(a.tobytes())
    return h.hexdigest()[:32]


@dataclass
class RangeSensor:
    """Two infrared range rays on the robot's right side that estimate a wall line.

    Parameters
    ----------
    angles : (float, float)
        Ray directions in the robot frame (radians CCW; default right and
        front-right).
    max_range : float
        Rays longer than this see nothing (m).
    noise : float
        Std of the range noise (m).
    """

    angles: tuple[float, float] = (-np.pi / 2, -np.pi / 4)
    max_range: float = 1.0
    noise: float = 0.003

    def read(self, floor: FloorPlan, pose: Pose, rng: np.random.Generator) -> WallReading | None:
        """Wall estimate from the two rays, ``None`` if a ray sees nothing."""
        pts = []
        for a in self.angles:
            r = floor.raycast(pose.x, pose.y, pose.theta + a, max_range=self.max_range)
            if not np.isfinite(r):
                return None
            r = r + self.noise * rng.standard_normal()
            pts.append((r * np.cos(a), r * np.sin(a)))
        (x1, y1), (x2, y2) = pts
        dx, dy = x2 - x1, y2 - y1
        n = np.hypot(dx, dy)
        if n < 1e-9:
            return None
        # distance from the robot (origin) to the line through the two hits
        dist = abs(x1 * dy - y1 * dx) / n
        return WallReading(float(dist), float(np.arctan2(dy, dx)))


@dataclass
class SimulatedRobot:
    """Physical state of a simulated robot.

    Parameters
    ----------
    drive : DriveModel
        Wheel distance and static wheel error.
    start : Pose
        True start pose in the world (metres, radians).
    floor : FloorPlan, optional
        Obstacles (collisions, range sensor).
    radius : float
        Robot footprint radius (m) for collisions.
    confine : ((x_lo, y_lo), (x_hi, y_hi), Pose), optional
        Virtual walls: a rectangle in the frame of the given pose that the
        robot's centre may not leave.
    camera : Camera, optional
        Renders the view at the true pose.
    range_sensor : RangeSensor
        The wall sensor.
    rng : numpy.random.Generator
        Sensor noise.
    """

    drive: DriveModel
    start: Pose
    floor: FloorPlan | None = None
    radius: float = 0.18
    confine: tuple | None = None
    camera: Camera | None = None
    range_sensor: RangeSensor = field(default_factory=RangeSensor)
    rng: np.random.Generator = field(default_factory=lambda: np.random.default_rng(0))

    def __post_init__(self) -> None:
        self.pose = self.start
        self.odometry = Pose(0.0, 0.0, 0.0)
        self.bumper = False
        self.captures: list[tuple[np.ndarray, Pose]] = []
        self._n_captures = 0

    def _free(self, pose: Pose) -> bool:
        if self.floor is not None and self.floor.clearance(pose.x, pose.y) < self.radius:
            return False
        if self.confine is not None:
            lo, hi, frame = self.confine
            p = pose.relative_to(frame)
            if not (lo[0] <= p.x <= hi[0] and lo[1] <= p.y <= hi[1]):
                return False
        return True

    def observe(self, time: float) -> Observation:
        """The observation a controller gets now (camera grabs at the current true pose)."""
        self.captures = []
        cam = None
        if self.camera is not None:
            pose = self.pose

            def cam() -> np.ndarray:
                img = self.camera(pose, self._n_captures)
                self._n_captures += 1
                self.captures.append((img, pose))
                return img

        wall = None
        if self.floor is not None:
            wall = self.range_sensor.read(self.floor, self.pose, self.rng)
        return Observation(time=time, odometry=self.odometry, camera=cam, wall=wall, bumper=self.bumper)

    def apply(self, v_left: float, v_right: float, dt: float) -> tuple[float, float]:
        """Drive for ``dt`` seconds; returns the clipped commands actually sent to the motors."""
        vl, vr = self.drive.clip(v_left, v_right)
        tl, tr = self.drive.true_speeds(vl, vr)
        tw = self.drive.track_width
        new = integrate_pose(self.pose, tl, tr, dt, track_width=tw)
        odo = integrate_pose(self.odometry, vl, vr, dt, track_width=tw)
        self.bumper = False
        if not self._free(new):
            # blocked: the wheels stall, only turning on the spot is possible
            self.bumper = True
            new = Pose(self.pose.x, self.pose.y, new.theta)
            odo = Pose(self.odometry.x, self.odometry.y, odo.theta)
        self.pose = new
        self.odometry = odo
        return vl, vr


@dataclass
class Episode:
    """Recorded run.

    Attributes
    ----------
    time : ndarray (T,)
        Tick times (s).
    true_pose, odometry : ndarray (T, 3)
        Pose before each tick's command (world frame / odometry frame).
    command : ndarray (T, 2)
        Wheel speeds sent (m/s).
    info : list of (tick, dict)
        Non-empty controller internals.
    finished : bool
        The controller reported ``done`` before the time limit.
    """

    time: np.ndarray
    true_pose: np.ndarray
    odometry: np.ndarray
    command: np.ndarray
    info: list
    finished: bool


def run_episode(controller: Controller, robot: SimulatedRobot, *, dt: float = 0.1, max_time: float,
                on_tick: Callable[[int, Observation, Command, SimulatedRobot], None] | None = None) -> Episode:
    """Close the loop between a controller and a simulated robot.

    Parameters
    ----------
    controller : Controller
        Already :meth:`~Controller.reset`.
    robot : SimulatedRobot
        The robot at its start pose.
    dt : float
        Control period in seconds.
    max_time : float
        The run ends after this many seconds even if the controller is not done.
    on_tick : callable, optional
        ``on_tick(tick, observation, command, robot)`` after each command is
        computed and before it is applied (logging). ``robot.captures`` holds
        the images grabbed during the tick.

    Returns
    -------
    Episode
        The trajectory including the final pose (one more pose than commands
        is not kept: the final pose is appended with a zero command).
    """
    times, poses, odos, cmds, infos = [], [], [], [], []
    finished = False
    tick = 0
    t = 0.0
    while True:
        obs = robot.observe(t)
        cmd = controller.step(obs)
        times.append(t)
        poses.append(robot.pose.as_tuple())
        odos.append(robot.odometry.as_tuple())
        if on_tick is not None:
            on_tick(tick, obs, cmd, robot)
        if cmd.info:
            infos.append((tick, cmd.info))
        if cmd.done:
            cmds.append((0.0, 0.0))
            finished = True
            break
        if t >= max_time:
            cmds.append((0.0, 0.0))
            break
        cmds.append(robot.apply(cmd.v_left, cmd.v_right, dt))
        tick += 1
        t = tick * dt
    return Episode(np.array(times), np.array(poses), np.array(odos), np.array(cmds), infos, finished)
