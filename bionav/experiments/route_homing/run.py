"""``experiment=route_homing``: following real ant routes in a mesh world (Seville 2009 by default).

For every route (``experiment.routes``, default the ``db.route``) the
snapshots are the views along the route every ``db.step_m`` metres at the
ant's recorded heading (:func:`bionav.db.mesh.route_database`). Methods
(``experiment.methods``):

* ``perfect_memory`` -- RIDF against every snapshot, head where the best
  rotation points (Baddeley et al. 2012, doi:10.1371/journal.pcbi.1002336);
* ``windowed`` -- the same against the snapshots in a window ahead of the last
  best match (sequential perfect memory; open loop: around the true index);
* ``zernike`` -- perfect memory on Zernike-moment amplitudes (rotation
  invariant: one comparison per snapshot), heading from the phases of the best
  snapshot's moments (Sun, Yue & Mangan 2020, doi:10.7554/eLife.54026;
  :mod:`bionav.homing.signatures.zernike`);
* ``homing`` -- the configured ``homing=`` method as a route follower: home
  to the snapshot ``lookahead`` views after the current best match (progress
  tracked by windowed RIDF); the agent's view is aligned with that snapshot
  (a perfect compass), test-step methods get views at ``+-test_step_m``.

Measures (all angles radians, distances metres):

The set-up and the followers are :mod:`bionav.evaluation.route_setup` and
:mod:`bionav.evaluation.route_tests`.

* open loop, at every ``test_stride``-th route view and each lateral offset of
  ``offsets_m`` (left positive): heading error -- RIDF methods against the
  recorded route heading at that route point (as BoB/navbench), homing
  against the true direction to its target snapshot; ``catchment_width_m``:
  mean over route points of the lateral extent with errors below
  ``error_threshold_deg`` (:func:`bionav.evaluation.route.catchment_width`);
* closed loop, from the route start displaced ``start_offset_m`` to the left:
  steps of ``agent_step_m``; ``completed`` when within ``success_radius_m`` of
  the route's end, given up beyond ``give_up_m`` from the route or after
  ``max_steps_factor`` x route length / step; ``route_distance_m`` = mean
  distance of the path from the route.

``experiment.protocol=ardin2016`` runs instead the published test of Ardin,
Peng, Mangan, Lagogiannis & Webb 2016 (doi:10.1371/journal.pcbi.1004683) for
every agent of ``experiment.agents`` (``bionav.route_agents`` plugins and
homing methods), route and seed
(:mod:`bionav.experiments.route_homing.ardin2016`): errors (put-backs) per route,
error-free routes and arrivals at the nest, in metrics.json and
``route_following.csv`` (docs/worlds.md).

Writes metrics.json (``<measure>_<method>``: ``heading_error``,
``catchment_width_m``, ``completed``, ``route_distance_m``, each the mean over
routes), ``route_homing.csv`` (one row per route and method), run.mcap
(agent paths) and plots/ (world from above with routes and paths, headings
along each route, heading-error maps).
"""

from __future__ import annotations

import logging
import zlib
from typing import Any

import numpy as np
from omegaconf import OmegaConf

from bionav.evaluation.route import catchment_width
from bionav.evaluation.route_setup import route_renderer
from bionav.evaluation.route_tests import SnapshotFollower, closed_loop, open_loop
from bionav.experiments.common import make_homing
from bionav.experiments.route_homing.config import RouteHomingConfig
from bionav.experiments.route_homing import shared
from bionav.plugins.signatures.zernike import Zernike

log = logging.getLogger(__name__)


def run(exp: RouteHomingConfig, ctx) -> dict[str, Any]:
    """Run ``experiment=route_homing`` (``protocol=bionav``) with the checked ``exp`` (the rest in ``ctx.cfg``)."""
    cfg = ctx.cfg
    exp = shared.with_protocol_defaults(exp)
    routes = shared.routes_to_follow(cfg, exp, [str(OmegaConf.select(cfg, "db.route", default=None))])
    if exp.closed_loop:  # open-loop runs take no agent steps
        shared.check_step_budget(routes, exp, shared.routes_file(cfg))
    rows = []
    per_route = {}
    for name in routes:
        log.info("route %s: loading its world and route views (rendered once, then cached) ...", name)
        setup = shared.route_setup(cfg, name, exp)
        name = setup.name
        homing = make_homing(cfg, ctx, setup.geometry) if "homing" in exp.methods else None
        zernike = Zernike({"order": exp.zernike_order}) if "zernike" in exp.methods else None
        per_route[name] = {"setup": setup, "results": {}}
        for method in exp.methods:
            key = zlib.crc32(f"{name}/{method}".encode())  # camera noise per route and method, whatever the order
            rng = np.random.default_rng(np.random.SeedSequence([int(cfg.get("seed", 0)), key]))
            render = route_renderer(setup, rng)
            f = SnapshotFollower(method, setup, window=exp.window, test_step_m=exp.test_step_m, homing=homing,
                                 zernike=zernike)
            stations, err, est = open_loop(f, render, test_stride=exp.test_stride, offsets_m=exp.offsets_m,
                                           lookahead=exp.lookahead, progress=lambda it, n=name, m=method: ctx.progress(
                                               it, desc=f"{n} {m} open loop"))
            width = catchment_width(np.asarray(exp.offsets_m), err, threshold=np.deg2rad(exp.error_threshold_deg))
            row = {"route": name, "method": method, "n_snapshots": len(setup.xy),
                   "heading_error": float(np.nanmean(err)) if np.isfinite(err).any() else float("nan"),
                   "heading_error_on_route": float(np.nanmean(err[:, exp.offsets_m.index(0.0)])),
                   "catchment_width_m": float(width.mean()), "invalid": int(np.isnan(err).sum())}
            res = {"stations": stations, "err": err, "est": est}
            if exp.closed_loop:
                path, completed, dist = closed_loop(
                    f, render, start_offset_m=exp.start_offset_m, agent_step_m=exp.agent_step_m,
                    max_steps_factor=exp.max_steps_factor, success_radius_m=exp.success_radius_m,
                    give_up_m=exp.give_up_m, lookahead=exp.lookahead, progress=lambda it, n=name, m=method, **kw:
                    ctx.progress(it, desc=f"{n} {m} closed loop (steps)", **kw))
                row.update({"completed": bool(completed), "route_distance_m": dist, "steps": len(path) - 1})
                res["path"] = path
                ctx.log.write(shared.PATH_TOPIC, {"route": name, "method": method, "xy": path.tolist(),
                                           "completed": bool(completed)},
                              schema_name="bionav.RoutePath", schema=shared.PATH_SCHEMA)
            per_route[name]["results"][method] = res
            rows.append(row)
    routes = list(per_route)  # db=bag: the drive's own name
    _write_csv(ctx.dir / "route_homing.csv", rows)
    if exp.plots:
        from bionav.experiments.route_homing.plots import plot_error_maps, plot_headings, plot_world_routes

        setups = [v["setup"] for v in per_route.values()]
        paths = {(r, m): v["results"][m].get("path") for r, v in per_route.items() for m in v["results"]}
        plot_world_routes(ctx.plots / "world_routes.png", setups[0].world, setups, paths)
        for r, v in per_route.items():
            plot_headings(ctx.plots / f"headings_{r}.png", v["setup"], v["results"], exp.offsets_m)
            plot_error_maps(ctx.plots / f"error_map_{r}.png", v["setup"], v["results"], exp.offsets_m)
    metrics: dict[str, Any] = {"db": str(cfg.db.name), "routes": routes, "n_routes": len(routes),
                               "homing": str(cfg.homing.name) if "homing" in exp.methods else None}
    for method in exp.methods:
        mine = [r for r in rows if r["method"] == method]
        for key in ("heading_error", "heading_error_on_route", "catchment_width_m"):
            vals = [r[key] for r in mine if np.isfinite(r[key])]
            metrics[f"{key}_{method}"] = float(np.mean(vals)) if vals else None
        if exp.closed_loop:
            metrics[f"completed_{method}"] = float(np.mean([r["completed"] for r in mine]))
            metrics[f"route_distance_m_{method}"] = float(np.mean([r["route_distance_m"] for r in mine]))
    return metrics


def _write_csv(path, rows):
    shared.write_rows(path, rows, ["route", "method", "n_snapshots", "heading_error", "heading_error_on_route",
                                   "catchment_width_m", "invalid", "completed", "route_distance_m", "steps"])
