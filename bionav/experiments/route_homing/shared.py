"""What both route-following protocols of ``experiment=route_homing`` share: the routes' set-up from the run's
config, the step budget, the logged paths and the CSV rows.
"""

from __future__ import annotations

import math
from typing import Any

from omegaconf import DictConfig, OmegaConf

from bionav.errors import UserError
from bionav.evaluation.route_setup import RouteSetup, setup_route
from bionav.experiments.route_homing.config import RouteHomingConfig
from bionav.files import write_csv_atomic

#: what each protocol sets when the key is null: the agent's step and its start offset from the route, metres
PROTOCOL_DEFAULTS = {"bionav": {"agent_step_m": 0.05, "start_offset_m": 0.2},
                     "ardin2016": {"agent_step_m": 0.1, "start_offset_m": 0.0}}
#: most steps one agent may take on one route (``max_steps_factor`` x length / step)
MAX_STEPS_PER_ROUTE = 20_000
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


def route_setup(cfg: DictConfig, name: str) -> RouteSetup:
    """Route ``name`` of the run's route database (``db=seville_route``), its snapshots rendered or cached."""
    node = OmegaConf.to_container(cfg.db, resolve=True)
    if node.get("source") != "route":
        raise UserError(f"experiment=route_homing needs a route database (db=seville_route), not db={node.get('name')}.")
    return setup_route(node, name, cache_dir=str(cfg.cache_dir))


def routes_file(cfg: DictConfig):
    """``db.routes_path`` (None: the packaged Seville routes)."""
    return OmegaConf.select(cfg, "db.routes_path", default=None)


def check_step_budget(routes: list[str], exp: RouteHomingConfig, routes_path=None) -> None:
    """Refuse, before any work, a step so small that one route would take more than :data:`MAX_STEPS_PER_ROUTE` steps."""
    from bionav.db.mesh import load_route

    for name in routes:
        length = load_route(name, routes_path).length_m
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
