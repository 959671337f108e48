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
(:mod:`bionav.experiments.route_homing_ardin2016`): errors (put-backs) per route,
error-free routes and arrivals at the nest, in metrics.json and
``route_following.csv`` (docs/worlds.md).

Writes metrics.json (``<measure>_<method>``: ``heading_error``,
``catchment_width_m``, ``completed``, ``route_distance_m``, each the mean over
routes), ``route_homing.csv`` (one row per route and method), run.mcap
(agent paths) and plots/ (world from above with routes and paths, headings
along each route, heading-error maps).
"""

from __future__ import annotations

import math
import zlib
from dataclasses import dataclass
from typing import Any

import numpy as np
from omegaconf import DictConfig, OmegaConf

from bionav.errors import UserError
from bionav.experiments.configs import RouteHomingConfig, experiment_config
from bionav.files import write_csv_atomic
from bionav.geometry import angular_difference, wrap_angle

#: the agent's step of each protocol when ``experiment.agent_step_m`` is null, metres
PROTOCOL_STEP_M = {"bionav": 0.05, "ardin2016": 0.1}
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


def route_homing_config(cfg: DictConfig) -> RouteHomingConfig:
    """The typed, range-checked ``experiment`` node (:class:`~bionav.experiments.configs.RouteHomingConfig`,
    ``offsets_m`` with 0 checked by its ``validate``), ``agent_step_m`` defaulting to the protocol's."""
    exp = OmegaConf.to_object(experiment_config(cfg, "route_homing"))
    if exp.agent_step_m is None:
        exp.agent_step_m = PROTOCOL_STEP_M[exp.protocol]
    return exp


@dataclass
class _RouteSetup:
    name: str
    world: Any
    db: Any  # ImageDatabase of the snapshots
    xy: np.ndarray  # (K, 2) snapshot positions
    heading: np.ndarray  # (K,)
    dense_xy: np.ndarray  # the full recorded route, metres
    height: float
    geometry: Any
    noise: float


class _Follower:
    """Per-route state of one method: snapshots prepared once."""

    def __init__(self, method: str, setup: _RouteSetup, exp: RouteHomingConfig, homing=None):
        self.method = method
        self.s = setup
        self.exp = exp
        self.homing = homing
        self.snaps = setup.db.images
        self.prepared = None
        if method == "homing":
            self.prepared = [homing.prepare(img) for img in setup.db.images]
        if method == "zernike":
            from bionav.plugins.signatures.zernike import Zernike

            self.zernike = Zernike({"order": exp.zernike_order})
            self.moments = np.array([self.zernike.moments(img)[0] for img in setup.db.images])
            self.zindex = self.zernike.moments(setup.db.images[0])[1]

    def zernike_heading(self, view0, lo: int = 0, hi: int | None = None):
        """Best snapshot by moment amplitudes; heading from the phases (view0 looks along heading 0)."""
        from bionav.homing.signatures.zernike import rotation_from_moments

        hi = len(self.moments) if hi is None else hi
        zc = self.zernike.moments(view0)[0]
        d = ((np.abs(self.moments[lo:hi]) - np.abs(zc)[None]) ** 2).sum(axis=1)
        k = lo + int(np.argmin(d))
        delta = rotation_from_moments(zc, self.moments[k], self.zindex)  # heading(view0) - heading(snapshot k)
        return float(wrap_angle(-delta)), k

    def ridf_heading(self, view0, lo: int = 0, hi: int | None = None):
        from bionav.evaluation.route import best_match

        hi = len(self.snaps) if hi is None else hi
        h, k, d = best_match(view0, self.snaps[lo:hi], snapshot_headings=self.s.heading[lo:hi])
        return h, lo + k

    def window_of(self, k_last: int, centred: bool):
        from bionav.evaluation.route_followers import route_window

        return route_window(k_last, len(self.snaps), self.exp.window, centred=centred)

    def home_direction(self, render, pos, target: int):
        """World direction from ``pos`` to snapshot ``target`` by the homing method (NaN if none)."""
        from bionav.evaluation.route_followers import home_direction

        return home_direction(self.homing, self.prepared[target], float(self.s.heading[target]), render, pos,
                              test_step_m=self.exp.test_step_m)


def _make_renderer(setup: _RouteSetup, rng: np.random.Generator):
    from bionav.db.synthetic import quantise
    from bionav.world.mesh_render import render_mesh_panorama

    if recorded_world(setup):  # db=bag: the drive's recorded views are the world
        from bionav.experiments.route_homing_bag import recorded_renderer

        return recorded_renderer(setup)

    def render(xy, heading):
        z = float(setup.world.terrain_height(np.array([xy]))[0])
        z = (setup.world.ground_z if not np.isfinite(z) else z) + setup.height
        img = render_mesh_panorama(setup.world, position=(xy[0], xy[1], z), heading=heading, geometry=setup.geometry)
        img = quantise(img, noise=setup.noise, rng=rng).astype(np.float32) / np.float32(255.0)
        return img[..., 0] if img.shape[-1] == 1 else img

    return render


def open_loop(f: _Follower, render, exp: RouteHomingConfig, progress=None):
    """Heading errors at test points offset from the route: ``(stations (N,), errors (N, M), estimates (N, M))``."""
    from bionav.evaluation.route import lateral_normals

    s = f.s
    stations = np.arange(0, len(s.xy), exp.test_stride)
    offsets = np.asarray(exp.offsets_m, np.float64)
    normals = lateral_normals(s.heading)
    err = np.full((len(stations), len(offsets)), np.nan)
    est = np.full_like(err, np.nan)
    it = range(len(stations)) if progress is None else progress(range(len(stations)))
    for a in it:
        i = int(stations[a])
        for b, off in enumerate(offsets):
            p = s.xy[i] + off * normals[i]
            if f.method == "homing":
                target = min(i + exp.lookahead, len(s.xy) - 1)
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


def closed_loop(f: _Follower, render, exp: RouteHomingConfig):
    """Simulated agent from the displaced start; returns ``(path (T, 2), completed, mean distance)``."""
    from bionav.evaluation.route import distance_to_route, lateral_normals

    s = f.s
    pos = s.xy[0] + exp.start_offset_m * lateral_normals(s.heading[:1])[0]
    end = s.dense_xy[-1]
    length = float(np.linalg.norm(np.diff(s.dense_xy, axis=0), axis=1).sum())
    max_steps = int(math.ceil(exp.max_steps_factor * length / exp.agent_step_m))
    path = [pos.copy()]
    k_last = 0
    heading = float(s.heading[0])
    completed = False
    for _ in range(max_steps):
        if f.method == "perfect_memory":
            heading, k_last = f.ridf_heading(render(pos, 0.0))
        elif f.method == "zernike":
            heading, k_last = f.zernike_heading(render(pos, 0.0))
        elif f.method == "windowed":
            lo, hi = f.window_of(k_last, centred=False)
            heading, k_last = f.ridf_heading(render(pos, 0.0), lo, hi)
        else:
            lo, hi = f.window_of(k_last, centred=False)
            _h, k_last = f.ridf_heading(render(pos, 0.0), lo, hi)
            h = f.home_direction(render, pos, min(k_last + exp.lookahead, len(s.xy) - 1))
            if np.isfinite(h):
                heading = h
        pos = pos + exp.agent_step_m * np.array([math.cos(heading), math.sin(heading)])
        path.append(pos.copy())
        if np.linalg.norm(pos - end) <= exp.success_radius_m:
            completed = True
            break
        if distance_to_route(pos[None], s.dense_xy)[0][0] > exp.give_up_m:
            break
    path = np.array(path)
    dist = distance_to_route(path, s.dense_xy)[0]
    return path, completed, float(dist.mean())


#: most route views (route length / db.step_m) a run may render: a tiny step would otherwise render for days
#: (checked before any rendering; the agents' steps are bounded by :func:`check_step_budget`)
MAX_ROUTE_VIEWS = 20_000


def _check_step_counts(name: str, dense_xy: np.ndarray, step_m: float) -> None:
    length = float(np.linalg.norm(np.diff(np.asarray(dense_xy, float), axis=0), axis=1).sum())
    n_views = length / step_m
    if n_views > MAX_ROUTE_VIEWS:
        raise UserError(
            f"db.step_m={step_m:g} m gives {n_views:.0f} views along the {length:.1f} m route {name}, more than the "
            f"{MAX_ROUTE_VIEWS} a run renders; give db.step_m={length / MAX_ROUTE_VIEWS:.3g} or more (default 0.1)."
        )


def recorded_world(setup: _RouteSetup) -> bool:
    """Whether the route's world is a recording (``db=bag``) rather than a mesh to render."""
    from bionav.db.bag.route import RecordedViews

    return isinstance(setup.world, RecordedViews)


def routes_to_follow(cfg: DictConfig, exp: RouteHomingConfig, default: list[str]) -> list[str]:
    """The routes to follow: ``experiment.routes``, else ``default``; with ``db=bag`` the bag's one drive."""
    from bionav.experiments.route_homing_bag import check_routes, is_bag

    if is_bag(cfg):
        check_routes(exp)
        return ["drive"]
    return list(exp.routes or default)


def _setup_route(cfg: DictConfig, name: str) -> _RouteSetup:
    from bionav.db.loading import as_database_config
    from bionav.db.mesh import MeshDatabaseSpec, load_route, route_database, world_from_spec
    from bionav.experiments.route_homing_bag import bag_route_setup, is_bag

    if is_bag(cfg):
        setup = bag_route_setup(cfg, _RouteSetup)
        check_route_length(setup.name, float(np.linalg.norm(np.diff(setup.dense_xy, axis=0), axis=1).sum()),
                           route_homing_config(cfg))
        return setup
    node = OmegaConf.to_container(cfg.db, resolve=True)
    if node.get("source") != "route":
        raise UserError(f"experiment=route_homing needs a route database (db=seville_route), not db={node.get('name')}.")
    node["route"] = name
    dbc = as_database_config(node)
    spec = MeshDatabaseSpec.from_config(dbc, grid=False)
    dense = load_route(name, dbc.routes_path).xy
    _check_step_counts(name, dense, dbc.step_m)
    db = route_database(dbc, cache_dir=str(cfg.cache_dir))
    world = world_from_spec(spec)
    return _RouteSetup(name, world, db, np.asarray(db.meta["world_xy"]), np.asarray(db.headings), dense,
                       spec.camera_height_m, db.geometry, spec.noise)


def _routes_path(cfg: DictConfig):
    return OmegaConf.select(cfg, "db.routes_path", default=None)


def check_step_budget(routes: list[str], exp: RouteHomingConfig, routes_path=None) -> None:
    """Refuse, before any work, a step so small that one route would take more than :data:`MAX_STEPS_PER_ROUTE` steps."""
    from bionav.db.mesh import load_route

    for name in routes:
        if name != "drive":  # db=bag's drive is checked once it is read (check_route_length)
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


def run(cfg: DictConfig, ctx) -> dict[str, Any]:
    from bionav.experiments.common import make_homing

    exp = route_homing_config(cfg)
    if exp.protocol == "ardin2016":
        from bionav.experiments.route_homing_ardin2016 import run_ardin2016

        return run_ardin2016(cfg, ctx, exp)
    routes = routes_to_follow(cfg, exp, [str(OmegaConf.select(cfg, "db.route", default=None))])
    if exp.closed_loop:  # open-loop runs take no agent steps
        check_step_budget(routes, exp, _routes_path(cfg))
    rows = []
    per_route = {}
    for name in routes:
        setup = _setup_route(cfg, name)
        name = setup.name
        homing = make_homing(cfg, ctx, setup.geometry) if "homing" in exp.methods else None
        per_route[name] = {"setup": setup, "results": {}}
        for method in exp.methods:
            key = zlib.crc32(f"{name}/{method}".encode())  # camera noise per route and method, whatever the order
            rng = np.random.default_rng(np.random.SeedSequence([int(cfg.get("seed", 0)), key]))
            render = _make_renderer(setup, rng)
            f = _Follower(method, setup, exp, homing)
            stations, err, est = open_loop(f, render, exp, progress=lambda it, n=name, m=method: ctx.progress(
                it, desc=f"{n} {m} open loop"))
            from bionav.evaluation.route import catchment_width

            width = catchment_width(np.asarray(exp.offsets_m), err, threshold=np.deg2rad(exp.error_threshold_deg))
            row = {"route": name, "method": method, "n_snapshots": len(setup.xy),
                   "heading_error": float(np.nanmean(err)) if np.isfinite(err).any() else float("nan"),
                   "heading_error_on_route": float(np.nanmean(err[:, exp.offsets_m.index(0.0)])),
                   "catchment_width_m": float(width.mean()), "invalid": int(np.isnan(err).sum())}
            res = {"stations": stations, "err": err, "est": est}
            if exp.closed_loop:
                path, completed, dist = closed_loop(f, render, exp)
                row.update({"completed": bool(completed), "route_distance_m": dist, "steps": len(path) - 1})
                res["path"] = path
                ctx.log.write(PATH_TOPIC, {"route": name, "method": method, "xy": path.tolist(),
                                           "completed": bool(completed)},
                              schema_name="bionav.RoutePath", schema=PATH_SCHEMA)
            per_route[name]["results"][method] = res
            rows.append(row)
    routes = list(per_route)  # db=bag: the drive's own name
    _write_csv(ctx.dir / "route_homing.csv", rows)
    if exp.plots:
        from bionav.experiments.route_plots import plot_error_maps, plot_headings, plot_world_routes

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


def write_rows(path, rows: list[dict], keys: list[str]) -> None:
    """One CSV row per dict (floats with 6 decimals; keys not in ``keys`` left out)."""
    write_csv_atomic(path, keys, ([_cell(r.get(k, "")) for k in keys] for r in rows))


def _cell(value: Any) -> Any:
    return f"{value:.6f}" if isinstance(value, float) else value


def _write_csv(path, rows):
    write_rows(path, rows, ["route", "method", "n_snapshots", "heading_error", "heading_error_on_route",
                            "catchment_width_m", "invalid", "completed", "route_distance_m", "steps"])


__all__ = ["RouteHomingConfig", "check_route_length", "check_step_budget", "closed_loop", "open_loop",
           "recorded_world", "route_homing_config", "routes_to_follow", "run", "write_rows"]
