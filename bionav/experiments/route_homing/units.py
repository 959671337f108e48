"""One unit of work of ``experiment.protocol=ardin2016``: one agent following one route, for one seed and condition.

A :class:`Unit` is plain data (it crosses to pool workers): the run's checked settings with the
condition applied, the ``db`` node, the agent and where it follows. :func:`run_unit` sets the
route up (its views cached on disk, the world and the route kept per process), trains the
agent on the route's training views (rendered once per route, seed and condition in each
process and shared by the agents that follow it there) and walks it with
:func:`bionav.evaluation.route.follow_route`. Its random streams depend on the seed, the
route and the agent only, so a run gives the same rows in any order, split over any number
of processes.

Conventions: positions in metres (world frame of the mesh), headings radians CCW from world
``+x``; views as :func:`bionav.evaluation.route.scan_views`.
"""

from __future__ import annotations

import dataclasses
import json
import math
import time
import zlib
from dataclasses import dataclass
from typing import Any

import numpy as np

from bionav.experiments.route_homing.config import RouteHomingConfig

#: per process: route set-ups by (db node, route) and training views by (db node, route, seed, stride)
_SETUPS: dict[tuple, Any] = {}
_VIEWS: dict[tuple, np.ndarray] = {}
_CACHE_ITEMS = 64


@dataclass(frozen=True)
class Unit:
    """One agent on one route, seed and condition.

    Attributes
    ----------
    exp : RouteHomingConfig
        The run's checked settings with the condition applied (``sweep`` emptied).
    db : str
        The ``db`` node (:func:`frozen`), the condition applied.
    cache_dir : str
    route : str
    learned : tuple of str
        The routes whose views a familiarity agent learns (the followed one first).
    seed : int
    agent : str
    kind : str
        ``route_agent`` or ``homing``.
    homing : tuple of str or None
        ``homing``: ``(homing node, signature node)`` (:func:`frozen`; the signature ``null`` for
        methods without one).
    axis, level :
        The condition (``""`` and None for the run as configured; axis ``world``: the world's label).
    keep_path : bool
        Its path is drawn in ``plots/world_routes.png`` (the first seed of the run as configured).
    """

    exp: RouteHomingConfig
    db: str
    cache_dir: str
    route: str
    learned: tuple
    seed: int
    agent: str
    kind: str
    homing: Any = None
    axis: str = ""
    level: float | str | None = None
    keep_path: bool = False


def frozen(node: Any) -> str:
    """A resolved config container as a hashable JSON text (keys sorted); :func:`json.loads` gives it back."""
    return json.dumps(node, sort_keys=True)


def unit_stream(seed: int, *parts: str) -> np.random.Generator:
    """The random stream of ``seed`` and named parts (route, agent, purpose), independent of the order of work."""
    return np.random.default_rng(np.random.SeedSequence([int(seed), *(zlib.crc32(p.encode()) for p in parts)]))


def route_of(db: tuple, cache_dir: str, name: str):
    """Route ``name`` set up in the world of ``db`` (:func:`bionav.evaluation.route_setup.setup_route`; ``db=bag``:
    :func:`~bionav.evaluation.route_setup.setup_bag_route`), kept per process."""
    from bionav.evaluation.route_setup import setup_bag_route, setup_route

    node = json.loads(db)
    bag = node.get("source") == "bag"  # db=bag: the bag's one drive, whatever name it is asked by
    key = (db, None if bag else name)
    if key not in _SETUPS:
        if len(_SETUPS) >= _CACHE_ITEMS:
            _SETUPS.pop(next(iter(_SETUPS)))
        _SETUPS[key] = setup_bag_route(node) if bag else setup_route(node, name, cache_dir=cache_dir)
    return _SETUPS[key]


def route_headings(setup, exp: RouteHomingConfig) -> np.ndarray:
    """The headings the route's views are stored at: the direction of travel or the ant's recorded heading."""
    from bionav.evaluation.route_setup import travel_headings

    return setup.heading if exp.training_heading == "recorded" else travel_headings(setup.xy)


def training_indices(n_views: int, stride: int) -> np.ndarray:
    """Every ``stride``-th route view from the first, and always the last (the nest's view)."""
    idx = np.arange(0, n_views, int(stride))
    return idx if idx[-1] == n_views - 1 else np.append(idx, n_views - 1)


def scan_views_of(setup, exp: RouteHomingConfig, rng: np.random.Generator, *, half_deg: float | None = None):
    """The agents' preprocessed scan views (:func:`bionav.evaluation.route_setup.scan_renderer`) of ``exp``'s scan."""
    from bionav.evaluation.route_setup import scan_renderer

    return scan_renderer(setup, rng, scan_step_deg=exp.scan_step_deg, supersample=exp.supersample,
                         scan_half_deg=exp.scan_half_deg if half_deg is None else half_deg, view_size=exp.view_size)


def training_views(unit: Unit, name: str) -> tuple[np.ndarray, float]:
    """The training views of route ``name`` for ``unit``'s seed and condition, and the CPU seconds spent rendering them.

    Rendered once per process (0 s when they were already there): the views every
    ``training_stride``-th route view, facing the route's stored headings.
    """
    exp = unit.exp
    key = (unit.db, name, unit.seed, exp.training_stride, exp.training_heading, exp.supersample,
           tuple(exp.view_size), exp.scan_step_deg)
    if key in _VIEWS:
        return _VIEWS[key], 0.0
    cpu0 = time.process_time()
    setup = route_of(unit.db, unit.cache_dir, name)
    heading = route_headings(setup, exp)
    one = scan_views_of(setup, exp, unit_stream(unit.seed, name, "training"), half_deg=0.0)
    idx = training_indices(len(setup.xy), exp.training_stride)
    views = np.concatenate([one(setup.xy[i], float(heading[i]))[0] for i in idx])
    if len(_VIEWS) >= _CACHE_ITEMS:
        _VIEWS.pop(next(iter(_VIEWS)))
    _VIEWS[key] = views
    return views, time.process_time() - cpu0


class _Plugins:
    """What :func:`bionav.experiments.common.make_homing` needs of a run context, in a pool worker."""

    @staticmethod
    def plugin(kind: str, node: Any, **kwargs: Any) -> Any:
        from bionav.config import plugin_config

        cls, config = plugin_config(kind, node)
        return cls(config, **kwargs)


def _homing_follower(unit: Unit, setup, heading: np.ndarray):
    from omegaconf import OmegaConf

    from bionav.evaluation.route_followers import HomingFollower
    from bionav.evaluation.route_setup import route_renderer
    from bionav.experiments.common import make_homing

    exp = unit.exp
    homing_node, signature_node = unit.homing
    cfg = OmegaConf.create({"homing": json.loads(homing_node), "signature": json.loads(signature_node)})
    method = make_homing(cfg, _Plugins(), setup.geometry)
    idx = training_indices(len(setup.xy), exp.training_stride)
    shoot = route_renderer(setup, unit_stream(unit.seed, setup.name, "snapshots"))
    snapshots = np.stack([shoot(setup.xy[i], float(heading[i])) for i in idx])
    return HomingFollower(method, snapshots=snapshots, snapshot_headings=heading[idx],
                          render=route_renderer(setup, unit_stream(unit.seed, setup.name, unit.agent)),
                          window=exp.follower_window, lookahead=exp.lookahead, test_step_m=exp.test_step_m,
                          max_turn=math.radians(exp.scan_half_deg), passed=exp.passed, route_weight=exp.route_weight)


def follower_of(unit: Unit, setup, heading: np.ndarray) -> tuple[Any, float]:
    """The heading chooser of ``unit``'s agent on its route, and the CPU seconds of rendering shared training views."""
    from bionav.config import plugin_config
    from bionav.evaluation.route import scan_offsets
    from bionav.evaluation.route_followers import FamiliarityFollower

    exp = unit.exp
    if unit.kind == "homing":
        return _homing_follower(unit, setup, heading), 0.0
    cls, config = plugin_config("route_agent", {"name": unit.agent, **dict(exp.agent_params.get(unit.agent) or {})},
                                key=f"experiment.agent_params.{unit.agent}")
    agent = cls(config, rng=unit_stream(unit.seed, setup.name, unit.agent))
    shared = 0.0
    if getattr(agent, "needs_views", True):
        parts = []
        for name in unit.learned:
            views, cpu = training_views(unit, name)
            parts.append(views)
            shared += cpu
        agent.train(np.concatenate(parts))
    else:
        agent.train(np.zeros((0, 0), np.float32))
    offsets = scan_offsets(scan_half_deg=exp.scan_half_deg, scan_step_deg=exp.scan_step_deg)
    views = scan_views_of(setup, exp, unit_stream(unit.seed, setup.name, unit.agent))
    return FamiliarityFollower(agent, views, offsets=offsets), shared


def run_unit(unit: Unit) -> dict[str, Any]:
    """Walk ``unit``'s agent along its route; one row of ``route_following.csv`` and its ``path`` (T, 2), metres.

    ``cpu_s`` is the agent's own CPU time (building and training it, rendering its views and
    walking); ``views_cpu_s`` the rendering of training views it was the first in its process to need.
    """
    from bionav.evaluation.route import follow_route

    exp = unit.exp
    setup = route_of(unit.db, unit.cache_dir, unit.route)
    heading = route_headings(setup, exp)
    length = float(np.linalg.norm(np.diff(setup.dense_xy, axis=0), axis=1).sum())
    max_steps = int(math.ceil(exp.max_steps_factor * length / exp.agent_step_m))
    wall0, cpu0 = time.perf_counter(), time.process_time()
    follower, shared = follower_of(unit, setup, heading)
    learned_at = training_indices(len(setup.xy), exp.training_stride)

    def put_back(index: int) -> None:  # the follower counts its own (training) views
        follower.reset(int(np.argmin(np.abs(learned_at - int(index)))))

    res = follow_route(follower, route_xy=setup.xy, route_heading=heading, nest_xy=setup.dense_xy[-1],
                       step_m=exp.agent_step_m, putback_m=exp.putback_m, goal_m=exp.putback_m, max_steps=max_steps,
                       jitter_m=exp.position_jitter_m, heading_noise=math.radians(exp.heading_noise_deg),
                       start_offset_m=float(exp.start_offset_m or 0.0),
                       rng=unit_stream(unit.seed, unit.route, unit.agent, "jitter"), on_putback=put_back)
    cpu = time.process_time() - cpu0 - shared
    row = {"route": unit.route, "agent": unit.agent, "seed": int(unit.seed), "axis": unit.axis,
           "level": unit.level, "position_jitter_m": exp.position_jitter_m,
           "heading_noise_deg": exp.heading_noise_deg, "start_offset_m": float(exp.start_offset_m or 0.0),
           "training_stride": exp.training_stride, "camera_height_m": float(setup.height),
           "routes_learned_together": len(unit.learned), "errors": int(res.errors),
           "error_free": int(res.errors == 0), "reached_nest": int(res.reached_nest), "steps": int(res.steps),
           "n_views": len(setup.xy), "cpu_s": cpu, "views_cpu_s": shared, "wall_s": time.perf_counter() - wall0,
           "path": res.path}
    return row


def with_condition(exp: RouteHomingConfig, db: dict, axis: str, level: Any) -> tuple[RouteHomingConfig, dict]:
    """``exp`` and the ``db`` node with sweep axis ``axis`` set to ``level`` (``db.camera_height_m`` for the eye height)."""
    exp = dataclasses.replace(exp, sweep={})
    if axis == "camera_height_m":
        return exp, {**db, "camera_height_m": float(level)}
    if axis:
        exp = dataclasses.replace(exp, **{axis: type(getattr(exp, axis))(level)})
    return exp, dict(db)
