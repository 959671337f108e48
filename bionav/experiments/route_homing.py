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
homing methods), route and seed (:func:`run_ardin2016`,
:func:`bionav.evaluation.route.follow_route`): errors (put-backs) per route,
error-free routes and arrivals at the nest, in metrics.json and
``route_following.csv`` (docs/worlds.md).

Writes metrics.json (``<measure>_<method>``: ``heading_error``,
``catchment_width_m``, ``completed``, ``route_distance_m``, each the mean over
routes), ``route_homing.csv`` (one row per route and method), run.mcap
(agent paths) and plots/ (world from above with routes and paths, headings
along each route, heading-error maps).
"""

from __future__ import annotations

import csv
import math
import zlib
from dataclasses import dataclass
from typing import Any

import numpy as np
from omegaconf import DictConfig, OmegaConf

from bionav.errors import UserError
from bionav.experiments.configs import RouteHomingConfig, experiment_config
from bionav.geometry import angular_difference, wrap_angle

#: the agent's step of each protocol when ``experiment.agent_step_m`` is null, metres
PROTOCOL_STEP_M = {"bionav": 0.05, "ardin2016": 0.1}
#: most steps one agent may take on one route (``max_steps_factor`` x length / step)
MAX_STEPS_PER_ROUTE = 20_000
#: the routes of the ardin2016 protocol when ``experiment.routes`` is empty
ARDIN_ROUTES = tuple(f"Ant{a}_Route1" for a in range(1, 16))
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
    """The typed, range-checked ``experiment`` node (:class:`~bionav.experiments.configs.RouteHomingConfig`)."""
    exp = OmegaConf.to_object(experiment_config(cfg, "route_homing"))
    if exp.agent_step_m is None:
        exp.agent_step_m = PROTOCOL_STEP_M[exp.protocol]
    if not any(float(v) == 0.0 for v in exp.offsets_m):
        raise UserError(f"experiment.offsets_m={list(exp.offsets_m)} must include 0 (the route itself), "
                        "e.g. experiment.offsets_m=[-0.2,0.0,0.2].")
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
        w = self.exp.window
        if centred:
            return max(0, k_last - w // 2), min(len(self.snaps), k_last + w // 2 + 1)
        return max(0, k_last - 1), min(len(self.snaps), k_last + w + 1)

    def home_direction(self, render, pos, target: int):
        """World direction from ``pos`` to snapshot ``target`` by the homing method (NaN if none)."""
        h_t = float(self.s.heading[target])
        cur = render(pos, h_t)
        neighbours = None
        if getattr(self.homing, "uses_test_steps", False):
            neighbours = {}
            c, s = math.cos(h_t), math.sin(h_t)
            for d in ((1, 0), (-1, 0), (0, 1), (0, -1)):
                step = self.exp.test_step_m
                p = (pos[0] + step * (c * d[0] - s * d[1]), pos[1] + step * (s * d[0] + c * d[1]))
                neighbours[d] = self.homing.prepare(render(p, h_t))
        hv = self.homing.home_vector(self.prepared[target], self.homing.prepare(cur), neighbours=neighbours)
        return float(wrap_angle(hv.angle + h_t)) if hv.valid else float("nan")


def _make_renderer(setup: _RouteSetup, rng: np.random.Generator):
    from bionav.db.synthetic import quantise
    from bionav.world.mesh_render import render_mesh_panorama

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


def _setup_route(cfg: DictConfig, name: str) -> _RouteSetup:
    from bionav.db.loading import as_database_config
    from bionav.db.mesh import MeshDatabaseSpec, load_route, route_database, world_from_spec

    node = OmegaConf.to_container(cfg.db, resolve=True)
    if node.get("source") != "route":
        raise UserError(f"experiment=route_homing needs a route database (db=seville_route), not db={node.get('name')}.")
    node["route"] = name
    dbc = as_database_config(node)
    spec = MeshDatabaseSpec.from_config(dbc, grid=False)
    dense = load_route(name, dbc.routes_path).xy
    _check_step_counts(name, dense, float(dbc.step_m))
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
        length = load_route(name, routes_path).length_m
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
        return run_ardin2016(cfg, ctx, exp)
    routes = list(exp.routes) or [str(cfg.db.route)]
    if exp.closed_loop:  # open-loop runs take no agent steps
        check_step_budget(routes, exp, _routes_path(cfg))
    rows = []
    per_route = {}
    for name in routes:
        setup = _setup_route(cfg, name)
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
                   "heading_error_on_route": float(np.nanmean(err[:, list(exp.offsets_m).index(0.0)])),
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


# --------------------------------------------------------------------------- protocol ardin2016
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
                            f"{list(exp.agents)}; add it there or drop its parameters.")
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


def scan_geometry(exp: RouteHomingConfig):
    """The panorama the scans are cut from: columns every ``scan_step_deg``, 19 rows of 4 deg (+58 .. -14 deg).

    With ``supersample = s > 1`` the rendered panorama has columns and rows every ``4 / s`` degrees,
    columns half a fine column off the heading (:func:`box_panorama` averages them to 4-degree pixels).
    Returns ``(rendered geometry, scan-panorama column degrees, heading offset of the render, radians)``.
    """
    from bionav.geometry import PanoramaGeometry

    col = float(exp.scan_step_deg)
    s = int(exp.supersample)
    if s == 1:
        return PanoramaGeometry(int(round(360.0 / col)), 19, 14.5, math.radians(4.0)), col, 0.0
    fine = 4.0 / s
    return PanoramaGeometry(int(round(360.0 / fine)), 19 * s, 60.0 / fine - 0.5, math.radians(fine)), col, \
        math.radians(fine / 2.0)


def box_panorama(fine: np.ndarray, *, supersample: int, column_deg: float) -> np.ndarray:
    """4-degree pixels from a panorama rendered every ``4 / supersample`` degrees, one column every ``column_deg``.

    ``fine`` column ``m`` looks at ``heading + (m + 1/2) * f`` (``f = 4 / supersample`` degrees), row ``r``
    at ``60 - (r + 1/2) * f``. Output column ``k`` (at ``heading + k * column_deg``) is the mean of the
    ``supersample x supersample`` fine pixels within +-2 degrees of its centre, row ``i`` of rows
    ``i*s .. i*s + s - 1`` (centre ``58 - 4 i`` degrees): area pixels as the reference renderer's
    rasterised patches, instead of one ray per pixel centre. Shape ``(19, 360 / column_deg)``.
    """
    s = int(supersample)
    f = 4.0 / s
    h, w = fine.shape
    rows = fine.reshape(h // s, s, w).mean(axis=1)
    box = sum(np.roll(rows, s // 2 - j, axis=1) for j in range(s)) / s  # box[c] = mean rows[c - s/2 .. c + s/2 - 1]
    step = int(round(column_deg / f))
    return box[:, ::step]


def _scan_renderer(setup: _RouteSetup, exp: RouteHomingConfig, rng: np.random.Generator, *, half_deg=None):
    """``views(xy, heading) -> (views (S, h, w), offsets (S,))``: the agents' preprocessed scan views."""
    from bionav.db.synthetic import quantise
    from bionav.evaluation.route import scan_views
    from bionav.world.mesh_render import render_mesh_panorama

    geometry, col, shift = scan_geometry(exp)
    half = exp.scan_half_deg if half_deg is None else half_deg

    def views(xy, heading):
        z = float(setup.world.terrain_height(np.array([xy]))[0])
        z = (setup.world.ground_z if not np.isfinite(z) else z) + setup.height
        img = render_mesh_panorama(setup.world, position=(xy[0], xy[1], z), heading=heading + shift, geometry=geometry)
        img = img.mean(axis=-1)
        if exp.supersample > 1:
            img = box_panorama(img, supersample=exp.supersample, column_deg=col)
        img = quantise(img, noise=setup.noise, rng=rng).astype(np.float32) / np.float32(255.0)
        return scan_views(img, column_deg=col, scan_half_deg=half, scan_step_deg=float(exp.scan_step_deg),
                          size=list(exp.view_size))

    return views


def _familiarity_chooser(agent, views):
    """Heading of the least unfamiliar scan view; ties go to the view nearest straight ahead."""

    def choose(pos, heading):
        v, off = views(pos, heading)
        u = np.nan_to_num(np.asarray(agent.unfamiliarity(v), np.float64), nan=np.inf)
        if not np.isfinite(u).any():
            return float("nan")  # no opinion: keep the heading
        best = np.flatnonzero(u == u.min())
        s = int(best[np.argmin(np.abs(off[best]))])
        agent.choose(s)
        return heading + float(off[s])

    return choose


def travel_headings(xy: np.ndarray) -> np.ndarray:
    """Direction of travel from each route view to the next (the last repeats its predecessor's), radians CCW from ``+x``."""
    d = np.diff(np.asarray(xy, np.float64), axis=0)
    h = np.arctan2(d[:, 1], d[:, 0])
    return np.append(h, h[-1]) if len(h) else np.zeros(len(xy))


def _rng(seed: int, *parts: str) -> np.random.Generator:
    return np.random.default_rng(np.random.SeedSequence([int(seed), *(zlib.crc32(p.encode()) for p in parts)]))


def run_ardin2016(cfg: DictConfig, ctx, exp: RouteHomingConfig) -> dict[str, Any]:
    """``experiment.protocol=ardin2016``: the published route-following test for every agent, route and seed."""
    import time

    from bionav.evaluation.route import follow_route

    routes = list(exp.routes) or list(ARDIN_ROUTES)
    kinds = _agent_kinds(list(exp.agents))
    _check_agent_params(exp, kinds)
    check_step_budget(routes, exp, _routes_path(cfg))
    rows, paths, setups = [], {}, []
    timing = {a: [0.0, 0.0] for a in exp.agents}
    for name in ctx.progress(routes, desc="ardin2016 routes"):
        setup = _setup_route(cfg, name)
        setups.append(setup)
        length = float(np.linalg.norm(np.diff(setup.dense_xy, axis=0), axis=1).sum())
        max_steps = int(math.ceil(exp.max_steps_factor * length / exp.agent_step_m))
        route_heading = setup.heading if exp.training_heading == "recorded" else travel_headings(setup.xy)
        for seed in exp.seeds:
            train_views = None
            for agent_name in exp.agents:
                wall0, cpu0 = time.perf_counter(), time.process_time()
                rng = _rng(seed, name, agent_name)
                if kinds[agent_name] == "route_agent":
                    if train_views is None:  # the same training views for every agent of this route and seed
                        one = _scan_renderer(setup, exp, _rng(seed, name, "training"), half_deg=0.0)
                        train_views = np.concatenate([one(p, float(h))[0] for p, h in zip(setup.xy, route_heading)])
                    agent = _route_agent(agent_name, exp, rng)
                    agent.train(train_views)
                    choose = _familiarity_chooser(agent, _scan_renderer(setup, exp, rng))
                    on_putback = agent.reset
                else:
                    homing = _homing_agent(agent_name, cfg, ctx, exp, setup.geometry)
                    f = _Follower("homing", setup, exp, homing)
                    render = _make_renderer(setup, rng)
                    state = {"k": 0}

                    def choose(pos, heading, f=f, render=render, state=state):
                        lo, hi = f.window_of(state["k"], centred=False)
                        _h, state["k"] = f.ridf_heading(render(pos, 0.0), lo, hi)
                        h = f.home_direction(render, pos, min(state["k"] + exp.lookahead, len(f.s.xy) - 1))
                        # the turn is limited to the scan range of the familiarity agents
                        limit = math.radians(exp.scan_half_deg)
                        return heading + float(np.clip(wrap_angle(h - heading), -limit, limit))

                    def on_putback(k, state=state):
                        state["k"] = int(k)
                res = follow_route(choose, route_xy=setup.xy, route_heading=route_heading, nest_xy=setup.dense_xy[-1],
                                   step_m=exp.agent_step_m, putback_m=exp.putback_m, goal_m=exp.putback_m,
                                   max_steps=max_steps, jitter_m=exp.position_jitter_m,
                                   rng=_rng(seed, name, agent_name, "jitter"), on_putback=on_putback)
                wall, cpu = time.perf_counter() - wall0, time.process_time() - cpu0
                timing[agent_name][0] += wall
                timing[agent_name][1] += cpu
                rows.append({"route": name, "agent": agent_name, "seed": int(seed),
                             "position_jitter_m": float(exp.position_jitter_m), "errors": int(res.errors),
                             "error_free": int(res.errors == 0), "reached_nest": int(res.reached_nest),
                             "steps": int(res.steps), "n_views": len(setup.xy), "cpu_s": cpu})
                if seed == exp.seeds[0]:
                    paths[(name, agent_name)] = res.path
                ctx.log.write(PATH_TOPIC, {"route": name, "method": agent_name, "xy": res.path.tolist(),
                                           "completed": bool(res.reached_nest)},
                              schema_name="bionav.RoutePath", schema=PATH_SCHEMA)
    _write_rows(ctx.dir / ARDIN_CSV, rows, ARDIN_KEYS)
    if exp.plots:
        from bionav.experiments.route_plots import plot_world_routes

        plot_world_routes(ctx.plots / "world_routes.png", setups[0].world, setups, paths)
    return ardin_metrics(rows, routes=routes, agents=list(exp.agents), seeds=list(exp.seeds), timing=timing,
                         extra={"db": str(cfg.db.name), "protocol": "ardin2016",
                                "position_jitter_m": float(exp.position_jitter_m), "step_m": float(exp.agent_step_m)})


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


def _write_rows(path, rows, keys):
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.6f}" if isinstance(v, float) else v) for k, v in r.items()})


def _write_csv(path, rows):
    keys = ["route", "method", "n_snapshots", "heading_error", "heading_error_on_route", "catchment_width_m",
            "invalid", "completed", "route_distance_m", "steps"]
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.6f}" if isinstance(v, float) else v) for k, v in r.items()})


__all__ = ["RouteHomingConfig", "ardin_metrics", "check_step_budget", "closed_loop", "open_loop", "route_homing_config",
           "run", "run_ardin2016", "scan_geometry"]
