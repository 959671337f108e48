"""A route set up for following: its snapshots, the world, and what an agent sees.

:func:`setup_route` renders the snapshots along a recorded route in a mesh world
(:func:`bionav.db.mesh.route_database`) and builds the world once; :func:`setup_bag_route` takes a
robot's drive from a ROS bag (``db=bag``) as the route, its recorded views as the world
(:class:`bionav.db.bag.route.RecordedViews`). :func:`route_renderer` gives the agent's canonical
panorama at a pose and :func:`scan_renderer` the preprocessed views of a scan around a heading, as
the protocol of Ardin et al. 2016 (doi:10.1371/journal.pcbi.1004683) sees them (:func:`scan_geometry`,
:func:`box_panorama`; in a recorded world cut from the nearest recorded view, :func:`recorded_world`);
:func:`travel_headings` gives the training headings along the route.

Conventions: positions in metres (world frame of the mesh or of the bag's poses), headings radians
counter-clockwise from world ``+x``; panoramas canonical (:mod:`bionav.geometry`), column 0 along the
heading rendered at; camera noise and 8-bit quantisation as the databases'
(:func:`bionav.db.synthetic.quantise`; a recorded world adds none: its views carry the camera's own).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from bionav.db.synthetic import quantise
from bionav.errors import UserError
from bionav.evaluation.route import scan_views
from bionav.geometry import PanoramaGeometry
from bionav.world.mesh_render import render_mesh_panorama

#: most route views (route length / db.step_m) a run may render: a tiny step would otherwise render for days
#: (checked before any rendering)
MAX_ROUTE_VIEWS = 20_000


@dataclass
class RouteSetup:
    """One route ready to follow.

    Attributes
    ----------
    name : str
        ``Ant<a>_Route<r>``; a bag's drive: the bag's name and image topic (:func:`setup_bag_route`).
    world : MeshWorld or RecordedViews
        The mesh world (:func:`bionav.db.mesh.world_from_spec`), or a drive's recorded views.
    db : ImageDatabase
        The snapshots along the route.
    xy : ndarray, shape (K, 2)
        Snapshot positions, metres.
    heading : ndarray, shape (K,)
        The ant's recorded heading at each snapshot, radians CCW from ``+x``.
    dense_xy : ndarray, shape (M, 2)
        The whole recorded route, metres.
    height : float
        Camera height over the terrain, metres (0 for a recorded world).
    geometry : PanoramaGeometry
        The snapshots' geometry.
    noise : float
        Camera noise std before 8-bit quantisation (0 for a recorded world).
    scans : dict
        The noiseless scan panoramas rendered so far, by scan geometry and pose (:func:`scan_renderer`:
        agents that stand where another stood, or on a training view, reuse its render; the noise is drawn anew).
    """

    name: str
    world: Any
    db: Any
    xy: np.ndarray
    heading: np.ndarray
    dense_xy: np.ndarray
    height: float
    geometry: Any
    noise: float
    scans: dict = field(default_factory=dict, repr=False)


#: most noiseless scan panoramas kept per route (about 27 kB each at 2-degree columns)
MAX_KEPT_SCANS = 768


def check_route_views(name: str, dense_xy: np.ndarray, step_m: float) -> None:
    """Refuse a ``db.step_m`` that would render more than :data:`MAX_ROUTE_VIEWS` views along route ``name``."""
    length = float(np.linalg.norm(np.diff(np.asarray(dense_xy, float), axis=0), axis=1).sum())
    n_views = length / step_m
    if n_views > MAX_ROUTE_VIEWS:
        raise UserError(
            f"db.step_m={step_m:g} m gives {n_views:.0f} views along the {length:.1f} m route {name}, more than the "
            f"{MAX_ROUTE_VIEWS} a run renders; give db.step_m={length / MAX_ROUTE_VIEWS:.3g} or more (default 0.1)."
        )


def setup_route(db_node: dict, name: str, *, cache_dir: str) -> RouteSetup:
    """Route ``name`` of a route database (``db.source=route``; ``db_node`` its resolved ``db`` node).

    The snapshots are rendered (or read from ``cache_dir``) every ``db.step_m`` metres along the
    route at the ant's recorded heading; the route's length is checked first (:func:`check_route_views`).
    """
    from bionav.db.loading import as_database_config
    from bionav.db.mesh import MeshDatabaseSpec, load_route, route_database, world_from_spec

    node = dict(db_node)
    node["route"] = name
    dbc = as_database_config(node)
    spec = MeshDatabaseSpec.from_config(dbc, grid=False)
    dense = load_route(name, dbc.routes_path).xy
    check_route_views(name, dense, dbc.step_m)
    db = route_database(dbc, cache_dir=str(cache_dir))
    world = world_from_spec(spec)
    return RouteSetup(name, world, db, np.asarray(db.meta["world_xy"]), np.asarray(db.headings), dense,
                      spec.camera_height_m, db.geometry, spec.noise)


def setup_bag_route(db_node: dict) -> RouteSetup:
    """The drive of a ROS bag (``db=bag``; ``db_node`` its resolved ``db`` node) as a route to follow.

    The route views are the drive's views every ``db.route_step_m`` of path length, the world its
    recorded views (:func:`bionav.db.bag.route.load_bag_route`): at any pose an agent sees the recorded
    view nearest to it, turned to its heading.
    """
    from bionav.db.bag.route import load_bag_route
    from bionav.db.loading import as_database_config

    route = load_bag_route(as_database_config(dict(db_node)))
    db = route.db
    return RouteSetup(route.name, route.world, db, np.asarray(db.meta["world_xy"]), np.asarray(db.headings),
                      route.dense_xy, 0.0, db.geometry, 0.0)


def recorded_world(setup: RouteSetup) -> bool:
    """Whether the route's world is a recording (``db=bag``: :func:`setup_bag_route`) rather than a mesh to render."""
    from bionav.db.bag.route import RecordedViews

    return isinstance(setup.world, RecordedViews)


def _camera_z(setup: RouteSetup, xy) -> float:
    z = float(setup.world.terrain_height(np.array([xy]))[0])
    return (setup.world.ground_z if not np.isfinite(z) else z) + setup.height


def route_renderer(setup: RouteSetup, rng: np.random.Generator):
    """``render(xy, heading) -> panorama (H, W)`` float32 in [0, 1] in the snapshots' geometry, with their camera noise.

    In a recorded world (:func:`recorded_world`) the recorded view nearest to ``xy`` turned to ``heading``.
    """
    if recorded_world(setup):
        return setup.world.render

    def render(xy, heading):
        z = _camera_z(setup, xy)
        img = render_mesh_panorama(setup.world, position=(xy[0], xy[1], z), heading=heading, geometry=setup.geometry)
        img = quantise(img, noise=setup.noise, rng=rng).astype(np.float32) / np.float32(255.0)
        return img[..., 0] if img.shape[-1] == 1 else img

    return render


def scan_geometry(*, scan_step_deg: float, supersample: int):
    """The panorama the scans are cut from: columns every ``scan_step_deg``, 19 rows of 4 deg (+58 .. -14 deg).

    With ``supersample = s > 1`` the rendered panorama has columns and rows every ``4 / s`` degrees,
    columns half a fine column off the heading (:func:`box_panorama` averages them to 4-degree pixels).
    Returns ``(rendered geometry, scan-panorama column degrees, heading offset of the render, radians)``.
    """
    col = float(scan_step_deg)  # an int of degrees (1, 2 or 4); the geometry takes a float
    s = supersample
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


def scan_renderer(setup: RouteSetup, rng: np.random.Generator, *, scan_step_deg: float, supersample: int,
                  scan_half_deg: float, view_size):
    """``views(xy, heading) -> (views (S, h, w), offsets (S,))``: the agents' preprocessed scan views.

    A scan of ``+-scan_half_deg`` in ``scan_step_deg`` around the heading, each view ``view_size``
    ``[W, H]`` (:func:`bionav.evaluation.route.scan_views`), cut from the panorama of
    :func:`scan_geometry` (``supersample`` rays per pixel and axis) with the snapshots' camera noise;
    in a recorded world (:func:`recorded_world`) from the nearest recorded view (:func:`_recorded_scan_renderer`).
    """
    if recorded_world(setup):
        return _recorded_scan_renderer(setup, scan_step_deg=scan_step_deg, scan_half_deg=scan_half_deg,
                                       view_size=view_size)
    geometry, col, shift = scan_geometry(scan_step_deg=scan_step_deg, supersample=supersample)

    def panorama(xy, heading):
        key = (scan_step_deg, supersample, float(xy[0]), float(xy[1]), float(heading))
        if key not in setup.scans:
            z = _camera_z(setup, xy)
            img = render_mesh_panorama(setup.world, position=(xy[0], xy[1], z), heading=heading + shift,
                                       geometry=geometry).mean(axis=-1)
            if len(setup.scans) >= MAX_KEPT_SCANS:
                setup.scans.pop(next(iter(setup.scans)))
            setup.scans[key] = box_panorama(img, supersample=supersample, column_deg=col) if supersample > 1 else img
        return setup.scans[key]

    def views(xy, heading):
        img = quantise(panorama(xy, heading), noise=setup.noise, rng=rng).astype(np.float32) / np.float32(255.0)
        return scan_views(img, column_deg=col, scan_half_deg=scan_half_deg, scan_step_deg=col, size=view_size)

    return views


def _recorded_scan_renderer(setup: RouteSetup, *, scan_step_deg: float, scan_half_deg: float, view_size):
    """The scan views of a recorded world: the nearest recorded view resampled to columns of ``scan_step_deg``.

    Columns are area averages (:func:`bionav.homing.imageops.resize_images`) centred on their azimuths;
    rows are the camera's own, resized to ``view_size`` as the rendered scans'.
    """
    from bionav.homing.imageops import resize_images

    col = float(scan_step_deg)
    columns = int(round(360.0 / col))
    width = setup.world.images.shape[-1]
    # area averages of columns j*s .. (j+1)*s - 1 are centred 0.5*col - 0.5*(360/width) deg after the render heading
    centre = math.radians(0.5 * col - 0.5 * 360.0 / width)

    def views(xy, heading):
        pano = setup.world.render(xy, heading - centre)
        img = resize_images(pano[None], (columns, pano.shape[0]))[0]
        return scan_views(img, column_deg=col, scan_half_deg=scan_half_deg, scan_step_deg=col, size=view_size)

    return views


def travel_headings(xy: np.ndarray) -> np.ndarray:
    """Direction of travel from each route view to the next (the last repeats its predecessor's), radians CCW from ``+x``."""
    d = np.diff(np.asarray(xy, np.float64), axis=0)
    h = np.arctan2(d[:, 1], d[:, 0])
    return np.append(h, h[-1]) if len(h) else np.zeros(len(xy))
