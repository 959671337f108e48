"""Robustness of route following beyond the published test: ``experiment.sweep`` of ``protocol=ardin2016``.

Each level of each axis (:data:`bionav.experiments.route_homing.config.SWEEP_AXES`) is a
condition: the run's settings with that one key changed. A level equal to the run's own
setting is the run itself (computed once). :func:`conditions` lists them; :func:`write`
summarises the rows per axis, level and agent into ``robustness.csv`` and draws
``plots/robustness_<axis>.png``.

Axes, units and what they change (none is in Ardin et al. 2016):

* ``position_jitter_m`` (m): Gaussian noise on the position after every step;
* ``heading_noise_deg`` (deg): Gaussian noise on every heading chosen;
* ``start_offset_m`` (m): the start lies this far left of the first route view;
* ``training_stride``: the agents learn every k-th route view (0.1 m apart at ``db.step_m=0.1``);
* ``camera_height_m`` (m): the eye height over the terrain (``db.camera_height_m``), training and test;
* ``routes_learned_together``: the familiarity agents learn this many routes' views at once (capacity);
* ``world`` (``experiment.worlds``, :mod:`bionav.experiments.route_homing.worlds`): the routes of a second world
  (a mesh world with routes, or a robot's drive from a bag), its level the world's label.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from bionav.experiments.route_homing.config import RouteHomingConfig, sweep_level

ROBUSTNESS_CSV = "robustness.csv"
ROBUSTNESS_KEYS = ["axis", "level", "agent", "runs", "errors_median", "errors_q25", "errors_q75", "errors_mean",
                   "error_free_routes", "reached_nest", "cpu_s_per_route"]
#: the unit of each axis in the figures
AXIS_UNITS = {"position_jitter_m": "m, std per axis", "heading_noise_deg": "deg, std", "start_offset_m": "m, left",
              "training_stride": "every k-th view", "camera_height_m": "m", "routes_learned_together": "routes",
              "world": ""}


def base_level(exp: RouteHomingConfig, db: dict, axis: str) -> float:
    """The run's own setting of ``axis`` (``db.camera_height_m`` for the eye height)."""
    value = db.get("camera_height_m") if axis == "camera_height_m" else getattr(exp, axis)
    return float(value or 0.0)


def conditions(exp: RouteHomingConfig, db: dict) -> list[tuple[str, Any]]:
    """``[("", nan), (axis, level), ..., ("world", label), ...]``: the run as configured, every sweep level that
    differs from it, then every world of ``experiment.worlds``."""
    out: list[tuple[str, Any]] = [("", math.nan)]
    for axis, levels in exp.sweep.items():
        for level in levels:
            value = float(sweep_level(exp, axis, level))
            if value != base_level(exp, db, axis) and (axis, value) not in out:
                out.append((axis, value))
    return out + [("world", label) for label in exp.worlds]


def axis_levels(exp: RouteHomingConfig, *, base_db: dict, base_world: str) -> list[tuple[str, list, Any]]:
    """``[(axis, levels in order, the run's own level), ...]``: each numeric axis of the sweep, then ``world`` (the
    run's world ``base_world`` first, then ``experiment.worlds`` in order) when there are worlds."""
    out = [(axis, sorted({float(sweep_level(exp, axis, v)) for v in levels}), base_level(exp, base_db, axis))
           for axis, levels in exp.sweep.items()]
    if exp.worlds:
        out.append(("world", [base_world, *exp.worlds], base_world))
    return out


def _rows_at(rows: list[dict], axis: str, level: Any, base: Any) -> list[dict]:
    if level == base:
        return [r for r in rows if not r["axis"]]
    if axis == "world":
        return [r for r in rows if r["axis"] == axis and str(r["level"]) == level]
    return [r for r in rows if r["axis"] == axis and float(r["level"]) == level]


def summary(rows: list[dict], *, exp: RouteHomingConfig, agents: list[str], base_world: str = "") -> list[dict]:
    """One row per axis, level and agent: errors per route (median, quartiles, mean), error-free routes, nest arrivals.

    ``error_free_routes`` is the number of error-free routes per seed, averaged over seeds;
    ``reached_nest`` the fraction of runs that reached the nest; ``cpu_s_per_route`` the agent's
    mean CPU seconds per run. Homing followers have no ``routes_learned_together`` rows (they
    learn their own route's views only). The ``world`` axis' levels are labels: ``base_world`` (the run's own world,
    :func:`bionav.experiments.route_homing.worlds.world_label`), then those of ``experiment.worlds``.
    """
    base_rows = [r for r in rows if not r["axis"]]
    base_db = {"camera_height_m": base_rows[0]["camera_height_m"]} if base_rows else {}
    out = []
    for axis, levels, base in axis_levels(exp, base_db=base_db, base_world=base_world):
        for level in levels:
            here = _rows_at(rows, axis, level, base)
            for a in agents:
                mine = [r for r in here if r["agent"] == a]
                if not mine:
                    continue
                err = np.array([r["errors"] for r in mine], np.float64)
                seeds = sorted({r["seed"] for r in mine})
                out.append({"axis": axis, "level": level, "agent": a, "runs": len(mine),
                            "errors_median": float(np.median(err)), "errors_q25": float(np.percentile(err, 25)),
                            "errors_q75": float(np.percentile(err, 75)), "errors_mean": float(err.mean()),
                            "error_free_routes": float(np.mean([sum(r["errors"] == 0 for r in mine if r["seed"] == s)
                                                                for s in seeds])),
                            "reached_nest": float(np.mean([r["reached_nest"] for r in mine])),
                            "cpu_s_per_route": float(np.mean([r["cpu_s"] for r in mine]))})
    return out


def write(ctx, rows: list[dict], *, exp: RouteHomingConfig, agents: list[str], base_world: str = "") -> dict[str, Any]:
    """``robustness.csv`` and ``plots/robustness_<axis>.png``; the metrics they add (the axes and their levels)."""
    from bionav.experiments.route_homing.shared import write_rows

    table = summary(rows, exp=exp, agents=agents, base_world=base_world)
    write_rows(ctx.dir / ROBUSTNESS_CSV, table, ROBUSTNESS_KEYS)
    axes = axis_levels(exp, base_db={}, base_world=base_world)
    if exp.plots:
        from bionav.experiments.route_homing.plots import plot_robustness

        for axis, levels, _base in axes:
            plot_robustness(ctx.plots / f"robustness_{axis}.png", [r for r in table if r["axis"] == axis], axis=axis,
                            unit=AXIS_UNITS[axis], agents=agents, categories=levels if axis == "world" else None)
    levels = {axis: [float(sweep_level(exp, axis, v)) for v in levels] for axis, levels in exp.sweep.items()}
    return {"sweep": {**levels, **({"world": [base_world, *exp.worlds]} if exp.worlds else {})},
            "n_conditions": len({(r["axis"], r["level"]) for r in rows})}
