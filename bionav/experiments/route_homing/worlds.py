"""A route in a second world: ``experiment.worlds``, the ``world`` axis of the robustness sweep (``ardin2016``).

``experiment.worlds`` maps a label to a world: a ``db`` preset (``db: bag`` or ``db: seville_route``; default the
run's own) with any of its keys changed, and for a mesh world the routes to follow there (``routes``; default
the run's). Each world is one condition of the sweep (axis ``world``, level = its label): every agent follows
that world's routes under the same protocol, and ``robustness.csv`` and ``plots/robustness_world.png`` set it
beside the run's own world (level :func:`world_label` of the run's ``db``)::

    +experiment.worlds.pillars={db:bag,path:DRIVE,image_topic:/camera/image,pose_topic:/odom}
    +experiment.worlds.other={path:WORLD.mat,routes_path:ROUTES.mat,routes:[Ant1_Route1]}

A bag's world is its drive (:func:`bionav.evaluation.route_setup.setup_bag_route`: the route is the drive, the
views the recorded ones); a mesh world (``db.path=FILE``, ``db.routes_path=FILE``) renders the routes as the
Seville world does (:func:`bionav.evaluation.route_setup.setup_route`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from omegaconf import DictConfig, OmegaConf

from bionav.errors import UserError
from bionav.experiments.route_homing.config import RouteHomingConfig

WORLD_AXIS = "world"


def world_label(db: dict) -> str:
    """The name of the world of a ``db`` node: ``db.world`` (a packaged world), else the stem of ``db.path``, else
    ``db.name``."""
    if db.get("source") != "bag" and db.get("world"):
        return str(db["world"])
    if db.get("path"):
        return Path(str(db["path"])).stem or str(db.get("name"))
    return str(db.get("name"))


def world_node(cfg: DictConfig, label: str, entry: dict) -> dict:
    """The checked ``db`` node of world ``label``: its preset (``entry["db"]``, default the run's ``db``) with the
    entry's keys; ``${data_dir}`` resolved. A bad key or value is a UserError naming ``experiment.worlds.<label>``."""
    from bionav.db.loading import as_database_config
    from bionav.experiments.common import db_preset

    entry = {k: v for k, v in entry.items() if k != "routes"}
    preset = str(entry.pop("db", None) or cfg.db.name)
    node = db_preset(preset, key=f"experiment.worlds.{label}.db")
    node.update(entry)
    for key, value in node.items():
        if isinstance(value, str) and "${data_dir}" in value:
            node[key] = value.replace("${data_dir}", str(cfg.data_dir))
    if node.get("source") not in ("route", "bag"):
        raise UserError(f"experiment.worlds.{label}: db={preset} is not a route world; give db:seville_route (a "
                        "mesh world with routes: path, routes_path, routes) or db:bag (a robot's drive).")
    try:
        as_database_config(dict(node))
    except UserError as exc:
        raise UserError(f"experiment.worlds.{label}: {exc}") from None
    return node


def world_routes(node: dict, entry: dict, *, default: list[str], cache_dir: str, exp: RouteHomingConfig) -> list[str]:
    """The routes followed in a world: a bag's drive (read here, its length checked), else ``entry["routes"]`` or
    ``default`` (their lengths checked against the step budget)."""
    from bionav.experiments.route_homing.shared import check_route_length, check_step_budget
    from bionav.experiments.route_homing.units import frozen, route_of

    if node.get("source") == "bag":
        setup = route_of(frozen(node), cache_dir, "drive")
        check_route_length(setup.name, float(np.linalg.norm(np.diff(setup.dense_xy, axis=0), axis=1).sum()), exp)
        return [setup.name]
    routes = list(entry.get("routes") or default)
    check_step_budget(routes, exp, node.get("routes_path"))
    return routes


def worlds_of(cfg: DictConfig, exp: RouteHomingConfig, *, default: list[str]) -> dict[str, tuple[dict, list[str]]]:
    """``{label: (db node, routes)}`` of every world of ``experiment.worlds``, checked before any work."""
    out = {}
    for label, entry in exp.worlds.items():
        entry = OmegaConf.to_container(entry, resolve=True) if isinstance(entry, DictConfig) else dict(entry)
        node = world_node(cfg, label, entry)
        out[label] = (node, world_routes(node, entry, default=default, cache_dir=str(cfg.cache_dir), exp=exp))
    return out
