"""``experiment=route_homing experiment.protocol=ardin2016``: the published route-following test.

The test of Ardin, Peng, Mangan, Lagogiannis & Webb 2016 (PLoS Comput. Biol.
12(2), e1004683, doi:10.1371/journal.pcbi.1004683) on the routes of the Seville
world, for every agent of ``experiment.agents`` (``bionav.route_agents``
plugins and homing methods), route and seed: the agent starts on the first
route view facing along the route, and each step
(:func:`bionav.evaluation.route.protocol_step`) scans ``+-scan_half_deg``
around its heading, walks ``agent_step_m`` along the least unfamiliar view
(:class:`bionav.evaluation.route_followers.FamiliarityFollower`; a homing
method homes to the view ahead instead,
:class:`~bionav.evaluation.route_followers.HomingFollower`), and farther than
``putback_m`` from the route it is put back on the nearest route view (an
error). Writes ``route_following.csv`` (one row per route, agent and seed),
metrics.json (:func:`ardin_metrics`), run.mcap (every path) and
``plots/world_routes.png`` (docs/worlds.md).

Conventions: positions in metres (world frame of the mesh), headings radians
CCW from world ``+x``, views as :func:`bionav.evaluation.route.scan_views`.
"""

from __future__ import annotations

import math
import time
import zlib
from typing import Any

import numpy as np
from omegaconf import DictConfig, OmegaConf

from bionav.errors import UserError
from bionav.evaluation.route_setup import RouteSetup, route_renderer, scan_renderer, travel_headings
from bionav.experiments.route_homing.config import RouteHomingConfig
from bionav.experiments.route_homing.shared import (
    PATH_SCHEMA,
    PATH_TOPIC,
    check_step_budget,
    route_setup,
    routes_file,
    routes_to_follow,
    with_protocol_step,
    write_rows,
)

#: the routes when ``experiment.routes`` is empty: Route1 of Ant1 .. Ant15, as the paper
ARDIN_ROUTES = tuple(f"Ant{a}_Route1" for a in range(1, 16))
ARDIN_CSV = "route_following.csv"
ARDIN_KEYS = ["route", "agent", "seed", "position_jitter_m", "errors", "error_free", "reached_nest", "steps",
              "n_views", "cpu_s"]


def _agent_kinds(agents: list[str]) -> dict[str, str]:
    """``{agent: "route_agent" | "homing"}``; an unknown name is a UserError listing both groups."""
    from bionav import registry

    route_agents = registry.plugins_of("route_agent", warn=False)
    homing = registry.plugins_of("homing", warn=False)
    kinds = {}
    for name in agents:
        if name in route_agents:
            kinds[name] = "route_agent"
        elif name in homing:
            kinds[name] = "homing"
        else:
            raise UserError(f"experiment.agents: unknown agent {name!r}; route agents: {', '.join(sorted(route_agents))}; "
                            f"homing methods (following the route by homing): {', '.join(sorted(homing))}.")
    if len(set(agents)) != len(agents):
        raise UserError(f"experiment.agents={list(agents)} names an agent twice; give each once.")
    return kinds


def _check_agent_params(exp: RouteHomingConfig, kinds: dict[str, str]) -> None:
    """Validate ``experiment.agent_params`` of the route agents before any work (key, value, range)."""
    from bionav.config import plugin_config

    for name, params in exp.agent_params.items():
        if name not in kinds:
            raise UserError(f"experiment.agent_params names {name!r}, which is not in experiment.agents="
                            f"{exp.agents}; add it there or drop its parameters.")
        if not isinstance(params, dict):
            raise UserError(f"experiment.agent_params.{name} must be a mapping of parameters, e.g. "
                            "+experiment.agent_params.mushroom_body.n_kc=5000.")
        if kinds[name] == "route_agent":
            plugin_config("route_agent", {"name": name, **params}, key=f"experiment.agent_params.{name}")


def _route_agent(name: str, exp: RouteHomingConfig, rng: np.random.Generator):
    from bionav.config import plugin_config

    params = dict(exp.agent_params.get(name) or {})
    cls, config = plugin_config("route_agent", {"name": name, **params}, key=f"experiment.agent_params.{name}")
    return cls(config, rng=rng)


def _homing_agent(name: str, cfg: DictConfig, ctx, exp: RouteHomingConfig, geometry):
    from omegaconf import open_dict

    from bionav.experiments.common import make_homing

    params = dict(exp.agent_params.get(name) or {})
    if str(cfg.homing.name) == name and not params:
        return make_homing(cfg, ctx, geometry)
    local = cfg.copy()
    with open_dict(local):
        local.homing = OmegaConf.create({"name": name, **params})
    return make_homing(local, ctx, geometry)


def _scan_renderer(setup: RouteSetup, exp: RouteHomingConfig, rng: np.random.Generator, *, half_deg=None):
    """The agents' preprocessed scan views (:func:`bionav.evaluation.route_setup.scan_renderer`) of ``exp``'s scan."""
    return scan_renderer(setup, rng, scan_step_deg=exp.scan_step_deg, supersample=exp.supersample,
                         scan_half_deg=exp.scan_half_deg if half_deg is None else half_deg, view_size=exp.view_size)


def _rng(seed: int, *parts: str) -> np.random.Generator:
    return np.random.default_rng(np.random.SeedSequence([int(seed), *(zlib.crc32(p.encode()) for p in parts)]))


def _follower(agent_name: str, kind: str, cfg: DictConfig, ctx, exp: RouteHomingConfig, setup: RouteSetup,
              route_heading: np.ndarray, seed: int, training: dict):
    """The heading chooser of one agent on one route and seed (``training`` caches the route's training views)."""
    from bionav.evaluation.route_followers import FamiliarityFollower, HomingFollower

    rng = _rng(seed, setup.name, agent_name)
    if kind == "route_agent":
        if "views" not in training:  # the same training views for every agent of this route and seed
            one = _scan_renderer(setup, exp, _rng(seed, setup.name, "training"), half_deg=0.0)
            training["views"] = np.concatenate([one(p, float(h))[0] for p, h in zip(setup.xy, route_heading)])
        agent = _route_agent(agent_name, exp, rng)
        agent.train(training["views"])
        return FamiliarityFollower(agent, _scan_renderer(setup, exp, rng))
    homing = _homing_agent(agent_name, cfg, ctx, exp, setup.geometry)
    return HomingFollower(homing, snapshots=setup.db.images, snapshot_headings=setup.heading,
                          render=route_renderer(setup, rng), window=exp.window, lookahead=exp.lookahead,
                          test_step_m=exp.test_step_m, max_turn=math.radians(exp.scan_half_deg))


def run(exp: RouteHomingConfig, ctx) -> dict[str, Any]:
    """``experiment.protocol=ardin2016``: the published route-following test for every agent, route and seed."""
    from bionav.evaluation.route import follow_route

    cfg = ctx.cfg
    exp = with_protocol_step(exp)
    routes = routes_to_follow(cfg, exp, list(ARDIN_ROUTES))
    kinds = _agent_kinds(exp.agents)
    _check_agent_params(exp, kinds)
    check_step_budget(routes, exp, routes_file(cfg))
    rows, paths, setups = [], {}, []
    timing = {a: [0.0, 0.0] for a in exp.agents}
    for name in ctx.progress(routes, desc="ardin2016 routes"):
        setup = route_setup(cfg, name, exp)
        name = setup.name
        setups.append(setup)
        length = float(np.linalg.norm(np.diff(setup.dense_xy, axis=0), axis=1).sum())
        max_steps = int(math.ceil(exp.max_steps_factor * length / exp.agent_step_m))
        route_heading = setup.heading if exp.training_heading == "recorded" else travel_headings(setup.xy)
        for seed in exp.seeds:
            training: dict = {}
            for agent_name in exp.agents:
                wall0, cpu0 = time.perf_counter(), time.process_time()
                follower = _follower(agent_name, kinds[agent_name], cfg, ctx, exp, setup, route_heading, seed,
                                     training)
                res = follow_route(follower, route_xy=setup.xy, route_heading=route_heading,
                                   nest_xy=setup.dense_xy[-1], step_m=exp.agent_step_m, putback_m=exp.putback_m,
                                   goal_m=exp.putback_m, max_steps=max_steps, jitter_m=exp.position_jitter_m,
                                   rng=_rng(seed, name, agent_name, "jitter"), on_putback=follower.reset)
                wall, cpu = time.perf_counter() - wall0, time.process_time() - cpu0
                timing[agent_name][0] += wall
                timing[agent_name][1] += cpu
                rows.append({"route": name, "agent": agent_name, "seed": int(seed),
                             "position_jitter_m": exp.position_jitter_m, "errors": int(res.errors),
                             "error_free": int(res.errors == 0), "reached_nest": int(res.reached_nest),
                             "steps": int(res.steps), "n_views": len(setup.xy), "cpu_s": cpu})
                if seed == exp.seeds[0]:
                    paths[(name, agent_name)] = res.path
                ctx.log.write(PATH_TOPIC, {"route": name, "method": agent_name, "xy": res.path.tolist(),
                                           "completed": bool(res.reached_nest)},
                              schema_name="bionav.RoutePath", schema=PATH_SCHEMA)
    routes = [s.name for s in setups]  # db=bag: the drive's own name
    write_rows(ctx.dir / ARDIN_CSV, rows, ARDIN_KEYS)
    if exp.plots:
        from bionav.experiments.route_homing.plots import plot_world_routes

        plot_world_routes(ctx.plots / "world_routes.png", setups[0].world, setups, paths)
    return ardin_metrics(rows, routes=routes, agents=exp.agents, seeds=exp.seeds, timing=timing,
                         extra={"db": str(cfg.db.name), "protocol": "ardin2016",
                                "position_jitter_m": exp.position_jitter_m, "step_m": exp.agent_step_m})


def ardin_metrics(rows: list[dict], *, routes: list[str], agents: list[str], seeds: list[int],
                  timing: dict | None = None, extra: dict | None = None) -> dict[str, Any]:
    """Flat metrics of the ardin2016 rows (one per route, agent and seed).

    Per agent ``a``: ``errors_per_route_<a>`` (median over routes x seeds), ``errors_per_route_q25_<a>``,
    ``errors_per_route_q75_<a>``, ``errors_per_route_mean_<a>``; ``error_free_routes_<a>`` (error-free
    routes out of ``n_routes``, mean over seeds); ``reached_nest_<a>`` (fraction of runs);
    ``errors_by_route_<a>`` and ``reached_nest_by_route_<a>`` (``{route: [per seed]}``); ``wall_s_<a>``, ``cpu_s_<a>``.
    """
    m: dict[str, Any] = dict(extra or {})
    m.update({"routes": routes, "n_routes": len(routes), "agents": agents, "seeds": seeds})
    for a in agents:
        mine = [r for r in rows if r["agent"] == a]
        err = np.array([r["errors"] for r in mine], np.float64)
        m[f"errors_per_route_{a}"] = float(np.median(err))
        m[f"errors_per_route_q25_{a}"] = float(np.percentile(err, 25))
        m[f"errors_per_route_q75_{a}"] = float(np.percentile(err, 75))
        m[f"errors_per_route_mean_{a}"] = float(err.mean())
        m[f"error_free_routes_{a}"] = float(np.mean([sum(r["errors"] == 0 for r in mine if r["seed"] == s)
                                                     for s in seeds]))
        m[f"reached_nest_{a}"] = float(np.mean([r["reached_nest"] for r in mine]))
        m[f"errors_by_route_{a}"] = {rt: [r["errors"] for r in mine if r["route"] == rt] for rt in routes}
        m[f"reached_nest_by_route_{a}"] = {rt: [bool(r["reached_nest"]) for r in mine if r["route"] == rt]
                                           for rt in routes}
        if timing is not None:
            m[f"wall_s_{a}"], m[f"cpu_s_{a}"] = (float(v) for v in timing[a])
    return m


__all__ = ["ARDIN_ROUTES", "ardin_metrics", "run"]
