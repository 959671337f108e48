"""The controller protocol: what a cleaning-robot controller sees and what it emits.

A controller is a ``bionav.controllers`` plugin. It sees only what a real
robot's computer sees and emits wheel commands, so the same object can drive
the simulator (:mod:`bionav.robot.simulator`), a replayed log
(:mod:`bionav.experiments.cleaning_replay`) or real hardware:

* :class:`Observation` (one per control tick): the time, the odometry pose
  (dead reckoning from the wheel encoders, frame fixed at the start of the
  run, *not* the true pose), a camera it may trigger to grab a panoramic
  image in the robot's own frame (canonical panorama, :mod:`bionav.geometry`),
  a side range sensor's wall estimate and the bumper;
* its own state (e.g. the topological map of snapshots it builds);
* the task (:class:`LanePlan`) and, if it uses vision, a homing method
  (:class:`bionav.homing.base.HomingMethod`) injected at :meth:`Controller.reset`.

It returns a :class:`Command` per tick: wheel speeds for the next tick,
whether the job is finished, and a JSON-serialisable ``info`` dict with its
internals for the log (empty on most ticks).

Determinism (needed for replay): a controller's commands must be a pure
function of its config, the plan, the seed given to :meth:`Controller.reset`,
the homing method and the sequence of observations (including the images the
camera returned). No wall-clock time, no global random state.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, ClassVar

import numpy as np

from bionav.robot.kinematics import Pose


@dataclass(frozen=True)
class WallReading:
    """A side range sensor's estimate of a wall on the robot's right.

    Attributes
    ----------
    distance : float
        Perpendicular distance from the robot's reference point to the wall
        line, metres.
    angle : float
        Direction of the wall line in the robot's frame (radians CCW; 0 when
        the robot drives parallel to the wall, positive when the wall turns
        away to the left).
    """

    distance: float
    angle: float


@dataclass(frozen=True)
class Observation:
    """Everything the controller may use at one control tick.

    Attributes
    ----------
    time : float
        Seconds since the start of the run.
    odometry : Pose
        Dead-reckoned pose from the wheel encoders (metres, radians CCW), in
        the odometry frame (the pose at the start of the run is the origin).
    camera : callable or None
        ``camera() -> ndarray (H, W) float32`` grabs a canonical panorama in
        the robot's own frame (column 0 along the heading). Calling it is
        what costs time on a real robot, so controllers grab only when they
        need an image. ``None`` when the robot has no camera.
    wall : WallReading or None
        Right-side wall estimate, ``None`` when no wall is in range.
    bumper : bool
        True when the robot touched an obstacle during the last tick (the
        motion was blocked).
    """

    time: float
    odometry: Pose
    camera: Callable[[], np.ndarray] | None = None
    wall: WallReading | None = None
    bumper: bool = False


@dataclass(frozen=True)
class Command:
    """Wheel commands for the next tick.

    Attributes
    ----------
    v_left, v_right : float
        Wheel speeds in m/s (positive forwards).
    done : bool
        The controller has finished its job (the run ends).
    info : dict
        JSON-serialisable internals for the log (empty when nothing new).
    """

    v_left: float
    v_right: float
    done: bool = False
    info: dict = field(default_factory=dict)


@dataclass(frozen=True)
class LanePlan:
    """The cleaning task: a meander of parallel lanes.

    The *plan frame* has its origin at the start of the first lane, ``+x``
    along the first lane. The first lane runs along a wall on the robot's
    right at ``wall_offset`` metres; later lanes follow at ``spacing`` metres
    to the left (``turn = "left"``) or right (``turn = "right"``) of their
    predecessor, in alternating directions.

    Attributes
    ----------
    n_lanes : int
        Number of lanes.
    lane_length : float
        Length of each lane in metres.
    spacing : float
        Inter-lane distance in metres (the cleaning unit's width).
    turn : str
        ``"left"`` or ``"right"``: the side on which the next lane lies.
    wall_offset : float
        Distance of the first lane from the wall on its right, metres.
    unit_width : float
        Width of the cleaning unit in metres.
    """

    n_lanes: int = 7
    lane_length: float = 4.0
    spacing: float = 0.30
    turn: str = "left"
    wall_offset: float = 0.25
    unit_width: float = 0.30

    def __post_init__(self) -> None:
        if self.turn not in ("left", "right"):
            raise ValueError(f"turn must be 'left' or 'right', got {self.turn!r}")
        if self.n_lanes < 1 or self.lane_length <= 0 or self.spacing <= 0:
            raise ValueError("n_lanes >= 1, lane_length > 0 and spacing > 0 are required")

    @property
    def side(self) -> int:
        """+1 when lanes stack to the left (plan ``+y``), -1 to the right."""
        return 1 if self.turn == "left" else -1

    @property
    def ideal_path_length(self) -> float:
        """Distance driven by a perfect meander (lanes plus lane changes), metres."""
        return self.n_lanes * self.lane_length + (self.n_lanes - 1) * self.spacing

    def target_rectangle(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """Target area in the plan frame: ``((x_lo, y_lo), (x_hi, y_hi))`` in metres.

        The strips the ideal lanes' cleaning unit covers: ``x`` from 0 to
        ``lane_length``, ``y`` from half a unit outside the first lane to half
        a unit outside the last one.
        """
        half = 0.5 * self.unit_width
        far = self.side * (self.n_lanes - 1) * self.spacing
        y_lo, y_hi = min(0.0, far) - half, max(0.0, far) + half
        return (0.0, y_lo), (self.lane_length, y_hi)


class Controller:
    """Base class of every ``bionav.controllers`` plugin.

    A plugin subclasses this, sets ``Config`` to a dataclass of its
    parameters (defaults = the thesis' values) and implements :meth:`reset`
    and :meth:`step`.

    Class attributes
    ----------------
    Config : type
        Dataclass of the controller's parameters.
    uses_camera : bool
        True when the controller grabs images (needs a homing method).
    confined : bool
        True when the controller expects to be kept inside the target area by
        virtual walls (random bounce); the simulator then adds them.
    """

    Config: ClassVar[type]
    uses_camera: ClassVar[bool] = False
    confined: ClassVar[bool] = False

    def __init__(self, config: Any, *, track_width: float = 0.30) -> None:
        """A controller with its ``config`` for a robot whose wheels are ``track_width`` metres apart.

        The track width is the robot's, not the controller's: one setting
        (``experiment.track_width``) drives the simulated wheels
        (:class:`~bionav.robot.kinematics.DriveModel`) and the controller's
        conversion of ``(v, omega)`` into wheel speeds.
        """
        self.config = config
        self.track_width = track_width

    def reset(self, plan: LanePlan, *, homing: Any = None, rng: np.random.Generator | None = None) -> None:
        """Start a new run.

        Parameters
        ----------
        plan : LanePlan
            The task.
        homing : HomingMethod, optional
            Visual homing method (``uses_camera`` controllers).
        rng : numpy.random.Generator, optional
            The controller's only source of randomness.
        """
        raise NotImplementedError

    def step(self, obs: Observation) -> Command:
        """One control tick: observation in, wheel commands out."""
        raise NotImplementedError
