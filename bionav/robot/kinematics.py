"""Differential-drive kinematics: exact pose integration for constant wheel speeds.

Frames and units: poses are ``(x, y, theta)`` in metres and radians, ``theta``
counter-clockwise from the world ``+x`` axis (see :mod:`bionav.geometry`).
Wheel speeds are linear speeds of the wheel contact points in m/s, positive
forwards; the wheels sit ``track_width`` metres apart, symmetric about the
robot's reference point.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.geometry import wrap_angle


@dataclass(frozen=True)
class Pose:
    """A planar pose.

    Attributes
    ----------
    x, y : float
        Position in metres.
    theta : float
        Heading in radians, counter-clockwise from ``+x``.
    """

    x: float
    y: float
    theta: float

    def as_tuple(self) -> tuple[float, float, float]:
        """``(x, y, theta)`` as plain floats."""
        return (float(self.x), float(self.y), float(self.theta))

    def relative_to(self, origin: "Pose") -> "Pose":
        """This pose expressed in the frame of ``origin`` (``origin^-1 * self``)."""
        c, s = np.cos(origin.theta), np.sin(origin.theta)
        dx, dy = self.x - origin.x, self.y - origin.y
        return Pose(float(c * dx + s * dy), float(-s * dx + c * dy), float(wrap_angle(self.theta - origin.theta)))

    def compose(self, delta: "Pose") -> "Pose":
        """Apply ``delta`` (given in this pose's frame): ``self * delta``."""
        c, s = np.cos(self.theta), np.sin(self.theta)
        return Pose(
            float(self.x + c * delta.x - s * delta.y),
            float(self.y + s * delta.x + c * delta.y),
            float(wrap_angle(self.theta + delta.theta)),
        )


def body_velocity(v_left: float, v_right: float, *, track_width: float) -> tuple[float, float]:
    """Forward speed and turn rate of a differential drive.

    Parameters
    ----------
    v_left, v_right : float
        Wheel speeds in m/s.
    track_width : float
        Distance between the wheels in metres.

    Returns
    -------
    v : float
        Forward speed of the midpoint between the wheels, m/s.
    omega : float
        Turn rate in rad/s, counter-clockwise positive.
    """
    return 0.5 * (v_left + v_right), (v_right - v_left) / track_width


def wheel_speeds(v: float, omega: float, *, track_width: float) -> tuple[float, float]:
    """Inverse of :func:`body_velocity`: wheel speeds ``(v_left, v_right)`` in m/s."""
    half = 0.5 * omega * track_width
    return v - half, v + half


def integrate_pose(pose: Pose, v_left: float, v_right: float, dt: float, *, track_width: float) -> Pose:
    """Exact pose after driving with constant wheel speeds for ``dt`` seconds.

    With constant wheel speeds the midpoint moves on a circular arc of radius
    ``R = v / omega`` (a straight line when ``omega == 0``)::

        x' = x + R (sin(theta + omega dt) - sin(theta))
        y' = y - R (cos(theta + omega dt) - cos(theta))

    evaluated in the numerically stable form ``chord = 2 v sin(omega dt / 2) / omega``
    along the mean heading ``theta + omega dt / 2``.

    Parameters
    ----------
    pose : Pose
        Start pose.
    v_left, v_right : float
        Wheel speeds in m/s.
    dt : float
        Duration in seconds.
    track_width : float
        Wheel distance in metres.

    Returns
    -------
    Pose
        The pose at the end of the arc, heading wrapped to ``[-pi, pi)``.
    """
    v, omega = body_velocity(v_left, v_right, track_width=track_width)
    dtheta = omega * dt
    half = 0.5 * dtheta
    if abs(half) < 1e-9:
        chord = v * dt
    else:
        chord = v * dt * np.sin(half) / half
    mid = pose.theta + half
    return Pose(
        float(pose.x + chord * np.cos(mid)),
        float(pose.y + chord * np.sin(mid)),
        float(wrap_angle(pose.theta + dtheta)),
    )


@dataclass(frozen=True)
class DriveModel:
    """The physical drive of the simulated robot and what its odometry believes.

    Parameters
    ----------
    track_width : float
        Wheel distance in metres.
    wheel_error : (float, float)
        Static relative wheel-speed errors ``(e_left, e_right)``: the wheels
        really turn at ``v * (1 + e)``. The odometry does not know them; it
        integrates the commanded speeds (a robot whose wheel diameters differ
        from their nominal values).
    max_wheel_speed : float
        Commands are clipped to ``[-max, max]`` m/s.
    """

    track_width: float = 0.30
    wheel_error: tuple[float, float] = (0.05, -0.05)
    max_wheel_speed: float = 0.3

    def clip(self, v_left: float, v_right: float) -> tuple[float, float]:
        """Commands clipped to the motors' range (m/s)."""
        m = self.max_wheel_speed
        return float(np.clip(v_left, -m, m)), float(np.clip(v_right, -m, m))

    def true_speeds(self, v_left: float, v_right: float) -> tuple[float, float]:
        """Actual wheel speeds for commanded (clipped) speeds, m/s."""
        return v_left * (1.0 + self.wheel_error[0]), v_right * (1.0 + self.wheel_error[1])
