"""Route followers: the heading choosers that :func:`bionav.evaluation.route.follow_route` walks.

Two kinds follow a trained route in the test of Ardin, Peng, Mangan,
Lagogiannis & Webb 2016 (PLoS Comput. Biol. 12(2), e1004683,
doi:10.1371/journal.pcbi.1004683):

* :class:`FamiliarityFollower`: a scene-familiarity agent (perfect memory,
  infomax, the mushroom body; :mod:`bionav.homing.familiarity`) rates the
  views of a scan around the current heading and walks along the least
  unfamiliar one (:func:`bionav.evaluation.route.least_unfamiliar`);
* :class:`HomingFollower`: a local homing method (``bionav.homing``) tracks
  its progress along the route by windowed RIDF (:func:`windowed_match`) and
  homes to the stored view ``lookahead`` views ahead (:func:`home_direction`).

Both are plain callables ``(xy (2,), heading) -> heading`` with a
``reset(index)`` for the put-back rule, so they run on any view source: the
Seville mesh, or an analytic test world. Conventions: positions in metres,
world frame; headings radians CCW from world ``+x``; canonical panoramas
(:mod:`bionav.geometry`), column 0 along the heading they were rendered at.
"""

from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np

from bionav.evaluation.route import best_match, least_unfamiliar
from bionav.geometry import wrap_angle

#: ``views(xy, heading) -> (views (S, h, w), offsets (S,))``: the preprocessed views of a scan, offsets in radians
ScanViews = Callable[[np.ndarray, float], tuple[np.ndarray, np.ndarray]]
#: ``render(xy, heading) -> panorama (H, W)``: the canonical panorama at a pose
Render = Callable[[np.ndarray, float], np.ndarray]


class FamiliarityFollower:
    """Heading chooser of a familiarity agent: scan, rate every view, walk along the least unfamiliar.

    Parameters
    ----------
    agent : route agent
        ``unfamiliarity(views (S, h, w)) -> (S,)`` (lower = more familiar), ``choose(s)``
        (the agent walked along candidate ``s``), ``reset(index)`` (put back at route view
        ``index``); the ``bionav.route_agents`` plugins.
    views : callable ``(xy, heading) -> (views (S, h, w), offsets (S,))``
        The scan at a pose (:func:`bionav.evaluation.route.scan_views` cuts it from a panorama).
    offsets : ndarray, shape (S,), optional
        The scan's offsets in radians (:func:`bionav.evaluation.route.scan_offsets`), needed
        only for an agent with ``needs_views = False`` (``random_choice``): it gets ``S``
        empty views of shape ``(S, 0)`` and nothing is rendered.

    Calling it returns ``heading + offsets[s]`` for the least unfamiliar view ``s``
    (ties: the one nearest straight ahead), or NaN (keep the heading) when no view has a
    finite unfamiliarity.
    """

    def __init__(self, agent: Any, views: ScanViews, *, offsets: np.ndarray | None = None) -> None:
        self.agent = agent
        self.views = views
        self.blind = not getattr(agent, "needs_views", True)
        if self.blind and offsets is None:
            raise ValueError("an agent that needs no views needs the scan offsets")
        self.offsets = None if offsets is None else np.asarray(offsets, np.float64)

    def __call__(self, xy: np.ndarray, heading: float) -> float:
        if self.blind:
            off = self.offsets
            v = np.zeros((len(off), 0), np.float32)
        else:
            v, off = self.views(xy, heading)
        s = least_unfamiliar(self.agent.unfamiliarity(v), off)
        if s < 0:
            return float("nan")
        self.agent.choose(s)
        return heading + float(off[s])

    def reset(self, index: int) -> None:
        """The agent was put back at route view ``index``."""
        self.agent.reset(int(index))


def route_window(last: int, n_views: int, window: int, *, centred: bool = False) -> tuple[int, int]:
    """Route views ``lo:hi`` searched around the last best match ``last``.

    ``centred=False`` (walking): one view behind to ``window`` ahead; ``centred=True``
    (a test point at a known route view): ``window // 2`` either side. Clipped to ``0:n_views``.
    """
    if centred:
        return max(0, last - window // 2), min(n_views, last + window // 2 + 1)
    return max(0, last - 1), min(n_views, last + window + 1)


def windowed_match(view: np.ndarray, snapshots: np.ndarray, snapshot_headings: np.ndarray, *, last: int,
                   window: int, centred: bool = False) -> tuple[float, int]:
    """Perfect-memory heading and best route view among the views of :func:`route_window`.

    Parameters
    ----------
    view : ndarray, shape (H, W)
        The current panorama rendered at heading 0 (column 0 along world ``+x``).
    snapshots : ndarray, shape (K, H, W)
        The route views, each rendered at its ``snapshot_headings`` (radians CCW from ``+x``).
    last, window : int
        The last best match and the window (:func:`route_window`).

    Returns
    -------
    heading : float
        Radians CCW from ``+x`` (:func:`bionav.evaluation.route.best_match`).
    index : int
        The best-matching route view.
    """
    lo, hi = route_window(int(last), len(snapshots), int(window), centred=centred)
    h, k, _d = best_match(view, snapshots[lo:hi], snapshot_headings=np.asarray(snapshot_headings)[lo:hi])
    return h, lo + k


def home_direction(homing: Any, prepared_target: Any, target_heading: float, render: Render, xy: np.ndarray, *,
                   test_step_m: float) -> float:
    """World direction from ``xy`` to a stored view by a homing method, radians CCW from ``+x`` (NaN if none).

    The current view is rendered at the stored view's heading ``target_heading`` (a perfect
    compass); methods with test steps (``uses_test_steps``) also get the views ``test_step_m``
    ahead, behind, left and right in that frame.

    Parameters
    ----------
    homing : HomingMethod
        ``prepare(image)``, ``home_vector(snapshot, current, neighbours=...)`` (angle in the
        current view's frame).
    prepared_target : any
        ``homing.prepare`` of the stored view.
    """
    cur = render(xy, target_heading)
    neighbours = None
    if getattr(homing, "uses_test_steps", False):
        neighbours = {}
        c, s = math.cos(target_heading), math.sin(target_heading)
        for d in ((1, 0), (-1, 0), (0, 1), (0, -1)):
            p = (xy[0] + test_step_m * (c * d[0] - s * d[1]), xy[1] + test_step_m * (s * d[0] + c * d[1]))
            neighbours[d] = homing.prepare(render(p, target_heading))
    hv = homing.home_vector(prepared_target, homing.prepare(cur), neighbours=neighbours)
    return float(wrap_angle(hv.angle + target_heading)) if hv.valid else float("nan")


class HomingFollower:
    """Heading chooser of a homing method following a route by homing to the view ahead.

    Each call:

    1. **progress**: the best route view ``k`` by windowed RIDF (:func:`windowed_match`, from the
       last match);
    2. **target**: the view ``j = k + lookahead`` and the home direction to it (:func:`home_direction`);
    3. **a passed view** (``passed="skip"``): a home direction more than 90 degrees from the
       route direction at ``j`` means the agent is already past ``j`` (homing to it would turn
       it round); it homes to ``j + 1`` instead, and so on, at most ``max_skip`` views further
       (``passed="keep"`` homes to ``j`` whatever the direction);
    4. **route direction** (``route_weight = w``): the heading is the direction of
       ``(1 - w) * u_home + w * u_route``, unit vectors along the home direction and the route
       direction stored with the target view (the compass heading of travel when it was stored);
       ``w = 0`` homes, ``w = 1`` ignores the home vector;
    5. the turn from the current heading is limited to ``+-max_turn`` radians (the familiarity
       agents' scan range).

    A put-back (:meth:`reset`) moves the last match to the route view the agent was put on.

    Parameters
    ----------
    homing : HomingMethod
    snapshots : ndarray, shape (K, H, W)
        Route views, canonical panoramas rendered at ``snapshot_headings``.
    snapshot_headings : ndarray, shape (K,)
        Radians CCW from ``+x``.
    render : callable ``(xy, heading) -> (H, W)``
    window, lookahead : int
        Route views.
    test_step_m : float
        Metres.
    max_turn : float
        Radians.
    passed : {"keep", "skip"}
        What to do with a target view the agent has passed (step 3).
    max_skip : int, optional
        Views skipped at most per call (default ``lookahead``, at least 1).
    route_weight : float
        ``w`` in ``[0, 1]`` (step 4).
    route_directions : ndarray, shape (K,), optional
        Route direction at each view, radians CCW from ``+x`` (default ``snapshot_headings``).
    """

    def __init__(self, homing: Any, *, snapshots: np.ndarray, snapshot_headings: np.ndarray, render: Render,
                 window: int, lookahead: int, test_step_m: float, max_turn: float, passed: str = "keep",
                 max_skip: int | None = None, route_weight: float = 0.0,
                 route_directions: np.ndarray | None = None) -> None:
        if passed not in ("keep", "skip"):
            raise ValueError(f"passed={passed!r}: use 'keep' or 'skip'")
        if not 0.0 <= route_weight <= 1.0:
            raise ValueError(f"route_weight={route_weight} outside [0, 1]")
        self.homing = homing
        self.snapshots = np.asarray(snapshots)
        self.headings = np.asarray(snapshot_headings, np.float64)
        self.route_directions = self.headings if route_directions is None else np.asarray(route_directions, np.float64)
        self.prepared = [homing.prepare(img) for img in self.snapshots]
        self.render = render
        self.window, self.lookahead = int(window), int(lookahead)
        self.test_step_m, self.max_turn = float(test_step_m), float(max_turn)
        self.passed, self.route_weight = passed, float(route_weight)
        self.max_skip = max(1, self.lookahead) if max_skip is None else int(max_skip)
        self.last = 0

    def _home(self, xy: np.ndarray, j: int) -> float:
        return home_direction(self.homing, self.prepared[j], float(self.headings[j]), self.render, xy,
                              test_step_m=self.test_step_m)

    def target_direction(self, xy: np.ndarray) -> tuple[float, int]:
        """The home direction from ``xy`` (radians CCW from ``+x``, NaN if none) and the view it homes to."""
        n = len(self.snapshots)
        _h, self.last = windowed_match(self.render(xy, 0.0), self.snapshots, self.headings, last=self.last,
                                       window=self.window)
        j = min(self.last + self.lookahead, n - 1)
        h = self._home(xy, j)
        if self.passed == "skip":
            first = j
            while (np.isfinite(h) and j < n - 1 and j - first < self.max_skip
                   and abs(wrap_angle(h - self.route_directions[j])) > math.pi / 2):
                j += 1
                h = self._home(xy, j)
        return h, j

    def __call__(self, xy: np.ndarray, heading: float) -> float:
        h, j = self.target_direction(xy)
        if not np.isfinite(h):
            return float("nan")
        w = self.route_weight
        if w > 0:
            r = float(self.route_directions[j])
            y, x = (1 - w) * math.sin(h) + w * math.sin(r), (1 - w) * math.cos(h) + w * math.cos(r)
            h = math.atan2(y, x) if math.hypot(x, y) > 1e-9 else r  # opposite and equal: the route decides
        return heading + float(np.clip(wrap_angle(h - heading), -self.max_turn, self.max_turn))

    def reset(self, index: int) -> None:
        """The agent was put back at route view ``index``."""
        self.last = int(index)


__all__ = ["FamiliarityFollower", "HomingFollower", "home_direction", "route_window", "windowed_match"]
