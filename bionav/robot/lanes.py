"""Lane geometry of the meander: the ideal trajectory and frame changes.

Layouts of the thesis (section 7.2, fig. 7.2): ``long_lanes`` = 7 lanes of
4 m, ``short_lanes`` = 14 lanes of 2 m, both 0.30 m apart; the first lane is
driven by wall following. A :class:`~bionav.robot.controller.LanePlan`
describes a layout in its own *plan frame* (origin at the start of the first
lane, ``+x`` along it); a start pose places the plan frame in the world.
"""

from __future__ import annotations

import numpy as np

from bionav.robot.controller import LanePlan
from bionav.robot.kinematics import Pose


def ideal_meander(plan: LanePlan, *, step: float = 0.01) -> np.ndarray:
    """The perfect meander in the plan frame.

    Lanes along ``+-x`` from ``x = 0`` to ``x = lane_length`` at
    ``y = side * k * spacing``; at each lane end a 90-degree turn on the spot,
    a straight shift by ``spacing`` and another 90-degree turn.

    Parameters
    ----------
    plan : LanePlan
        The layout.
    step : float
        Sampling step along straight segments (m); turns are sampled every
        ``step / (unit_width / 2)`` radians.

    Returns
    -------
    ndarray, shape (N, 3)
        Poses ``(x, y, theta)`` in metres and radians.
    """
    out = []
    side = plan.side
    n_lane = max(2, int(np.ceil(plan.lane_length / step)) + 1)
    n_shift = max(2, int(np.ceil(plan.spacing / step)) + 1)
    n_turn = max(2, int(np.ceil((np.pi / 2) / (step / (0.5 * plan.unit_width)))) + 1)
    for k in range(plan.n_lanes):
        y = side * k * plan.spacing
        forward = k % 2 == 0
        xs = np.linspace(0.0, plan.lane_length, n_lane)
        th = 0.0 if forward else np.pi
        if not forward:
            xs = xs[::-1]
        out.append(np.stack([xs, np.full_like(xs, y), np.full_like(xs, th)], axis=1))
        if k == plan.n_lanes - 1:
            break
        x_end = xs[-1]
        # turn towards the next lane: +90 deg (CCW) if the next lane is on the robot's left
        lane_side = side * (1 if forward else -1)
        turn = lane_side * np.pi / 2
        a = th + np.linspace(0.0, turn, n_turn)
        out.append(np.stack([np.full_like(a, x_end), np.full_like(a, y), a], axis=1))
        ys = y + side * np.linspace(0.0, plan.spacing, n_shift)
        out.append(np.stack([np.full_like(ys, x_end), ys, np.full_like(ys, th + turn)], axis=1))
        a = th + turn + np.linspace(0.0, turn, n_turn)
        out.append(np.stack([np.full_like(a, x_end), np.full_like(a, ys[-1]), a], axis=1))
    poses = np.concatenate(out)
    poses[:, 2] = (poses[:, 2] + np.pi) % (2 * np.pi) - np.pi
    return poses


def to_plan_frame(poses: np.ndarray, start: Pose) -> np.ndarray:
    """World poses ``(N, 3)`` expressed in the plan frame whose origin is ``start``."""
    p = np.asarray(poses, dtype=np.float64)
    c, s = np.cos(start.theta), np.sin(start.theta)
    dx, dy = p[:, 0] - start.x, p[:, 1] - start.y
    th = (p[:, 2] - start.theta + np.pi) % (2 * np.pi) - np.pi
    return np.stack([c * dx + s * dy, -s * dx + c * dy, th], axis=1)


def to_world_frame(poses: np.ndarray, start: Pose) -> np.ndarray:
    """Plan-frame poses ``(N, 3)`` expressed in the world (inverse of :func:`to_plan_frame`)."""
    p = np.asarray(poses, dtype=np.float64)
    c, s = np.cos(start.theta), np.sin(start.theta)
    th = (p[:, 2] + start.theta + np.pi) % (2 * np.pi) - np.pi
    return np.stack([start.x + c * p[:, 0] - s * p[:, 1], start.y + s * p[:, 0] + c * p[:, 1], th], axis=1)
