"""What both route-following protocols of ``experiment=route_homing`` share: the routes to follow and their set-up
from the run's config (a route database, or with ``db=bag`` a robot's drive), the step budget, the logged paths and
the CSV rows.

With ``db=bag`` (docs/ros.md) the route is the bag's drive and the world the agents walk in is its recorded views
(:func:`bionav.evaluation.route_setup.setup_bag_route`). It is followed with the published protocol
(``experiment.protocol=ardin2016``: put back on the route beyond ``putback_m``, so the agents stay where views were
recorded); the ``bionav`` protocol, which measures views beside the route, is refused.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from omegaconf import DictConfig, OmegaConf

from bionav.errors import UserError
from bionav.evaluation.route_setup import RouteSetup, setup_bag_route, setup_route
from bionav.experiments.route_homing.config import RouteHomingConfig
from bionav.files import write_csv_atomic

#: what each protocol sets when the key is null: the agent's step and its start offset from the route, metres
PROTOCOL_DEFAULTS = {"bionav": {"agent_step_m": 0.05, "start_offset_m": 0.2},
                     "ardin2016": {"agent_step_m": 0.1, "start_offset_m": 0.0}}
#: most steps one agent may take on one route (``max_steps_factor`` x length / step)
MAX_STEPS_PER_ROUTE = 20_000
#: the route name :func:`routes_to_follow` gives a bag's drive until it is read (then :attr:`RouteSetup.name`)
BAG_DRIVE = "drive"
PATH_TOPIC = "/route_homing/agent_path"
PATH_SCHEMA = {
    "type": "object",
    "properties": {
        "route": {"type": "string"},
        "method": {"type": "string"},
        "xy": {"type": "array", "description": "agent positions (x, y) in metres, world frame"},
        "completed": {"type": "boolean"},
    },
}


def with_protocol_defaults(exp: RouteHomingConfig) -> RouteHomingConfig:
    """``exp`` with ``agent_step_m`` and ``start_offset_m`` defaulting to its protocol's (:data:`PROTOCOL_DEFAULTS`)."""
    import dataclasses

    unset = {k: v for k, v in PROTOCOL_DEFAULTS[exp.protocol].items() if getattr(exp, k) is None}
    return dataclasses.replace(exp, **unset) if unset else exp


def is_bag(cfg: DictConfig) -> bool:
    """Whether the run's database is a ROS bag (``db=bag``)."""
    return OmegaConf.select(cfg, "db.source", default=None) == "bag"


def routes_to_follow(cfg: DictConfig, exp: RouteHomingConfig, default: list[str]) -> list[str]:
    """The routes to follow: ``experiment.routes``, else ``default``; with ``db=bag`` the bag's one drive."""
    if is_bag(cfg):
        _check_bag_routes(exp)
        return [BAG_DRIVE]
    return list(exp.routes or default)


def _check_bag_routes(exp: RouteHomingConfig) -> None:
    """With a bag the route is its drive (``experiment.routes``, Seville routes, must stay empty), followed by the
    published protocol: the ``bionav`` protocol starts beside the route and measures views off it, which a
    recorded drive does not hold (the nearest recorded view would stand for them)."""
    if exp.protocol != "ardin2016":
        raise UserError("with db=bag follow the drive with the published protocol: experiment.protocol=ardin2016 (the "
                        "bionav protocol tests views beside the route, and a recorded drive has views only along it).")
    if exp.routes:
        raise UserError(f"experiment.routes={list(exp.routes)} names routes of the Seville world, but with db=bag the "
                        "route is the bag's drive (db.image_topic, db.pose_topic); drop experiment.routes.")


def route_setup(cfg: DictConfig, name: str, exp: RouteHomingConfig) -> RouteSetup:
    """Route ``name`` of the run's route database (``db=seville_route``), its snapshots rendered or cached; with
    ``db=bag`` the bag's drive (:func:`setup_bag_route`), its length checked against the step budget once read."""
    node = OmegaConf.to_container(cfg.db, resolve=True)
    if is_bag(cfg):
        setup = setup_bag_route(node)
        check_route_length(setup.name, float(np.linalg.norm(np.diff(setup.dense_xy, axis=0), axis=1).sum()), exp)
        return setup
    if node.get("source") != "route":
        raise UserError(f"experiment=route_homing needs a route database (db=seville_route) or a robot's drive "
                        f"(db=bag), not db={node.get('name')}.")
    return setup_route(node, name, cache_dir=str(cfg.cache_dir))


def routes_file(cfg: DictConfig):
    """``db.routes_path`` (None: the packaged Seville routes)."""
    return OmegaConf.select(cfg, "db.routes_path", default=None)


def check_step_budget(routes: list[str], exp: RouteHomingConfig, routes_path=None) -> None:
    """Refuse, before any work, a step so small that one route would take more than :data:`MAX_STEPS_PER_ROUTE` steps."""
    from bionav.db.mesh import load_route

    for name in routes:
        if name != BAG_DRIVE:  # db=bag's drive is checked once it is read (route_setup)
            check_route_length(name, load_route(name, routes_path).length_m, exp)


def check_route_length(name: str, length: float, exp: RouteHomingConfig) -> None:
    """Refuse a route of ``length`` metres that would take more than :data:`MAX_STEPS_PER_ROUTE` agent steps."""
    steps = math.ceil(exp.max_steps_factor * length / exp.agent_step_m)
    if steps > MAX_STEPS_PER_ROUTE:
        smallest = exp.max_steps_factor * length / MAX_STEPS_PER_ROUTE
        raise UserError(f"experiment.agent_step_m={exp.agent_step_m:g} allows {steps} steps on {name} "
                        f"({length:.2f} m x max_steps_factor={exp.max_steps_factor:g}), more than the "
                        f"{MAX_STEPS_PER_ROUTE} steps a route may take; use experiment.agent_step_m >= "
                        f"{math.ceil(smallest * 1e4) / 1e4:g} (the ardin2016 protocol steps 0.1 m).")


def write_rows(path, rows: list[dict], keys: list[str]) -> None:
    """One CSV row per dict (floats with 6 decimals; keys not in ``keys`` left out)."""
    write_csv_atomic(path, keys, ([_cell(r.get(k, "")) for k in keys] for r in rows))


def _cell(value: Any) -> Any:
    return f"{value:.6f}" if isinstance(value, float) else value
