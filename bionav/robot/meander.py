"""The meander: lanes, lane changes, wall following and lane keeping.

Shared machinery of the ``triangulation`` and ``odometry`` controllers
(thesis section 7.1): the first lane is driven by wall following, at its end
the robot turns by 90 degrees on the spot, drives forward by the inter-lane
distance, turns by another 90 degrees and drives the next lane antiparallel to
the previous one, and so on.

State estimate. The controller keeps its pose in the *lane frame* ``R_k`` of
the current lane ``k``: origin at the lane's start on its desired line, ``+x``
along the direction of travel, ``+y`` to the left. The estimate is propagated
every tick by the odometry increment (which is wrong by the unknown wheel
error) and corrected by *fixes*: on the first lane by the wall sensor (every
tick), on later lanes by whatever the subclass measures (visual triangulation
against the previous lane for ``triangulation``, nothing for ``odometry``).
A fix replaces ``y`` and the heading by ``y + g (y_meas - y)`` (gain ``g``).

Wheel bias. A static wheel-speed error makes the robot turn by ``kappa``
radians per metre driven that the odometry does not see. With
``bias_learning`` the controller estimates ``kappa`` from its fixes: the
heading corrections it applied, summed over at least ``bias_window`` metres
and divided by the distance driven, are the drift its dead reckoning missed;
``kappa`` moves towards explaining them (gain ``bias_gain``), and the
odometry increments are corrected by ``kappa`` times the distance driven.

Lane keeping is pure pursuit of a point ``lookahead`` metres ahead on the
desired line: desired heading ``atan2(-y, lookahead)``, turn rate
``omega = heading_gain * wrap(desired - heading)`` (clipped).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.geometry import wrap_angle
from bionav.robot.controller import Command, Controller, LanePlan, Observation
from bionav.robot.kinematics import Pose, wheel_speeds
from bionav.validation import bounded


@dataclass
class MeanderConfig:
    """Parameters shared by the meander controllers (SI units, radians unless ``_deg``).

    Attributes
    ----------
    speed : float
        Forward speed on lanes, m/s.
    turn_rate : float
        Turn rate of the 90-degree turns on the spot, rad/s.
    lookahead : float
        Pure-pursuit look-ahead distance on the desired lane, m.
    heading_gain : float
        Turn rate per radian of heading error, 1/s.
    max_steer_rate : float
        Largest turn rate while driving a lane, rad/s.
    bias_learning : bool
        Estimate the heading drift per metre (wheel error) from the fixes.
    bias_gain : float
        Fraction of the observed drift added to the estimate per window.
    bias_window : float
        Distance (m) over which heading corrections are summed per update.
    wall_gate_deg : float
        Wall readings whose heading disagrees with the estimate by more than
        this are ignored (a corner, an open door).
    turn_tolerance_deg : float
        A turn on the spot ends when the heading is this close to its target.
    turn_reference : str
        Heading reference of the lane change. ``"local"``: the current heading
        estimate, i.e. relative to the previous lane's direction where the lane
        ends (a hooked lane end tilts the next lane, and the tilt grows from
        lane to lane). ``"lane_mean"``: relative to the lane's mean direction,
        the average over the lane of the direction its fixes implied (in the
        bias-corrected odometry frame).
    """

    speed: float = bounded(0.10, gt=0.0, le=5.0)
    turn_rate: float = bounded(0.5, gt=0.0, le=20.0)
    lookahead: float = bounded(0.60, gt=0.0, le=100.0)
    heading_gain: float = bounded(1.5, ge=0.0, le=100.0)
    max_steer_rate: float = bounded(0.5, gt=0.0, le=20.0)
    bias_learning: bool = False
    bias_gain: float = bounded(0.5, ge=0.0, le=1.0)
    bias_window: float = bounded(0.2, gt=0.0, le=100.0)
    wall_gate_deg: float = bounded(20.0, ge=0.0, le=180.0)
    turn_tolerance_deg: float = bounded(0.5, gt=0.0, le=45.0)
    turn_reference: str = bounded("lane_mean", choices=("local", "lane_mean"))


class MeanderController(Controller):
    """Base class of meander controllers; subclasses add lane fixes through :meth:`lane_fix`."""

    Config = MeanderConfig

    def reset(self, plan: LanePlan, *, homing=None, rng=None) -> None:
        self.plan = plan
        self.homing = homing
        self.rng = rng
        self.lane = 0
        self.phase = "lane"
        self.est = Pose(0.0, 0.0, 0.0)  # pose in the current lane frame
        self.origin_in_prev = Pose(0.0, 0.0, 0.0)  # R_k's origin in R_{k-1}
        self.kappa = 0.0  # learned heading drift, rad per metre driven
        self.odometry = Pose(0.0, 0.0, 0.0)  # odometry corrected by kappa (frame of the run's start)
        self._bias_turn = 0.0  # heading corrections applied in the current window (rad)
        self._bias_dist = 0.0  # distance driven in the current window (m)
        self._dir_sum = np.zeros(2)  # sum of (cos, sin) of the lane direction in the corrected odometry frame
        self._prev_odo: Pose | None = None
        self._lane_end_x = 0.0

    def lane_side(self, lane: int) -> int:
        """Side (+1 left, -1 right, in lane ``lane``'s frame) on which lane ``lane + 1`` lies.

        Turns alternate: a meander turns left, right, left, ... when
        ``plan.turn == "left"``.
        """
        return self.plan.side * (1 if lane % 2 == 0 else -1)

    # ------------------------------------------------------------------ hooks
    def lane_fix(self, obs: Observation, info: dict) -> tuple[float | None, float, float] | None:
        """Measure ``(x, y, heading)`` in the current lane frame on lanes after the first.

        Called every tick while driving a lane ``k >= 1``; return ``None`` when
        there is nothing new, ``x = None`` when only ``y`` and the heading were
        measured. Subclasses write their internals into ``info``.
        """
        return None

    def lane_tick(self, obs: Observation, info: dict) -> None:
        """Called every tick while driving any lane, before the fix (e.g. to grab an image)."""

    def post_fix(self, obs: Observation, info: dict) -> None:
        """Called every tick while driving any lane, after the fix (e.g. to store a snapshot)."""

    # ------------------------------------------------------------------ control
    def _apply_fix(self, y: float, heading: float, gain: float, x: float | None = None) -> None:
        turn = gain * float(wrap_angle(heading - self.est.theta))
        new_x = self.est.x if x is None else self.est.x + gain * (x - self.est.x)
        self.est = Pose(new_x, self.est.y + gain * (y - self.est.y), float(wrap_angle(self.est.theta + turn)))
        c = self.config
        if c.bias_learning:
            self._bias_turn += turn
            if self._bias_dist >= c.bias_window:
                self.kappa += c.bias_gain * self._bias_turn / self._bias_dist
                self._bias_turn = 0.0
                self._bias_dist = 0.0

    def _wall_fix(self, obs: Observation) -> None:
        if obs.wall is None:
            return
        heading = -obs.wall.angle
        if abs(wrap_angle(heading - self.est.theta)) > np.radians(self.config.wall_gate_deg):
            return
        # the wall is on the right at -wall_offset in R_0
        self._apply_fix(obs.wall.distance - self.plan.wall_offset, heading, 1.0)

    def _wheels(self, v: float, omega: float) -> tuple[float, float]:
        return wheel_speeds(v, omega, track_width=self.track_width)

    def _lane_command(self) -> tuple[float, float]:
        c = self.config
        desired = np.arctan2(-self.est.y, c.lookahead)
        err = float(wrap_angle(desired - self.est.theta))
        omega = float(np.clip(c.heading_gain * err, -c.max_steer_rate, c.max_steer_rate))
        v = c.speed * max(0.0, float(np.cos(err)))
        return self._wheels(v, omega)

    def _turn_command(self, target: float) -> tuple[float, float] | None:
        err = float(wrap_angle(target - self.est.theta))
        if abs(err) < np.radians(self.config.turn_tolerance_deg):
            return None
        omega = float(np.clip(2.0 * err, -self.config.turn_rate, self.config.turn_rate))
        return self._wheels(0.0, omega)

    def step(self, obs: Observation) -> Command:
        if self._prev_odo is None:
            self._prev_odo = obs.odometry
        delta = obs.odometry.relative_to(self._prev_odo)
        if self.kappa != 0.0:
            delta = Pose(delta.x, delta.y, delta.theta + self.kappa * delta.x)
        self.est = self.est.compose(delta)
        self.odometry = self.odometry.compose(delta)
        if self.phase == "lane":
            self._bias_dist += abs(delta.x)
        self._prev_odo = obs.odometry
        info: dict = {}
        side = self.lane_side(self.lane)

        if self.phase == "lane":
            self.lane_tick(obs, info)
            if self.lane == 0:
                self._wall_fix(obs)
            else:
                fix = self.lane_fix(obs, info)
                if fix is not None:
                    self._apply_fix(fix[1], fix[2], getattr(self.config, "fix_gain", 1.0), x=fix[0])
            self.post_fix(obs, info)
            d = float(self.odometry.theta - self.est.theta)
            self._dir_sum += (np.cos(d), np.sin(d))
            if self.est.x >= self.plan.lane_length or obs.bumper:
                info["lane_end"] = self.lane
                info["lane_end_bumper"] = bool(obs.bumper)
                if self.lane == self.plan.n_lanes - 1:
                    self.phase = "done"
                    return Command(0.0, 0.0, True, info)
                self._lane_end_x = self.est.x
                if self.config.turn_reference == "lane_mean" and self.lane > 0:
                    mean_dir = float(np.arctan2(self._dir_sum[1], self._dir_sum[0]))
                    heading = float(wrap_angle(self.odometry.theta - mean_dir))
                    info["lane_heading_correction"] = float(wrap_angle(heading - self.est.theta))
                    self.est = Pose(self.est.x, self.est.y, heading)
                self._dir_sum = np.zeros(2)
                self.phase = "turn1"
            else:
                return Command(*self._lane_command(), False, info)

        if self.phase == "turn1":
            cmd = self._turn_command(side * np.pi / 2)
            if cmd is not None:
                return Command(*cmd, False, info)
            self.phase = "shift"

        if self.phase == "shift":
            if side * self.est.y < self.plan.spacing and not obs.bumper:
                c = self.config
                err = float(wrap_angle(side * np.pi / 2 - self.est.theta))
                omega = float(np.clip(c.heading_gain * err, -c.max_steer_rate, c.max_steer_rate))
                return Command(*self._wheels(c.speed, omega), False, info)
            self.phase = "turn2"

        if self.phase == "turn2":
            cmd = self._turn_command(np.pi)
            if cmd is not None:
                return Command(*cmd, False, info)
            # enter lane k+1: its frame starts across from where lane k ended
            origin = Pose(self._lane_end_x, side * self.plan.spacing, np.pi)
            self.est = self.est.relative_to(origin)
            self.origin_in_prev = origin
            self.lane += 1
            self.phase = "lane"
            info["lane_start"] = self.lane
            return Command(*self._lane_command(), False, info)

        return Command(0.0, 0.0, True, info)
