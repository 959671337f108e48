"""``controller=random``: random bounce, the strategy of most consumer cleaning robots (thesis ch. 7).

The robot drives straight until its bumper fires, backs off a little, turns
on the spot by a random angle and drives straight again. It is kept inside
the target area by virtual walls (like the magnetic strips of consumer
robots; the simulator adds them because ``confined = True``) and stops after
driving ``path_factor`` times the length of the ideal meander, so that its
cleaning time matches a meander's.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.geometry import wrap_angle
from bionav.robot.controller import Command, Controller, LanePlan, Observation
from bionav.robot.kinematics import Pose, wheel_speeds
from bionav.validation import bounded


@dataclass
class RandomConfig:
    """Parameters of the random-bounce controller (SI units, degrees in ``_deg`` fields).

    Attributes
    ----------
    speed : float
        Forward speed, m/s.
    turn_rate : float
        Turn rate on the spot, rad/s.
    backoff : float
        Distance backed off after a bump, m.
    min_turn_deg, max_turn_deg : float
        The turn after a bump is uniform in this range, random sign.
    path_factor : float
        Stop after driving this multiple of the ideal meander's path length.
    """

    speed: float = bounded(0.10, gt=0.0, le=5.0)
    turn_rate: float = bounded(0.5, gt=0.0, le=20.0)
    backoff: float = bounded(0.03, ge=0.0, le=10.0)
    min_turn_deg: float = bounded(45.0, ge=0.0, le=360.0)
    max_turn_deg: float = bounded(180.0, ge=0.0, le=360.0)
    path_factor: float = bounded(1.0, gt=0.0, le=1000.0)


class RandomController(Controller):
    """Random-bounce controller."""

    Config = RandomConfig
    confined = True

    def reset(self, plan: LanePlan, *, homing=None, rng=None) -> None:
        self.plan = plan
        self.rng = rng if rng is not None else np.random.default_rng(0)
        self.phase = "forward"
        self.distance = 0.0
        self._prev: Pose | None = None
        self._target = 0.0
        self._backed = 0.0

    def step(self, obs: Observation) -> Command:
        c = self.config
        if self._prev is None:
            self._prev = obs.odometry
        delta = obs.odometry.relative_to(self._prev)
        self._prev = obs.odometry
        moved = float(np.hypot(delta.x, delta.y))
        self.distance += moved
        if self.distance >= c.path_factor * self.plan.ideal_path_length:
            return Command(0.0, 0.0, True)
        info: dict = {}
        if self.phase == "forward" and obs.bumper:
            self.phase = "back"
            self._backed = 0.0
            info["bump"] = True
        elif self.phase == "back":
            self._backed += moved
            if self._backed >= c.backoff or obs.bumper:
                turn = np.radians(self.rng.uniform(c.min_turn_deg, c.max_turn_deg)) * self.rng.choice([-1.0, 1.0])
                self._target = float(wrap_angle(obs.odometry.theta + turn))
                self.phase = "turn"
                info["turn"] = float(turn)
        if self.phase == "turn":
            err = float(wrap_angle(self._target - obs.odometry.theta))
            if abs(err) > np.radians(0.5):
                omega = float(np.clip(2.0 * err, -c.turn_rate, c.turn_rate))
                return Command(*wheel_speeds(0.0, omega, track_width=self.track_width), False, info)
            self.phase = "forward"
        if self.phase == "back":
            return Command(-c.speed, -c.speed, False, info)
        return Command(c.speed, c.speed, False, info)
