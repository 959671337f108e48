"""Distance to the previous lane by triangulation from two home-vector bearings.

Gerstmayr, Möller et al. (2009), "A vision-based trajectory controller for
autonomous cleaning robots", Autonome Mobile Systeme 2009,
doi:10.1007/978-3-642-10284-4_9; thesis section 7.1, fig. 7.1.

Frame (the *baseline frame*): snapshot ``SS1`` at the origin, snapshot ``SS2``
at ``(d, 0)``, so ``+x`` runs along the previous lane from ``SS1`` to ``SS2``
and ``+y`` is to its left. The current view ``CV`` sees ``SS1`` under the
bearing ``beta1`` and ``SS2`` under ``beta2`` (radians, CCW from ``+x``: the
home-vector angles turned from the robot's frame into the baseline frame).
From ``SS_i = CV + t_i (cos beta_i, sin beta_i)`` with ``t_i > 0``::

    t1 = -d sin(beta2) / sin(beta2 - beta1)
    t2 = -d sin(beta1) / sin(beta2 - beta1)
    x  = d sin(beta2) cos(beta1) / sin(beta2 - beta1)
    y  = d sin(beta1) sin(beta2) / sin(beta2 - beta1)

``y`` is the signed perpendicular distance ``h`` of the current view from the
line through the snapshots (positive left of ``SS1 -> SS2``).

Conditioning. The two bearings intersect at ``CV`` under the angle
``gamma = |wrap(beta2 - beta1)|``; small ``gamma`` (both snapshots nearly in
one direction) or ``gamma`` near ``pi`` (the robot on the line between them)
makes ``h`` ill-conditioned. First-order error propagation gives::

    dh/dbeta1 =  d sin(beta2)^2 / sin(beta2 - beta1)^2
    dh/dbeta2 = -d sin(beta1)^2 / sin(beta2 - beta1)^2

so independent bearing errors of std ``sigma_a`` and a common heading error of
std ``sigma_c`` (from the compass, added to both bearings) give::

    sigma_h^2 = d^2 (sigma_a^2 (s1^4 + s2^4) + sigma_c^2 (s2^2 - s1^2)^2) / sin(beta2 - beta1)^4

For a pair placed symmetrically at ``+-a`` along the lane at distance ``h``
this is minimal at ``a = h`` (``gamma = 90 deg``), where
``sigma_h = sqrt(2) h sigma_a``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.geometry import wrap_angle


@dataclass(frozen=True)
class Triangulation:
    """Position of the current view in the baseline frame.

    Attributes
    ----------
    x, y : float
        Position in metres (``y`` is the signed distance ``h`` to the lane).
    gamma : float
        Intersection angle of the two bearings, radians in ``[0, pi]``.
    t1, t2 : float
        Distances from the current view to ``SS1`` and ``SS2`` in metres
        (negative when a bearing points away from its snapshot: inconsistent).
    """

    x: float
    y: float
    gamma: float
    t1: float
    t2: float

    @property
    def consistent(self) -> bool:
        """Both snapshots lie ahead along their bearings (``t1, t2 > 0``)."""
        return bool(self.t1 > 0 and self.t2 > 0)


def intersection_angle(beta1, beta2):
    """Angle between two bearings, radians in ``[0, pi]``."""
    return np.abs(wrap_angle(np.asarray(beta2) - np.asarray(beta1)))


def triangulate(d: float, beta1: float, beta2: float) -> Triangulation:
    """Triangulate the current view from the bearings to two snapshots.

    Parameters
    ----------
    d : float
        Distance from ``SS1`` to ``SS2`` in metres (odometry), ``> 0``.
    beta1, beta2 : float
        Bearings from the current view to ``SS1`` and ``SS2`` in the baseline
        frame (radians, CCW from the direction ``SS1 -> SS2``).

    Returns
    -------
    Triangulation
        ``x``, ``y`` are NaN when the bearings are parallel.
    """
    den = np.sin(beta2 - beta1)
    gamma = float(intersection_angle(beta1, beta2))
    if abs(den) < 1e-12:
        nan = float("nan")
        return Triangulation(nan, nan, gamma, nan, nan)
    s1, s2 = np.sin(beta1), np.sin(beta2)
    return Triangulation(
        x=float(d * s2 * np.cos(beta1) / den),
        y=float(d * s1 * s2 / den),
        gamma=gamma,
        t1=float(-d * s2 / den),
        t2=float(-d * s1 / den),
    )


def lateral_error_std(d, beta1, beta2, *, bearing_std: float, common_std: float = 0.0):
    """First-order standard deviation of ``h`` (metres) for given bearing noise.

    Parameters
    ----------
    d : float or ndarray
        Snapshot distance in metres.
    beta1, beta2 : float or ndarray
        Bearings in the baseline frame (radians).
    bearing_std : float
        Std of each home-vector angle, independent per snapshot (radians).
    common_std : float
        Std of an error shared by both bearings (the heading estimate; radians).

    Returns
    -------
    float or ndarray
        ``sigma_h`` in metres (``inf`` for parallel bearings).
    """
    s1 = np.sin(beta1) ** 2
    s2 = np.sin(beta2) ** 2
    den = np.sin(np.asarray(beta2) - np.asarray(beta1)) ** 2
    num = np.asarray(d) * np.sqrt(bearing_std ** 2 * (s1 ** 2 + s2 ** 2) + common_std ** 2 * (s2 - s1) ** 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.where(den > 1e-24, num / np.where(den > 1e-24, den, 1.0), np.inf)
    return out if out.ndim else float(out)
