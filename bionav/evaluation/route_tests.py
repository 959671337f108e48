"""bionav's own route tests (``experiment.protocol=bionav``): open loop at lateral offsets, closed loop from a displaced start.

A :class:`SnapshotFollower` holds one method's per-route state (the snapshots prepared once) and
answers a heading for a view:

* ``perfect_memory``: RIDF against every snapshot, head where the best rotation points
  (Baddeley et al. 2012, doi:10.1371/journal.pcbi.1002336);
* ``windowed``: the same within a window ahead of the last best match;
* ``zernike``: perfect memory on Zernike-moment amplitudes, heading from the phases of the best
  snapshot's moments (Sun, Yue & Mangan 2020, doi:10.7554/eLife.54026); the signature is handed
  in (anything with ``moments(image) -> (moments, index)``, e.g. ``signature=zernike``);
* ``homing``: a homing method (handed in) homes to the snapshot ``lookahead`` views after the best match.

:func:`open_loop` measures heading errors at test points offset from the route,
:func:`closed_loop` walks a simulated agent. Conventions: positions in metres (world frame),
headings radians counter-clockwise from world ``+x``; a ``render(xy, heading)`` gives the
canonical panorama at a pose (:func:`bionav.evaluation.route_setup.route_renderer`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from bionav.evaluation.route import best_match, distance_to_route, lateral_normals
from bionav.evaluation.route_followers import home_direction, route_window
from bionav.evaluation.route_setup import RouteSetup
from bionav.geometry import angular_difference, wrap_angle
from bionav.homing.signatures.zernike import rotation_from_moments

class SnapshotFollower:
    """Per-route state of one method: snapshots prepared once.

    Parameters
    ----------
    method : str
        ``perfect_memory``, ``windowed``, ``zernike`` or ``homing``.
    setup : RouteSetup
        The route.
    window : int
        Snapshots ahead of the last match searched by ``windowed`` (and by ``homing`` to track progress).
    test_step_m : float
        Test-step length of homing methods with test steps, metres.
    homing : HomingMethod, optional
        The method of ``homing``.
    zernike : Signature, optional
        The Zernike-moment signature of ``zernike`` (``moments(image) -> (moments, index)``).
    """

    def __init__(self, method: str, setup: RouteSetup, *, window: int, test_step_m: float, homing: Any = None,
                 zernike: Any = None):
        self.method = method
        self.s = setup
        self.window = window
        self.test_step_m = test_step_m
        self.homing = homing
        self.snaps = setup.db.images
        self.prepared = None
        if method == "homing":
            self.prepared = [homing.prepare(img) for img in setup.db.images]
        if method == "zernike":
            self.zernike = zernike
            self.moments = np.array([self.zernike.moments(img)[0] for img in setup.db.images])
            self.zindex = self.zernike.moments(setup.db.images[0])[1]

    def zernike_heading(self, view0, lo: int = 0, hi: int | None = None):
        """Best snapshot by moment amplitudes; heading from the phases (view0 looks along heading 0)."""
        hi = len(self.moments) if hi is None else hi
        zc = self.zernike.moments(view0)[0]
        d = ((np.abs(self.moments[lo:hi]) - np.abs(zc)[None]) ** 2).sum(axis=1)
        k = lo + int(np.argmin(d))
        delta = rotation_from_moments(zc, self.moments[k], self.zindex)  # heading(view0) - heading(snapshot k)
        return float(wrap_angle(-delta)), k

    def ridf_heading(self, view0, lo: int = 0, hi: int | None = None):
        """Heading of the best RIDF match among snapshots ``lo .. hi`` and its index."""
        hi = len(self.snaps) if hi is None else hi
        h, k, d = best_match(view0, self.snaps[lo:hi], snapshot_headings=self.s.heading[lo:hi])
        return h, lo + k

    def window_of(self, k_last: int, centred: bool):
        """The snapshot window searched after a match at ``k_last``."""
        return route_window(k_last, len(self.snaps), self.window, centred=centred)

    def home_direction(self, render, pos, target: int):
        """World direction from ``pos`` to snapshot ``target`` by the homing method (NaN if none)."""
        return home_direction(self.homing, self.prepared[target], float(self.s.heading[target]), render, pos,
                              test_step_m=self.test_step_m)


def open_loop(f: SnapshotFollower, render, *, test_stride: int, offsets_m, lookahead: int, progress=None):
    """Heading errors at test points offset from the route: ``(stations (N,), errors (N, M), estimates (N, M))``.

    Every ``test_stride``-th route view is a station, tested at each lateral offset of ``offsets_m``
    (metres, left positive); RIDF methods are scored against the recorded heading there, ``homing``
    against the true direction to the snapshot ``lookahead`` views ahead.
    """
    s = f.s
    stations = np.arange(0, len(s.xy), test_stride)
    offsets = np.asarray(offsets_m, np.float64)
    normals = lateral_normals(s.heading)
    err = np.full((len(stations), len(offsets)), np.nan)
    est = np.full_like(err, np.nan)
    it = range(len(stations)) if progress is None else progress(range(len(stations)))
    for a in it:
        i = int(stations[a])
        for b, off in enumerate(offsets):
            p = s.xy[i] + off * normals[i]
            if f.method == "homing":
                target = min(i + lookahead, len(s.xy) - 1)
                truth = math.atan2(s.xy[target, 1] - p[1], s.xy[target, 0] - p[0])
                h = f.home_direction(render, p, target)
            else:
                truth = float(s.heading[i])
                view0 = render(p, 0.0)
                if f.method == "zernike":
                    h, _k = f.zernike_heading(view0)
                else:
                    lo, hi = (0, None) if f.method == "perfect_memory" else f.window_of(i, centred=True)
                    h, _k = f.ridf_heading(view0, lo, hi)
            est[a, b] = h
            err[a, b] = angular_difference(h, truth) if np.isfinite(h) else np.nan
    return stations, err, est


def _closed_loop_heading(f: SnapshotFollower, render, pos, heading: float, k_last: int, lookahead: int):
    """The next heading of the closed-loop agent at ``pos`` and the index of its best match."""
    if f.method == "perfect_memory":
        return f.ridf_heading(render(pos, 0.0))
    if f.method == "zernike":
        return f.zernike_heading(render(pos, 0.0))
    lo, hi = f.window_of(k_last, centred=False)
    if f.method == "windowed":
        return f.ridf_heading(render(pos, 0.0), lo, hi)
    _h, k_last = f.ridf_heading(render(pos, 0.0), lo, hi)
    h = f.home_direction(render, pos, min(k_last + lookahead, len(f.s.xy) - 1))
    return (h if np.isfinite(h) else heading), k_last


def closed_loop(f: SnapshotFollower, render, *, start_offset_m: float, agent_step_m: float, max_steps_factor: float,
                success_radius_m: float, give_up_m: float, lookahead: int, progress=None):
    """Simulated agent from the start displaced ``start_offset_m`` to the left; ``(path (T, 2), completed, mean distance)``.

    Steps of ``agent_step_m``; completed within ``success_radius_m`` of the route's end, given up
    beyond ``give_up_m`` from the route or after ``max_steps_factor`` x route length / step; the
    mean distance of the path from the route, metres. ``progress(iterable, total=...)`` shows the
    steps (at most the step budget; the bar ends when the agent does).
    """
    s = f.s
    pos = s.xy[0] + start_offset_m * lateral_normals(s.heading[:1])[0]
    end = s.dense_xy[-1]
    length = float(np.linalg.norm(np.diff(s.dense_xy, axis=0), axis=1).sum())
    max_steps = int(math.ceil(max_steps_factor * length / agent_step_m))
    path = [pos.copy()]
    k_last = 0
    heading = float(s.heading[0])
    completed = False
    for _ in (progress or (lambda it, **_: it))(range(max_steps), total=max_steps):
        heading, k_last = _closed_loop_heading(f, render, pos, heading, k_last, lookahead)
        pos = pos + agent_step_m * np.array([math.cos(heading), math.sin(heading)])
        path.append(pos.copy())
        if np.linalg.norm(pos - end) <= success_radius_m:
            completed = True
            break
        if distance_to_route(pos[None], s.dense_xy)[0][0] > give_up_m:
            break
    path = np.array(path)
    dist = distance_to_route(path, s.dense_xy)[0]
    return path, completed, float(dist.mean())
