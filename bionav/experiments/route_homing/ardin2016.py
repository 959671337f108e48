"""``experiment=route_homing experiment.protocol=ardin2016``: the published route-following test, and beyond it.

The test of Ardin, Peng, Mangan, Lagogiannis & Webb 2016 (PLoS Comput. Biol.
12(2), e1004683, doi:10.1371/journal.pcbi.1004683) on the routes of a mesh
world, for every agent of ``experiment.agents`` (``bionav.route_agents``
plugins and homing methods), route and seed: the agent starts on the first
route view facing along the route, and each step
(:func:`bionav.evaluation.route.protocol_step`) scans ``+-scan_half_deg``
around its heading, walks ``agent_step_m`` along the least unfamiliar view
(:class:`bionav.evaluation.route_followers.FamiliarityFollower`; a homing
method homes to the view ahead instead,
:class:`~bionav.evaluation.route_followers.HomingFollower`), and farther than
``putback_m`` from the route it is put back on the nearest route view (an
error). Each agent, route and seed is one unit of work
(:mod:`bionav.experiments.route_homing.units`), run on ``workers`` processes.

``experiment.sweep`` adds robustness conditions no paper reports (position and
heading noise, start offsets, sparser training views, eye height, routes
learned together): every level of every axis is a condition run like the run
itself (:mod:`bionav.experiments.route_homing.robustness`).

Writes ``route_following.csv`` (one row per route, agent, seed and condition),
``errors_per_route.csv`` and ``plots/errors_per_route.png`` (the published
figure's boxplots, for the run as configured), metrics.json
(:func:`ardin_metrics`), run.mcap (every path), ``plots/world_routes.png``, and
with a sweep ``robustness.csv`` and ``plots/robustness_<axis>.png`` (docs/worlds.md).

Conventions: positions in metres (world frame of the mesh), headings radians
CCW from world ``+x``, views as :func:`bionav.evaluation.route.scan_views`.
"""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path
from typing import Any, Iterator

import numpy as np
from omegaconf import DictConfig, OmegaConf

from bionav.errors import UserError
from bionav.experiments.route_homing import robustness
from bionav.experiments.route_homing.config import RouteHomingConfig
from bionav.experiments.route_homing.shared import (
    PATH_SCHEMA,
    PATH_TOPIC,
    check_route_length,
    check_step_budget,
    is_bag,
    routes_file,
    routes_to_follow,
    with_protocol_defaults,
    write_rows,
)
from bionav.experiments.route_homing.units import Unit, frozen, route_of, run_unit, with_condition
from bionav.experiments.route_homing.worlds import WORLD_AXIS, world_label, worlds_of

#: the routes when ``experiment.routes`` is empty: Route1 of Ant1 .. Ant15, as the paper
ARDIN_ROUTES = tuple(f"Ant{a}_Route1" for a in range(1, 16))
ARDIN_CSV = "route_following.csv"
PER_ROUTE_CSV = "errors_per_route.csv"
ARDIN_KEYS = ["route", "agent", "seed", "axis", "level", "position_jitter_m", "heading_noise_deg", "start_offset_m",
              "training_stride", "camera_height_m", "routes_learned_together", "errors", "error_free", "reached_nest",
              "steps", "n_views", "cpu_s", "views_cpu_s", "unit"]
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


def _homing_nodes(name: str, cfg: DictConfig, exp: RouteHomingConfig) -> tuple[str, str]:
    """The ``homing`` and ``signature`` nodes of homing agent ``name`` (:func:`units.frozen`), checked here."""
    from bionav.config import plugin_config

    params = dict(exp.agent_params.get(name) or {})
    if str(cfg.homing.name) == name and not params:
        node = OmegaConf.to_container(cfg.homing, resolve=True)
    else:
        node = {"name": name, **params}
    plugin_config("homing", node, key=f"experiment.agent_params.{name}" if params else "homing")
    signature = OmegaConf.to_container(cfg.signature, resolve=True) if cfg.get("signature") else None
    return frozen(node), frozen(signature)


def _units(exp: RouteHomingConfig, cfg: DictConfig, routes: list[str], kinds: dict[str, str]) -> list[Unit]:
    """Every unit of the run: the run as configured, then each sweep level that differs from it, then each world."""
    db = OmegaConf.to_container(cfg.db, resolve=True)
    if db.get("source") not in ("route", "bag"):
        raise UserError(f"experiment=route_homing needs a route database (db=seville_route) or a robot's drive "
                        f"(db=bag), not db={db.get('name')}.")
    homing = {a: _homing_nodes(a, cfg, exp) for a, k in kinds.items() if k == "homing"}
    worlds = worlds_of(cfg, exp, default=list(exp.routes or ARDIN_ROUTES))
    units = []
    for axis, level in robustness.conditions(exp, db):
        if axis == WORLD_AXIS:
            (cdb, here), cexp = worlds[level], dataclasses.replace(exp, sweep={}, worlds={})
        else:
            (cexp, cdb), here = with_condition(exp, db, axis, level), routes
        for i, route in enumerate(here):
            learned = tuple(here[(i + k) % len(here)] for k in range(min(cexp.routes_learned_together, len(here))))
            for seed in exp.seeds:
                for agent in exp.agents:
                    if kinds[agent] == "homing" and axis == "routes_learned_together":
                        continue  # a homing follower learns its own route's views only
                    units.append(Unit(cexp, frozen(cdb), str(cfg.cache_dir), route, learned, int(seed), agent,
                                      kinds[agent], homing.get(agent), axis,
                                      level if axis == WORLD_AXIS else float(level) if axis else None,
                                      keep_path=not axis and seed == exp.seeds[0]))
    return units


def _group_rows(units: list[Unit]) -> list[dict]:
    return [run_unit(u) for u in units]


def unit_groups(units: list[Unit]) -> list[list[Unit]]:
    """``units`` in runs of one route, seed and condition (the agents that share their training views: one task)."""
    groups: list[list[Unit]] = []
    for u in units:
        if groups and (groups[-1][0].route, groups[-1][0].seed, groups[-1][0].db, groups[-1][0].exp) == \
                (u.route, u.seed, u.db, u.exp):
            groups[-1].append(u)
        else:
            groups.append([u])
    return groups


def _run_units(units: list[Unit], ctx, workers: int) -> Iterator[dict]:
    """The rows of ``units`` in order: here, or on a pool of ``workers`` processes by route, seed and condition."""
    if workers <= 1:
        yield from (run_unit(u) for u in units)
        return
    from bionav.experiments.common import worker_pool

    with worker_pool(workers) as pool:
        for rows in pool.imap(_group_rows, unit_groups(units), chunksize=1):
            yield from rows


def _routes_of_run(exp: RouteHomingConfig, cfg: DictConfig, db: dict) -> tuple[list[str], dict[str, str]]:
    """The routes to follow (a bag's drive read here, by its own name) and the agents' kinds, checked before any work."""
    routes = routes_to_follow(cfg, exp, list(ARDIN_ROUTES))
    kinds = _agent_kinds(exp.agents)
    _check_agent_params(exp, kinds)
    check_step_budget(routes, exp, routes_file(cfg))
    if is_bag(cfg):  # the drive read once per process (units.route_of), its length checked; its own name in the rows
        setup = route_of(frozen(db), str(cfg.cache_dir), routes[0])
        check_route_length(setup.name, float(np.linalg.norm(np.diff(setup.dense_xy, axis=0), axis=1).sum()), exp)
        routes = [setup.name]
    return routes, kinds


def run(exp: RouteHomingConfig, ctx) -> dict[str, Any]:
    """``experiment.protocol=ardin2016``: the published route-following test for every agent, route, seed and condition.

    With ``experiment.block=[i,n]`` the run is task ``i`` of ``n``: every n-th group of units (one route, seed and
    condition: :func:`unit_groups`) from the i-th; it writes its rows (``route_following.csv``, with each row's
    ``unit`` index in the whole run) and paths, and :func:`bionav.experiments.route_homing.merge.merge` joins the
    tasks into the whole run's files (``python -m bionav.experiments.merge OUT TASK_DIR...``).
    """
    from bionav.experiments.tasks import block_of
    from bionav.machine import usable_cpus

    cfg = ctx.cfg
    exp = with_protocol_defaults(exp)
    db = OmegaConf.to_container(cfg.db, resolve=True)
    routes, kinds = _routes_of_run(exp, cfg, db)
    units = _units(exp, cfg, routes, kinds)
    groups = unit_groups(units)
    index = {id(u): k for k, u in enumerate(units)}
    task = block_of(exp.block, range(len(groups)), what="group of units (one route, seed and condition)")
    mine = [u for g in task for u in groups[g]]
    workers = max(1, min(int(cfg.get("workers") or 1), usable_cpus(), len(mine)))
    rows, paths = [], {}
    wall0 = time.perf_counter()
    desc = f"ardin2016: {len(routes)} routes x {len(exp.agents)} agents x {len(exp.seeds)} seeds" + \
        (f" x {len(robustness.conditions(exp, db))} conditions" if exp.sweep or exp.worlds else "")
    for unit, row in zip(mine, ctx.progress(_run_units(mine, ctx, workers), desc=desc, total=len(mine))):
        path = row.pop("path")
        ctx.log.write(PATH_TOPIC, {"route": row["route"], "method": row["agent"], "xy": path.tolist(),
                                   "completed": bool(row["reached_nest"])},
                      schema_name="bionav.RoutePath", schema=PATH_SCHEMA)
        if unit.keep_path:
            paths[(row["route"], row["agent"])] = path
        rows.append({**row, "unit": index[id(unit)]})
    run_info = {"db": str(cfg.db.name), "protocol": "ardin2016", "workers": workers,
                "position_jitter_m": exp.position_jitter_m, "step_m": exp.agent_step_m,
                "wall_s": time.perf_counter() - wall0}
    if exp.block is not None:
        write_rows(ctx.dir / ARDIN_CSV, rows, ARDIN_KEYS)
        return {**run_info, "block": [int(v) for v in exp.block], "n_units": len(units), "task_units": len(mine),
                "routes": routes, "agents": list(exp.agents), "seeds": list(exp.seeds), "kinds": kinds,
                "run_db": db, "cache_dir": str(cfg.cache_dir), "settings": {**dataclasses.asdict(exp), "block": None}}
    return write_ardin_outputs(ctx.dir, rows, paths, exp=exp, db=db, cache_dir=str(cfg.cache_dir), routes=routes,
                               kinds=kinds, run_info=run_info)


def write_ardin_outputs(out: Path, rows: list[dict], paths: dict, *, exp: RouteHomingConfig, db: dict, cache_dir: str,
                        routes: list[str], kinds: dict[str, str], run_info: dict) -> dict[str, Any]:
    """The whole run's files in ``out`` from its rows (in unit order) and the paths of the run as configured (first
    seed): ``route_following.csv``, ``errors_per_route.csv``, the plots, ``robustness.csv``; the metrics."""
    from types import SimpleNamespace

    write_rows(out / ARDIN_CSV, rows, ARDIN_KEYS)
    base = [r for r in rows if not r["axis"]]
    table = per_route_table(base, routes=routes, agents=exp.agents, seeds=exp.seeds)
    write_rows(out / PER_ROUTE_CSV, table, ["route", "seed", *exp.agents])
    if exp.plots:
        from bionav.experiments.route_homing.plots import plot_errors_per_route, plot_world_routes

        (out / "plots").mkdir(parents=True, exist_ok=True)
        setups = [route_of(frozen(db), cache_dir, r) for r in routes]
        plot_world_routes(out / "plots" / "world_routes.png", setups[0].world, setups, paths)
        plot_errors_per_route(out / "plots" / "errors_per_route.png", table, list(exp.agents),
                              title=f"{len(routes)} routes x {len(exp.seeds)} seed(s), protocol of Ardin et al. 2016",
                              labels={a: f"{a} (homing)" for a, k in kinds.items() if k == "homing"})
    metrics = ardin_metrics(base, routes=routes, agents=exp.agents, seeds=exp.seeds, extra=run_info)
    if exp.sweep or exp.worlds:
        metrics.update(robustness.write(SimpleNamespace(dir=out, plots=out / "plots"), rows, exp=exp,
                                        agents=list(exp.agents), base_world=world_label(db)))
    return metrics


def per_route_table(rows: list[dict], *, routes: list[str], agents: list[str], seeds: list[int]) -> list[dict]:
    """One row per route and seed with each agent's errors (integers): the data of ``plots/errors_per_route.png``."""
    errors = {(r["route"], r["seed"], r["agent"]): int(r["errors"]) for r in rows}
    return [{"route": route, "seed": int(seed), **{a: errors[(route, int(seed), a)] for a in agents}}
            for route in routes for seed in seeds]


def _count(value: float) -> float | int:
    """A statistic of counts as an int when it is whole (a median of 0 prints as 0, not 0.0000)."""
    return int(value) if float(value).is_integer() else float(value)


def ardin_metrics(rows: list[dict], *, routes: list[str], agents: list[str], seeds: list[int],
                  extra: dict | None = None) -> dict[str, Any]:
    """Flat metrics of the ardin2016 rows (one per route, agent and seed).

    Per agent ``a``: ``errors_per_route_<a>`` (median over routes x seeds), ``errors_per_route_q25_<a>``,
    ``errors_per_route_q75_<a>``, ``errors_per_route_mean_<a>``; ``error_free_routes_<a>`` (error-free
    routes out of ``n_routes``, mean over seeds); ``reached_nest_<a>`` (fraction of runs);
    ``errors_by_route_<a>`` and ``reached_nest_by_route_<a>`` (``{route: [per seed]}``); ``wall_s_<a>``,
    ``cpu_s_<a>`` (summed over the runs) and ``cpu_s_per_route_<a>`` (their mean). Counts and
    statistics of counts that are whole are ints.
    """
    m: dict[str, Any] = dict(extra or {})
    m.update({"routes": routes, "n_routes": len(routes), "agents": agents, "seeds": seeds})
    for a in agents:
        mine = [r for r in rows if r["agent"] == a]
        err = np.array([r["errors"] for r in mine], np.float64)
        m[f"errors_per_route_{a}"] = _count(np.median(err))
        m[f"errors_per_route_q25_{a}"] = _count(np.percentile(err, 25))
        m[f"errors_per_route_q75_{a}"] = _count(np.percentile(err, 75))
        m[f"errors_per_route_mean_{a}"] = float(err.mean())
        m[f"error_free_routes_{a}"] = _count(np.mean([sum(r["errors"] == 0 for r in mine if r["seed"] == s)
                                                      for s in seeds]))
        m[f"reached_nest_{a}"] = float(np.mean([r["reached_nest"] for r in mine]))
        m[f"errors_by_route_{a}"] = {rt: [r["errors"] for r in mine if r["route"] == rt] for rt in routes}
        m[f"reached_nest_by_route_{a}"] = {rt: [bool(r["reached_nest"]) for r in mine if r["route"] == rt]
                                           for rt in routes}
        m[f"wall_s_{a}"] = float(sum(r.get("wall_s", 0.0) for r in mine))
        m[f"cpu_s_{a}"] = float(sum(r["cpu_s"] for r in mine))
        m[f"cpu_s_per_route_{a}"] = m[f"cpu_s_{a}"] / max(1, len(mine))
    return m


__all__ = ["ARDIN_ROUTES", "ardin_metrics", "per_route_table", "run", "unit_groups", "write_ardin_outputs"]
