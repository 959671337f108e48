"""``controller=triangulation``: lane keeping by visual triangulation against the previous lane.

Gerstmayr, Möller et al. (2009), "A vision-based trajectory controller for
autonomous cleaning robots", Autonome Mobile Systeme 2009,
doi:10.1007/978-3-642-10284-4_9; thesis chapter 7, fig. 7.1.

The robot grabs a panoramic snapshot every ``snapshot_interval`` metres and
adds it to a topological map (a chain of nodes per lane, each with its
odometry pose and along-lane position). On every lane after the first it
computes, at each snapshot, the home-vector angles ``alpha1``, ``alpha2`` to
two snapshots of the previous lane with the injected homing method (thesis:
min-warping with compass), triangulates its distance ``h`` to the previous
lane (:func:`bionav.robot.triangulation.triangulate`, baseline ``d`` from the
odometry poses of the two snapshots), and corrects its lateral offset
``e = h - spacing`` and heading estimate; pure pursuit then steers it back
onto the lane at ``spacing`` metres from the previous one.

Heading relative to the previous lane. The bearings must be turned from the
robot's frame into the baseline frame. With ``orientation="compass"`` the
homing method's compass ``psi_i`` (rotation of the current view relative to
snapshot ``i``) gives the robot's heading relative to each snapshot; the
snapshot's heading relative to the baseline comes from the odometry *local*
to the two snapshots (their odometric headings minus the chord direction,
averaged over both snapshots, which is exact for a circular arc of any
curvature and so insensitive to the wheel error). With
``orientation="odometry"`` the heading difference of the odometry is used
instead (drifts with the wheel error; for homing methods without compass).

Choosing the snapshot pair (conditioning). Candidates are the previous lane's
snapshots within ``max_snapshot_distance`` (along the lane) of the robot. For
every candidate pair the controller predicts the bearings from its current
estimate and computes the first-order standard deviation of ``h``
(:func:`bionav.robot.triangulation.lateral_error_std`, bearing noise
``bearing_std_deg``, common heading noise ``compass_std_deg``); pairs whose
predicted intersection angle is below ``min_intersection_deg`` are excluded,
and the pair with the smallest predicted std wins (for a straight lane this
is the pair seen under about 90 degrees, at about ``+-h`` along the lane).
After measuring, a fix is rejected when the *measured* bearings intersect
under less than ``min_intersection_deg`` (or more than 180 degrees minus it),
when a snapshot lies behind its bearing (inconsistent triangle), when a home
vector is invalid, or when ``h`` differs from its prediction by more than
``max_innovation`` metres.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from bionav.errors import UserError
from bionav.geometry import wrap_angle
from bionav.robot.controller import Observation
from bionav.robot.kinematics import Pose
from bionav.robot.meander import MeanderConfig, MeanderController
from bionav.validation import bounded


@dataclass
class TriangulationConfig(MeanderConfig):
    """Parameters of the triangulation controller (adds to :class:`MeanderConfig`).

    Attributes
    ----------
    snapshot_interval : float
        Distance between snapshots along a lane, m (thesis: 0.10).
    max_snapshot_distance : float
        Only snapshots of the previous lane within this along-lane distance are
        candidates, m.
    min_intersection_deg : float
        Pairs whose bearings intersect under a smaller angle (or one closer
        than this to 180 degrees) are rejected.
    bearing_std_deg : float
        Assumed std of a home-vector angle, for ranking pairs.
    compass_std_deg : float
        Assumed std of the heading estimate, for ranking pairs.
    orientation : str
        ``"compass"`` (the homing method's psi) or ``"odometry"``.
    fix_gain : float
        Weight of a fix (1 replaces the estimate, smaller values smooth).
    max_innovation : float
        Fixes whose ``h`` differs from the prediction by more are rejected, m.
    max_rejections : int
        When this many consecutive fixes were rejected for their innovation
        but agree with each other (their ``h`` within ``max_innovation``), the
        estimate rather than the measurements is wrong: the latest is accepted.
    """

    bias_learning: bool = True
    snapshot_interval: float = bounded(0.10, gt=0.0, le=100.0)
    max_snapshot_distance: float = bounded(1.0, gt=0.0, le=1000.0)
    min_intersection_deg: float = bounded(30.0, ge=0.0, lt=90.0)
    bearing_std_deg: float = bounded(5.0, gt=0.0, le=180.0)
    compass_std_deg: float = bounded(3.0, gt=0.0, le=180.0)
    orientation: str = bounded("compass", choices=("compass", "odometry"))
    fix_gain: float = bounded(0.5, gt=0.0, le=1.0)
    max_innovation: float = bounded(0.15, gt=0.0, le=100.0)
    max_rejections: int = bounded(3, ge=0, le=1000)


@dataclass
class MapNode:
    """A snapshot in the topological map.

    Attributes
    ----------
    id : int
        Running index.
    lane : int
        Lane on which it was taken.
    x, y : float
        Estimated position in its lane's frame (m).
    odometry : Pose
        Odometry pose at capture, corrected by the learned wheel bias
        (:attr:`MeanderController.kappa`).
    prepared : object
        The homing method's prepared image.
    """

    id: int
    lane: int
    x: float
    y: float
    odometry: Pose
    prepared: Any


class TriangulationController(MeanderController):
    """Meander whose lanes keep ``spacing`` from the previous lane by visual triangulation."""

    Config = TriangulationConfig
    uses_camera = True

    def reset(self, plan, *, homing=None, rng=None) -> None:
        if homing is None:
            raise UserError("controller=triangulation needs a homing method (homing=minwarping or another "
                            "homing plugin); none was given.")
        super().reset(plan, homing=homing, rng=rng)
        self.nodes: list[MapNode] = []
        self._lane_nodes: dict[int, list[MapNode]] = {}
        self._next_capture = 0.0
        self._capture_lane = 0
        self._current = None
        self._rejected_h: list[float] = []

    # ------------------------------------------------------------------ hooks
    def lane_tick(self, obs: Observation, info: dict) -> None:
        self._current = None
        if self._capture_lane != self.lane:
            self._capture_lane = self.lane
            self._next_capture = 0.0
        if self.est.x + 1e-9 < self._next_capture or obs.camera is None:
            return
        interval = self.config.snapshot_interval
        self._next_capture = (np.floor(self.est.x / interval + 1e-9) + 1.0) * interval
        self._current = self.homing.prepare(obs.camera())

    def lane_fix(self, obs: Observation, info: dict):
        if self._current is None:
            return None
        prev = self._lane_nodes.get(self.lane - 1, [])
        choice = self.choose_pair(prev)
        if choice is None:
            info["fix"] = {"accepted": False, "reason": "no well-conditioned pair"}
            return None
        n1, n2, sigma = choice
        result = self.measure(n1, n2, self.odometry)
        result["predicted_std"] = float(sigma)
        info["fix"] = result
        if not result["accepted"]:
            return None
        side_prev = self.lane_side(self.lane - 1)
        return None, side_prev * self.plan.spacing - result["h"], float(wrap_angle(result["heading"] - np.pi))

    def post_fix(self, obs: Observation, info: dict) -> None:
        if self._current is None:
            return
        node = MapNode(len(self.nodes), self.lane, self.est.x, self.est.y, self.odometry, self._current)
        self.nodes.append(node)
        self._lane_nodes.setdefault(self.lane, []).append(node)
        info["snapshot"] = {"id": node.id, "lane": node.lane, "x": node.x, "y": node.y}
        self._current = None

    # ------------------------------------------------------------------ triangulation
    def robot_in_previous_lane(self) -> Pose:
        """The current pose estimate in the previous lane's frame."""
        return self.origin_in_prev.compose(self.est)

    def choose_pair(self, prev: list[MapNode]):
        """Best-conditioned pair of previous-lane snapshots, ``(node1, node2, predicted_std)`` or None.

        ``node1`` precedes ``node2`` along the previous lane. See the module
        docstring for the criterion.
        """
        from bionav.robot.triangulation import intersection_angle, lateral_error_std

        c = self.config
        if len(prev) < 2:
            return None
        r = self.robot_in_previous_lane()
        xs = np.array([n.x for n in prev])
        ys = np.array([n.y for n in prev])
        cand = np.flatnonzero(np.abs(xs - r.x) <= c.max_snapshot_distance)
        if len(cand) < 2:
            return None
        i, j = np.triu_indices(len(cand), k=1)
        i, j = cand[i], cand[j]
        base = np.arctan2(ys[j] - ys[i], xs[j] - xs[i])
        d = np.hypot(xs[j] - xs[i], ys[j] - ys[i])
        b1 = np.arctan2(ys[i] - r.y, xs[i] - r.x) - base
        b2 = np.arctan2(ys[j] - r.y, xs[j] - r.x) - base
        gamma = intersection_angle(b1, b2)
        gmin = np.radians(c.min_intersection_deg)
        sigma = np.asarray(lateral_error_std(d, b1, b2, bearing_std=np.radians(c.bearing_std_deg),
                                             common_std=np.radians(c.compass_std_deg)), dtype=float)
        ok = (gamma >= gmin) & (gamma <= np.pi - gmin) & (d > 1e-6)
        if not np.any(ok):
            return None
        sigma = np.where(ok, sigma, np.inf)
        k = int(np.argmin(sigma))
        return prev[i[k]], prev[j[k]], float(sigma[k])

    def measure(self, n1: MapNode, n2: MapNode, odometry: Pose) -> dict:
        """Triangulate the distance to the previous lane from snapshots ``n1``, ``n2``.

        Returns a JSON-serialisable dict with ``accepted``, ``reason``, the
        snapshot ids, home-vector angles ``alpha1``, ``alpha2`` (robot frame,
        rad), compass angles, baseline ``d`` (m), ``heading`` (robot heading in
        the baseline frame, rad), ``h`` (m), ``e = h - desired`` (m) and the
        intersection angle ``gamma`` (rad).
        """
        from bionav.robot.triangulation import triangulate

        c = self.config
        hv1 = self.homing.home_vector(n1.prepared, self._current)
        hv2 = self.homing.home_vector(n2.prepared, self._current)
        out: dict = {"snapshots": [n1.id, n2.id], "alpha1": _num(hv1.angle), "alpha2": _num(hv2.angle),
                     "psi1": _num(hv1.compass), "psi2": _num(hv2.compass)}
        if not (hv1.valid and hv2.valid):
            out.update(accepted=False, reason="invalid home vector")
            return out
        o1, o2 = n1.odometry, n2.odometry
        chord = np.arctan2(o2.y - o1.y, o2.x - o1.x)
        d = float(np.hypot(o2.x - o1.x, o2.y - o1.y))
        if c.orientation == "compass" and hv1.compass is not None and hv2.compass is not None:
            h1 = o1.theta + hv1.compass
            h2 = o2.theta + hv2.compass
            heading = _circmean(h1, h2) - chord
        else:
            heading = odometry.theta - chord
        heading = float(wrap_angle(heading))
        tri = triangulate(d, hv1.angle + heading, hv2.angle + heading)
        desired = self.lane_side(self.lane - 1) * self.plan.spacing
        out.update(d=d, heading=heading, h=_num(tri.y), e=_num(tri.y - desired), gamma=_num(tri.gamma),
                   x=_num(tri.x))
        # prediction from the current estimate: signed distance to the line n1 -> n2
        r = self.robot_in_previous_lane()
        bx, by = n2.x - n1.x, n2.y - n1.y
        h_pred = float((bx * (r.y - n1.y) - by * (r.x - n1.x)) / np.hypot(bx, by))
        out["h_predicted"] = h_pred
        gmin = np.radians(c.min_intersection_deg)
        if not np.isfinite(tri.y) or tri.gamma < gmin or tri.gamma > np.pi - gmin:
            out.update(accepted=False, reason="ill-conditioned bearings")
        elif not tri.consistent:
            out.update(accepted=False, reason="inconsistent triangle")
        elif abs(tri.y - h_pred) > c.max_innovation and not self._consistent_rejections(tri.y):
            out.update(accepted=False, reason="innovation too large")
        else:
            self._rejected_h = []
            out.update(accepted=True, reason="")
        return out

    def _consistent_rejections(self, h: float) -> bool:
        """Record an innovation rejection; True when the last ``max_rejections`` ones agree."""
        c = self.config
        self._rejected_h = (self._rejected_h + [float(h)])[-c.max_rejections:]
        recent = self._rejected_h
        return len(recent) >= c.max_rejections and max(recent) - min(recent) <= c.max_innovation


def _circmean(a: float, b: float) -> float:
    return float(np.arctan2(np.sin(a) + np.sin(b), np.cos(a) + np.cos(b)))


def _num(v) -> float | None:
    if v is None:
        return None
    v = float(v)
    return v if np.isfinite(v) else None
