"""Route-following measures: RIDF, perfect-memory headings, catchment width, distance from a route.

The rotational image difference function (RIDF, Zeil, Hofmann & Chahl 2003,
"Catchment areas of panoramic snapshots in outdoor scenes", J. Opt. Soc. Am.
A 20(3), 450-469, doi:10.1364/JOSAA.20.000450) of a current view ``C`` against
a snapshot ``S`` is the mean squared pixel difference of ``C`` rotated by each
whole column against ``S``. A perfect-memory route follower (Baddeley et al.
2012, PLoS Comput. Biol. 8(1), e1002336, doi:10.1371/journal.pcbi.1002336)
stores every view along the route and heads where the best-matching rotation
of its current view points.

The published route-following test (Ardin, Peng, Mangan, Lagogiannis & Webb
2016, PLoS Comput. Biol. 12(2), e1004683, doi:10.1371/journal.pcbi.1004683):
:func:`follow_route` walks an agent from the route's start in fixed steps
(:func:`protocol_step`) along the heading it chooses, puts it back on the
route (counting an error) whenever it strays too far, and stops at the nest or
after a step budget; :func:`least_unfamiliar` is the familiarity agents' choice;
:func:`scan_views` cuts the views of a heading scan out of one panorama and
preprocesses them as the paper (inversion, histogram equalisation, 36 x 10).

Conventions: canonical panoramas (:mod:`bionav.geometry`); a current view
rendered at heading ``phi`` rolled by ``-c`` columns is the view at heading
``phi + 2*pi*c/W``; headings in radians CCW from world ``+x``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np

from bionav.geometry import TWO_PI, wrap_angle


def _grey(images: np.ndarray, ndim: int) -> np.ndarray:
    a = np.asarray(images, np.float64)
    return a.mean(axis=-1) if a.ndim == ndim + 1 else a


def ridf(current: np.ndarray, snapshots: np.ndarray) -> np.ndarray:
    """Rotational image difference of one view against many snapshots.

    Parameters
    ----------
    current : ndarray, shape (H, W) or (H, W, C)
    snapshots : ndarray, shape (K, H, W) or (K, H, W, C)

    Returns
    -------
    ndarray, shape (K, W)
        ``D[k, c] = mean((roll(current, -c, axis=1) - snapshots[k])**2)`` over
        pixels (and channels averaged first to grey), via the FFT.
    """
    cur = _grey(current, 2)
    snaps = _grey(snapshots, 3)
    if snaps.ndim == 2:
        snaps = snaps[None]
    h, w = cur.shape
    fc = np.fft.rfft(cur, axis=1)
    fs = np.fft.rfft(snaps, axis=2)
    # corr[k, c] = sum_r sum_j cur[r, j + c] * snap[k, r, j]
    corr = np.fft.irfft((fc[None] * np.conj(fs)).sum(axis=1), n=w, axis=1)
    ss = (snaps ** 2).sum(axis=(1, 2))
    return (float((cur ** 2).sum()) + ss[:, None] - 2.0 * corr) / (h * w)


def best_match(current: np.ndarray, snapshots: np.ndarray, *, snapshot_headings: np.ndarray,
               current_heading: float = 0.0) -> tuple[float, int, float]:
    """Perfect-memory heading: the rotation of ``current`` that best matches any snapshot.

    The best (snapshot ``k``, rotation ``c``) gives the heading at which the
    current view looks like snapshot ``k``:
    ``current_heading + 2*pi*c/W``. (``snapshot_headings`` are not needed for
    the heading itself -- the snapshots were taken facing along the route --
    but fix the frame in which the views were rendered.)

    Returns
    -------
    heading : float
        Radians CCW from world ``+x``, wrapped to ``[-pi, pi)``.
    index : int
        Best-matching snapshot.
    difference : float
        Its minimum RIDF value.
    """
    d = ridf(current, snapshots)
    k, c = np.unravel_index(int(np.argmin(d)), d.shape)
    w = d.shape[1]
    return float(wrap_angle(current_heading + TWO_PI * c / w)), int(k), float(d[k, c])


def distance_to_route(points: np.ndarray, route_xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance of points to a polyline and the index of the nearest route vertex.

    Parameters
    ----------
    points : ndarray, shape (N, 2)
    route_xy : ndarray, shape (M, 2)
        Polyline vertices in metres.

    Returns
    -------
    distance : ndarray, shape (N,)
        Metres to the nearest point on any segment.
    nearest : ndarray, shape (N,), int
        Index of the nearest vertex.
    """
    p = np.asarray(points, np.float64).reshape(-1, 2)
    r = np.asarray(route_xy, np.float64).reshape(-1, 2)
    if len(r) == 1:
        d = np.linalg.norm(p - r[0], axis=1)
        return d, np.zeros(len(p), np.int64)
    a = r[:-1]
    ab = r[1:] - a
    L2 = np.maximum((ab ** 2).sum(axis=1), 1e-30)
    t = np.clip(((p[:, None, :] - a[None]) * ab[None]).sum(axis=2) / L2[None], 0.0, 1.0)
    proj = a[None] + t[..., None] * ab[None]
    dist = np.linalg.norm(p[:, None, :] - proj, axis=2)
    nearest_vertex = np.argmin(np.linalg.norm(p[:, None, :] - r[None], axis=2), axis=1)
    return dist.min(axis=1), nearest_vertex


@dataclass
class RouteRun:
    """One closed-loop run of :func:`follow_route`.

    Attributes
    ----------
    path : ndarray, shape (T, 2)
        Positions in metres, world frame: the start, then every position after
        a step; a put-back adds the route view it was put on.
    errors : int
        Put-backs (the agent strayed more than ``putback_m`` from the route).
    reached_nest : bool
        Came within ``goal_m`` of the nest before the step budget ran out.
    steps : int
        Steps taken.
    putbacks : list of int
        Route-view index of every put-back, in order.
    """

    path: np.ndarray
    errors: int
    reached_nest: bool
    steps: int
    putbacks: list


@dataclass
class StepResult:
    """One step of :func:`protocol_step`.

    Attributes
    ----------
    position : ndarray, shape (2,)
        Metres, world frame: where the agent is after the step (after a put-back: on the route view).
    heading : float
        Radians CCW from world ``+x``: the heading it walked (after a put-back: the route view's).
    stepped_to : ndarray, shape (2,)
        Where the step itself ended (before any put-back), metres.
    put_back : int
        Route-view index the agent was put on, ``-1`` when it was not put back.
    reached_nest : bool
        The step ended within ``goal_m`` of the nest (checked before the put-back rule).
    """

    position: np.ndarray
    heading: float
    stepped_to: np.ndarray
    put_back: int
    reached_nest: bool


def protocol_step(choose_heading: Callable[[np.ndarray, float], float], position: np.ndarray, heading: float, *,
                  route_xy: np.ndarray, route_heading: np.ndarray, nest_xy: np.ndarray, step_m: float,
                  putback_m: float, goal_m: float, jitter_m: float = 0.0, heading_noise: float = 0.0,
                  rng: np.random.Generator | None = None) -> StepResult:
    """One step of the route-following test of Ardin et al. 2016 (doi:10.1371/journal.pcbi.1004683).

    ``heading = choose_heading(position, heading)`` (the agent's scan and choice; NaN keeps
    the heading), Gaussian heading noise of std ``heading_noise`` radians added to it (the
    agent walks a little off the heading it chose; not in the paper), a step of ``step_m``
    along it, isotropic Gaussian position noise of ``jitter_m`` per axis (drawn after the
    heading noise); the nest is reached within ``goal_m`` of ``nest_xy``; otherwise,
    farther than ``putback_m`` from the route polyline (strictly), the agent is put on the
    *nearest* route view, facing ``route_heading`` there (an error).

    Parameters
    ----------
    choose_heading : callable ``(xy (2,), heading) -> heading``
        Radians CCW from world ``+x``.
    position : ndarray, shape (2,)
        Metres, world frame.
    heading : float
        Radians CCW from ``+x``.
    route_xy : ndarray, shape (K, 2)
        Route views (training positions), metres.
    route_heading : ndarray, shape (K,)
        Radians CCW from ``+x``.
    nest_xy : ndarray, shape (2,)
    step_m, putback_m, goal_m, jitter_m : float
        Metres; ``jitter_m > 0`` needs ``rng``.
    heading_noise : float
        Radians (std); ``> 0`` needs ``rng``.

    Returns
    -------
    StepResult
    """
    new = choose_heading(position, heading)
    if np.isfinite(new):
        heading = float(new)
    if heading_noise > 0:
        if rng is None:
            raise ValueError("heading_noise > 0 needs an rng")
        heading = float(heading + rng.normal(0.0, heading_noise))
    pos = np.asarray(position, np.float64) + step_m * np.array([math.cos(heading), math.sin(heading)])
    if jitter_m > 0:
        if rng is None:
            raise ValueError("jitter_m > 0 needs an rng")
        pos = pos + rng.normal(0.0, jitter_m, 2)
    if np.linalg.norm(pos - np.asarray(nest_xy, np.float64)) <= goal_m:
        return StepResult(pos, heading, pos, -1, True)
    dist, nearest = distance_to_route(pos[None], route_xy)
    if dist[0] > putback_m:
        k = int(nearest[0])
        return StepResult(np.asarray(route_xy[k], np.float64).copy(), float(route_heading[k]), pos, k, False)
    return StepResult(pos, heading, pos, -1, False)


def follow_route(choose_heading: Callable[[np.ndarray, float], float], *, route_xy: np.ndarray,
                 route_heading: np.ndarray, nest_xy: np.ndarray, step_m: float, putback_m: float,
                 goal_m: float, max_steps: int, jitter_m: float = 0.0, heading_noise: float = 0.0,
                 start_offset_m: float = 0.0, rng: np.random.Generator | None = None,
                 on_putback: Callable[[int], None] | None = None) -> RouteRun:
    """Walk an agent along a route with the put-back rule of Ardin et al. 2016 (doi:10.1371/journal.pcbi.1004683).

    The agent starts on route view 0 (``start_offset_m`` to its left, across ``route_heading[0]``;
    the paper starts on the view) facing ``route_heading[0]`` and takes
    :func:`protocol_step` after step until it reaches the nest or ``max_steps``
    steps are taken; every put-back is an error, and ``on_putback(index)``
    tells the agent where it was put.

    Parameters
    ----------
    choose_heading : callable ``(xy (2,), heading) -> heading``
        Radians CCW from world ``+x``; a NaN keeps the current heading.
    route_xy : ndarray, shape (K, 2)
        Route views (training positions), metres.
    route_heading : ndarray, shape (K,)
        Radians CCW from ``+x``.
    nest_xy : ndarray, shape (2,)
    step_m, putback_m, goal_m : float
        Metres.
    max_steps : int
        Step budget.
    jitter_m : float
        Metres; needs ``rng`` when positive.
    heading_noise : float
        Radians, the std of the noise added to every chosen heading (:func:`protocol_step`); needs ``rng``.
    start_offset_m : float
        Metres, left positive.
    """
    route_xy = np.asarray(route_xy, np.float64)
    if (jitter_m > 0 or heading_noise > 0) and rng is None:
        raise ValueError("jitter_m > 0 or heading_noise > 0 needs an rng")
    heading = float(route_heading[0])
    pos = route_xy[0] + float(start_offset_m) * lateral_normals(np.array([heading]))[0]
    path = [pos.copy()]
    steps, reached, putbacks = 0, False, []
    for steps in range(1, int(max_steps) + 1):
        r = protocol_step(choose_heading, pos, heading, route_xy=route_xy, route_heading=route_heading,
                          nest_xy=nest_xy, step_m=step_m, putback_m=putback_m, goal_m=goal_m, jitter_m=jitter_m,
                          heading_noise=heading_noise, rng=rng)
        path.append(r.stepped_to.copy())
        pos, heading = r.position, r.heading
        if r.reached_nest:
            reached = True
            break
        if r.put_back >= 0:
            putbacks.append(r.put_back)
            path.append(pos.copy())
            if on_putback is not None:
                on_putback(r.put_back)
    return RouteRun(np.array(path), len(putbacks), reached, steps if max_steps > 0 else 0, putbacks)


def least_unfamiliar(unfamiliarity: np.ndarray, offsets: np.ndarray) -> int:
    """Index of the least unfamiliar scan view; ties go to the one nearest straight ahead.

    Parameters
    ----------
    unfamiliarity : ndarray, shape (S,)
        Lower = more familiar; NaN counts as infinitely unfamiliar.
    offsets : ndarray, shape (S,)
        Scan offsets from the current heading, radians.

    Returns
    -------
    int
        ``-1`` when no value is finite (the agent has no opinion).
    """
    u = np.nan_to_num(np.asarray(unfamiliarity, np.float64), nan=np.inf)
    if not np.isfinite(u).any():
        return -1
    best = np.flatnonzero(u == u.min())
    return int(best[np.argmin(np.abs(np.asarray(offsets)[best]))])


def scan_views(panorama: np.ndarray, *, column_deg: float, scan_half_deg: float = 60.0, scan_step_deg: float = 2.0,
               fov_deg: float = 296.0, pixel_deg: float = 4.0, size: Sequence[int] = (36, 10)) -> tuple[np.ndarray, np.ndarray]:
    """The views of a heading scan, cut out of one panorama and preprocessed as Ardin et al. 2016.

    The panorama's column ``m`` looks at ``heading + m * column_deg``
    (counter-clockwise, :func:`bionav.world.render.ray_grid`), its rows at the
    elevations of the wanted view. The scan view at offset ``o`` (degrees,
    CCW, ``-scan_half_deg .. +scan_half_deg`` in ``scan_step_deg``) has
    ``fov_deg / pixel_deg`` pixels, left (``o + fov/2 - pixel/2``) to right,
    each the panorama column at its centre. Every view is then inverted
    (``1 - v``), histogram-equalised (:func:`bionav.homing.imageops.equalize_histogram`)
    and area-resized to ``size = [W, H]`` (doi:10.1371/journal.pcbi.1004683).

    Parameters
    ----------
    panorama : ndarray, shape (H, W), float in [0, 1]
    column_deg : float
        Degrees per panorama column; ``scan_step_deg`` and ``pixel_deg`` must be
        whole multiples of it.

    Returns
    -------
    views : ndarray, shape (S, size[1], size[0]), float32 in [0, 1]
    offsets : ndarray, shape (S,)
        Scan offsets in radians (CCW positive), ``S = 2 * scan_half_deg / scan_step_deg + 1``.
    """
    from bionav.homing.imageops import equalize_histogram, resize_images

    pano = np.asarray(panorama, np.float32)
    w = pano.shape[1]
    scan = int(round(scan_step_deg / column_deg))
    pix = int(round(pixel_deg / column_deg))
    if scan < 1 or pix < 1 or abs(scan * column_deg - scan_step_deg) > 1e-9 or abs(pix * column_deg - pixel_deg) > 1e-9:
        raise ValueError(f"scan step {scan_step_deg} deg and pixel {pixel_deg} deg must be whole multiples "
                         f"of the panorama's {column_deg} deg columns")
    n_pix = int(round(fov_deg / pixel_deg))
    k = np.arange(-int(round(scan_half_deg / scan_step_deg)), int(round(scan_half_deg / scan_step_deg)) + 1)
    # pixel j of the view at offset k*scan: azimuth k*scan + (n_pix - 1)/2*pix - j*pix (in columns)
    half = (n_pix - 1) * pix / 2.0
    if abs(half - round(half)) > 1e-9:
        raise ValueError("fov_deg / pixel_deg must give pixel centres on panorama columns")
    cols = (k[:, None] * scan + int(round(half)) - np.arange(n_pix)[None] * pix) % w
    views = 1.0 - pano[:, cols].transpose(1, 0, 2)  # (S, H, n_pix), inverted
    views = equalize_histogram(views)
    return resize_images(views, size), scan_offsets(scan_half_deg=scan_half_deg, scan_step_deg=scan * column_deg)


def scan_offsets(*, scan_half_deg: float, scan_step_deg: float) -> np.ndarray:
    """The headings of a scan relative to the current one: ``-scan_half_deg .. +scan_half_deg`` in ``scan_step_deg``.

    Returns
    -------
    ndarray, shape (S,)
        Radians, counter-clockwise positive, ``S = 2 * round(scan_half_deg / scan_step_deg) + 1``
        (the offsets of :func:`scan_views`).
    """
    n = int(round(scan_half_deg / scan_step_deg))
    return np.deg2rad(np.arange(-n, n + 1) * float(scan_step_deg))


def lateral_normals(headings: np.ndarray) -> np.ndarray:
    """Unit vectors to the left of each heading (CCW 90 degrees), shape ``(N, 2)``."""
    h = np.asarray(headings, np.float64)
    return np.column_stack([-np.sin(h), np.cos(h)])


def catchment_width(offsets: np.ndarray, errors: np.ndarray, *, threshold: float) -> np.ndarray:
    """Route catchment width per route point from heading errors at lateral offsets.

    The catchment of route point ``i`` extends to each side as far as every
    offset up to there (from 0 outwards) has a heading error below
    ``threshold``; the width is the sum of both sides' extents (BoB/navbench
    style "catchment area" of a route, here across the route).

    Parameters
    ----------
    offsets : ndarray, shape (M,)
        Signed lateral offsets in metres (must include 0; left positive).
    errors : ndarray, shape (N, M)
        Absolute heading errors in radians (NaN = failure).
    threshold : float
        Radians.

    Returns
    -------
    ndarray, shape (N,)
        Width in metres (0 when the route point itself fails).
    """
    off = np.asarray(offsets, np.float64)
    err = np.asarray(errors, np.float64)
    if not np.any(off == 0):
        raise ValueError("offsets must include 0")
    ok = np.nan_to_num(err, nan=np.inf) < threshold
    zero = int(np.flatnonzero(off == 0)[0])
    width = np.zeros(len(err))
    for side in (1, -1):
        order = np.flatnonzero(np.sign(off) == side)
        order = order[np.argsort(np.abs(off[order]))]
        ext = np.zeros(len(err))
        alive = ok[:, zero].copy()
        for j in order:
            alive &= ok[:, j]
            ext = np.where(alive, np.abs(off[j]), ext)
        width += ext
    return width
