"""Databases rendered in triangle-mesh worlds: grids (``db=mesh``, ``db=sim_seville``) and routes.

* :func:`mesh_grid_database` -- a grid of canonical panoramas in any mesh world
  (``db=mesh db.path=FILE db.grid_shape=[nx,ny] db.spacing_m=S
  db.origin_m=[x,y] db.camera_height_m=H``). Cell ``(i, j)`` lies at world
  ``origin_m + spacing_m * (i, j)`` (grid axes = world axes), the camera
  ``camera_height_m`` over the local terrain; cells inside vegetation or under
  the terrain are missing cells.
* :func:`route_database` -- views along a real ant route
  (``db=seville_route db.route=Ant1_Route1 db.step_m=0.1``), each at the
  ant's recorded heading.
* :func:`load_routes` / :func:`load_route` -- routes of the ``AntRoutes.mat``
  layout: ``Ant<a>_Route<r>``, ``n x 3`` = x (cm), y (cm), heading (degrees
  counter-clockwise from ``+x``, the MATLAB convention), converted here to
  metres and radians.

Rendered databases are cached like the synthetic ones (content-hashed
``.npz`` in ``cache_dir``), with camera noise and 8-bit quantisation.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Callable, Iterable, Optional

import numpy as np

from bionav.db.database import ImageDatabase
from bionav.errors import UserError
from bionav.geometry import PanoramaGeometry

#: Bump when the mesh database pipeline changes pixels.
MESH_DATABASE_VERSION = 1
#: Packaged worlds (``db.world=``).
PACKAGED_WORLDS = ("seville2009",)
#: Native size ``(W, H)`` of rendered mesh databases.
NATIVE_SIZE = (561, 81)


def seville_world_path() -> Path:
    """The packaged Seville 2009 ant world (``world5000_gray.mat``, MIT, see its CITATION.md)."""
    from bionav.data import data_path

    return data_path("seville2009", "world5000_gray.mat")


def seville_routes_path() -> Path:
    """The packaged Seville 2009 ant routes (``AntRoutes.mat``)."""
    from bionav.data import data_path

    return data_path("seville2009", "AntRoutes.mat")


@dataclass(frozen=True)
class MeshDatabaseSpec:
    """Parameters of a mesh-world database, derived from a checked ``db`` config (:meth:`from_config`).

    The ranges are declared once, on :class:`bionav.db.config.DatabaseConfig`,
    and checked where the ``db`` node enters (:func:`bionav.db.loading.as_database_config`).

    Attributes
    ----------
    path : Path
        Mesh file (``.mat``, ``.obj``, ``.ply``).
    grid_shape : (int, int)
        ``(nx, ny)`` cells; ``(1, 1)`` for route databases.
    spacing_m : float
        Grid spacing, metres.
    origin_m : (float, float) or None
        World ``(x, y)`` of cell ``(0, 0)``, metres; ``None`` centres the grid on the world.
    camera_height_m : float
        Over the local terrain, metres.
    ground : str
        ``plane`` or ``mesh`` (``auto`` resolved: ``.mat``: plane, else mesh).
    channels : str
        ``grey`` or ``spectral``.
    clearance_m : float or None
        Metres, or ``None`` (any triangle straight above makes a cell missing).
    size : (int, int)
        Rendered ``(W, H)``.
    noise : float
        Camera noise std before quantisation, 0..1.
    step_m : float
        Route databases: path length between views, metres.
    """

    path: Path
    grid_shape: tuple[int, int]
    spacing_m: float
    origin_m: Optional[tuple[float, float]]
    camera_height_m: float
    ground: str
    channels: str
    clearance_m: Optional[float]
    size: tuple[int, int]
    noise: float
    step_m: float

    @classmethod
    def from_config(cls, cfg, *, grid: bool = True) -> "MeshDatabaseSpec":
        """The spec of a checked :class:`~bionav.db.config.DatabaseConfig` (``source`` mesh or route).

        The mesh file is ``db.path``, else the packaged ``db.world``
        (:meth:`DatabaseConfig.validate` requires one of them).
        """
        path = Path(cfg.path).expanduser() if cfg.path is not None else seville_world_path()
        ground = cfg.ground
        if ground == "auto":
            ground = "plane" if path.suffix.lower() == ".mat" else "mesh"
        return cls(path, tuple(cfg.grid_shape) if grid else (1, 1), cfg.spacing_m,
                   None if cfg.origin_m is None else tuple(cfg.origin_m), cfg.camera_height_m, ground, cfg.channels,
                   cfg.clearance_m, NATIVE_SIZE if cfg.image_size is None else tuple(cfg.image_size), cfg.noise,
                   cfg.step_m)

    def geometry(self) -> PanoramaGeometry:
        """Square pixels, horizon on the middle row, rendered directly at ``size``."""
        return PanoramaGeometry.square_pixels(*NATIVE_SIZE).resized(*self.size)


@lru_cache(maxsize=4)
def _world_cached(path: str, mtime: float, ground: str, channels: str):
    from bionav.world.mesh import load_mesh
    from bionav.world.mesh_render import MeshWorld

    return MeshWorld(load_mesh(path), ground=ground, channels=channels)


def mesh_world(path, *, ground: str = "plane", channels: str = "grey"):
    """The :class:`~bionav.world.mesh_render.MeshWorld` of a mesh file (kept in memory per process)."""
    p = Path(path).expanduser()
    if not p.exists():
        raise UserError(f"mesh file {p} does not exist; give db.path=FILE with a .mat, .obj or .ply mesh.")
    return _world_cached(str(p.resolve()), p.stat().st_mtime, ground, channels)


def world_from_spec(spec: MeshDatabaseSpec):
    """The world a validated spec renders in."""
    return mesh_world(spec.path, ground=spec.ground, channels=spec.channels)


def _render_views(world, positions: np.ndarray, headings: np.ndarray, geometry: PanoramaGeometry, *,
                  progress=None, threads: int | None = 1) -> np.ndarray:
    from bionav.world.mesh_render import render_mesh_panorama

    out = np.empty((len(positions), geometry.height, geometry.width, world.n_channels), np.float32)
    it = range(len(positions))
    if progress is not None:
        it = progress(it)
    for k in it:
        out[k] = render_mesh_panorama(world, position=positions[k], heading=float(headings[k]), geometry=geometry,
                                      threads=threads)
    return out


def _cached_render(name: str, params: dict, cache_dir, render: Callable[[], np.ndarray], noise: float, seed: int):
    """Render (or read) quantised uint8 images keyed by ``params``; returns (float images, cache path, from_cache)."""
    from bionav.db.synthetic import quantise, read_cached_images
    from bionav.files import cache_key, default_cache_dir, write_atomic

    key = cache_key(params)
    cdir = Path(cache_dir) if cache_dir is not None else default_cache_dir()
    path = cdir / f"{name}-{key[:20]}.npz"
    images_u8 = read_cached_images(path, key)
    cached = images_u8 is not None
    if not cached:
        rng = np.random.default_rng(np.random.SeedSequence([int(seed) & 0xFFFFFFFF, 0x6D657368]))
        images_u8 = quantise(render(), noise=noise, rng=rng)
        try:
            write_atomic(path, lambda f: np.savez(f, images=images_u8, key=np.array(key),
                                                  params=np.array(json.dumps(params))))
        except OSError:
            pass
    images = images_u8.astype(np.float32) / np.float32(255.0)
    if images.shape[-1] == 1:
        images = images[..., 0]
    return images, path, cached


def grid_world_positions(spec: MeshDatabaseSpec, world) -> tuple[np.ndarray, tuple[float, float]]:
    """World ``(x, y)`` of every grid cell, shape ``(nx, ny, 2)``, and the origin used.

    Raises
    ------
    UserError
        When the grid reaches outside the mesh's ``x, y`` extent (the message
        gives the extent and the largest grid that fits).
    """
    nx, ny = spec.grid_shape
    (x0, y0), (x1, y1) = world.extent()
    span = np.array([(nx - 1) * spec.spacing_m, (ny - 1) * spec.spacing_m])
    if spec.origin_m is None:
        origin = ((x0 + x1 - span[0]) / 2.0, (y0 + y1 - span[1]) / 2.0)
    else:
        origin = spec.origin_m
    gx = origin[0] + spec.spacing_m * np.arange(nx)
    gy = origin[1] + spec.spacing_m * np.arange(ny)
    tol = 1e-9
    if gx[0] < x0 - tol or gx[-1] > x1 + tol or gy[0] < y0 - tol or gy[-1] > y1 + tol:
        fit = (int((x1 - x0) // spec.spacing_m) + 1, int((y1 - y0) // spec.spacing_m) + 1)
        raise UserError(
            f"the grid from ({gx[0]:.3f}, {gy[0]:.3f}) to ({gx[-1]:.3f}, {gy[-1]:.3f}) m lies outside the world "
            f"{spec.path.name}, which spans x {x0:.3f}..{x1:.3f} m, y {y0:.3f}..{y1:.3f} m. Choose db.origin_m, "
            f"db.spacing_m and db.grid_shape so the grid fits (at spacing {spec.spacing_m} m at most "
            f"[{fit[0]}, {fit[1]}] cells), or db.origin_m=null to centre it.")
    xy = np.stack(np.meshgrid(gx, gy, indexing="ij"), axis=-1)
    return xy, (float(origin[0]), float(origin[1]))


def mesh_grid_database(cfg, *, cache_dir=None, progress: Callable[[Iterable], Iterable] | None = None,
                       threads: int | None = 1) -> ImageDatabase:
    """Render (or load from the cache) a grid database in a mesh world.

    Parameters
    ----------
    cfg : DatabaseConfig
        ``path`` or ``world``, ``grid_shape``, ``spacing_m``, ``origin_m``,
        ``camera_height_m``, ``ground``, ``channels``, ``clearance_m``,
        ``image_size``, ``noise``, ``seed`` (noise seed), ``name``.
    cache_dir : path, optional
    progress : callable, optional
        Wraps the render loop on a cache miss.
    threads : int or None
        Render threads per image.

    Returns
    -------
    ImageDatabase
        Heading-0 canonical panoramas of the free cells; ``meta`` holds
        ``origin_m``, ``world_xy`` (N, 2) and ``camera_z`` (N,).
    """
    from bionav.validation import check_allocation
    from bionav.world.mesh_render import MESH_RENDERER_VERSION

    spec = MeshDatabaseSpec.from_config(cfg)
    nx, ny = spec.grid_shape
    check_allocation(  # float32 render buffer plus the 8-bit images of every cell, all bands
        5.0 * nx * ny * spec.size[0] * spec.size[1] * (5 if spec.channels == "spectral" else 1),
        what=f"rendering the {nx} x {ny} cells of {cfg.name!r} at {spec.size[0]} x {spec.size[1]} pixels",
        fix="choose a smaller db.grid_shape=[nx,ny] or db.image_size=[W,H]")
    world = world_from_spec(spec)
    xy, origin = grid_world_positions(spec, world)
    cam, free = world.camera_positions(xy.reshape(-1, 2), height=spec.camera_height_m, clearance_m=spec.clearance_m)
    free = free.reshape(spec.grid_shape)
    if not free.any():
        raise UserError(f"every cell of the {spec.grid_shape[0]}x{spec.grid_shape[1]} grid lies inside an object or "
                        f"off the terrain of {spec.path.name}; move it with db.origin_m or set db.clearance_m.")
    positions = np.argwhere(free).astype(np.int64)
    cam = cam.reshape(spec.grid_shape + (3,))[free]
    geometry = spec.geometry()
    params = {"mesh_renderer": MESH_RENDERER_VERSION, "database": MESH_DATABASE_VERSION, "kind": "grid",
              "mesh": world.mesh.digest(), "ground": spec.ground, "ground_z": float(world.ground_z),
              "channels": spec.channels, "geometry": [geometry.width, geometry.height, geometry.horizon_row,
                                                      geometry.rad_per_row],
              "cameras": np.round(cam, 9).tolist(), "noise": spec.noise, "seed": cfg.seed}
    images, path, cached = _cached_render(
        cfg.name, params, cache_dir,
        lambda: _render_views(world, cam, np.zeros(len(cam)), geometry, progress=progress, threads=threads),
        spec.noise, cfg.seed)
    meta = {"source": "mesh", "world": str(spec.path), "origin_m": list(origin), "spacing_m": spec.spacing_m,
            "camera_height_m": spec.camera_height_m, "ground": spec.ground, "channels": list(world.band_names),
            "world_xy": cam[:, :2].tolist(), "camera_z": cam[:, 2].tolist(), "cache_file": str(path),
            "from_cache": cached, "n_missing": int((~free).sum())}
    db = ImageDatabase(name=cfg.name, images=images, positions=positions, grid_shape=spec.grid_shape,
                       geometry=geometry, spacing_m=spec.spacing_m, meta=meta)
    if cfg.rotate_current:
        from bionav.db.rotation import rotate_views

        db = rotate_views(db, seed=cfg.rotation_seed)
    return db


# --- routes -------------------------------------------------------------------------------------------

_ROUTE_RE = re.compile(r"^Ant(\d+)_Route(\d+)$")


@lru_cache(maxsize=4)
def _routes_cached(path: str, mtime: float) -> dict[str, np.ndarray]:
    import scipy.io

    try:
        data = scipy.io.loadmat(path)
    except Exception as exc:
        raise UserError(f"{path} is not a readable MATLAB .mat file of routes ({type(exc).__name__}: {exc}); "
                        "give db.routes_path=FILE with Ant<a>_Route<r> arrays of n x 3 (x cm, y cm, heading deg).") from None
    routes = {}
    for k, v in data.items():
        if k.startswith("__"):
            continue
        a = np.asarray(v)
        if a.ndim == 2 and a.shape[1] >= 2 and a.shape[0] >= 2 and np.issubdtype(a.dtype, np.number):
            routes[k] = a.astype(np.float64)
    if not routes:
        raise UserError(f"{path} holds no routes (n x 3 arrays of x cm, y cm, heading deg); found: "
                        f"{', '.join(sorted(k for k in data if not k.startswith('__'))) or 'nothing'}.")
    return routes


def load_routes(path=None) -> dict[str, np.ndarray]:
    """Every route of an ``AntRoutes.mat``-style file, raw (x cm, y cm, heading deg), keyed by name."""
    p = Path(path).expanduser() if path is not None else seville_routes_path()
    if not p.exists():
        raise UserError(f"routes file {p} does not exist; give db.routes_path=FILE or leave it unset for the "
                        "packaged Seville routes.")
    return _routes_cached(str(p.resolve()), p.stat().st_mtime)


def _route_sort_key(name: str):
    m = _ROUTE_RE.match(name)
    return (0, int(m.group(1)), int(m.group(2))) if m else (1, name, 0)


def route_names(path=None) -> list[str]:
    """Names of the routes in a routes file, ordered by ant and route number."""
    return sorted(load_routes(path), key=_route_sort_key)


def _summarise_names(names: list[str]) -> str:
    """``Ant1_Route1..5, Ant2_Route1..3, ...`` (one entry per ant)."""
    by_ant: dict[str, list[int]] = {}
    other = []
    for n in names:
        m = _ROUTE_RE.match(n)
        if m:
            by_ant.setdefault(m.group(1), []).append(int(m.group(2)))
        else:
            other.append(n)
    parts = []
    for ant, rs in by_ant.items():
        rs = sorted(rs)
        parts.append(f"Ant{ant}_Route{rs[0]}" + (f"..{rs[-1]}" if len(rs) > 1 else "")
                     + ("" if rs == list(range(rs[0], rs[-1] + 1)) else f" ({', '.join(map(str, rs))})"))
    return ", ".join(parts + other)


@dataclass(frozen=True)
class Route:
    """One route in bionav's units.

    Attributes
    ----------
    name : str
    xy : ndarray, shape (n, 2)
        Positions in metres (the file's centimetres / 100).
    heading : ndarray, shape (n,)
        Radians counter-clockwise from ``+x`` (the file's MATLAB degrees, converted).
    """

    name: str
    xy: np.ndarray
    heading: np.ndarray

    @property
    def length_m(self) -> float:
        """Path length in metres."""
        return float(np.linalg.norm(np.diff(self.xy, axis=0), axis=1).sum())

    def resample(self, step_m: float) -> "Route":
        """Points every ``step_m`` metres of path length (first and last point kept), headings of the nearest sample."""
        seg = np.linalg.norm(np.diff(self.xy, axis=0), axis=1)
        s = np.concatenate([[0.0], np.cumsum(seg)])
        targets = np.arange(0.0, s[-1], step_m)
        if s[-1] - targets[-1] > 1e-9:
            targets = np.append(targets, s[-1])
        x = np.interp(targets, s, self.xy[:, 0])
        y = np.interp(targets, s, self.xy[:, 1])
        idx = np.clip(np.searchsorted(s, targets), 0, len(s) - 1)
        return Route(self.name, np.column_stack([x, y]), self.heading[idx])


def load_route(name: str, path=None) -> Route:
    """One route by name (``Ant1_Route1``), converted to metres and radians.

    Raises
    ------
    UserError
        Unknown route (the message lists the routes that exist).
    """
    routes = load_routes(path)
    if name is None or str(name) not in routes:
        names = sorted(routes, key=_route_sort_key)
        raise UserError(f"there is no route {name!r}; choose db.route=<name> from the {len(names)} routes: "
                        f"{_summarise_names(names)}.")
    a = routes[str(name)]
    xy = a[:, :2] / 100.0  # centimetres -> metres
    if a.shape[1] >= 3:
        heading = np.deg2rad(a[:, 2])  # MATLAB degrees CCW from +x -> radians
    else:
        d = np.gradient(xy, axis=0)
        heading = np.arctan2(d[:, 1], d[:, 0])
    return Route(str(name), xy, heading)


def route_database(cfg, *, cache_dir=None, progress=None, threads: int | None = 1) -> ImageDatabase:
    """Views along a route (``db=seville_route db.route=Ant1_Route1``), each at the recorded heading.

    Positions are the view indices ``(k, 0)`` along the route (grid shape
    ``(n, 1)``, spacing ``step_m``); ``headings`` the recorded headings in
    radians; ``meta["world_xy"]`` the positions in metres.
    """
    from bionav.world.mesh_render import MESH_RENDERER_VERSION

    spec = MeshDatabaseSpec.from_config(cfg, grid=False)
    route = load_route(cfg.route, cfg.routes_path).resample(spec.step_m)
    world = world_from_spec(spec)
    (x0, y0), (x1, y1) = world.extent()
    out = (route.xy[:, 0] < x0) | (route.xy[:, 0] > x1) | (route.xy[:, 1] < y0) | (route.xy[:, 1] > y1)
    if out.all():
        raise UserError(f"route {route.name} lies outside the world {spec.path.name} (x {x0:.2f}..{x1:.2f} m, "
                        f"y {y0:.2f}..{y1:.2f} m); routes and world must share one frame (routes in cm).")
    cam, _free = world.camera_positions(route.xy, height=spec.camera_height_m, clearance_m=spec.clearance_m)
    cam[:, 2] = np.where(np.isfinite(cam[:, 2]), cam[:, 2], world.ground_z + spec.camera_height_m)
    geometry = spec.geometry()
    params = {"mesh_renderer": MESH_RENDERER_VERSION, "database": MESH_DATABASE_VERSION, "kind": "route",
              "mesh": world.mesh.digest(), "ground": spec.ground, "channels": spec.channels,
              "geometry": [geometry.width, geometry.height, geometry.horizon_row, geometry.rad_per_row],
              "cameras": np.round(cam, 9).tolist(), "headings": np.round(route.heading, 12).tolist(),
              "noise": spec.noise, "seed": cfg.seed}
    images, path, cached = _cached_render(
        f"{cfg.name}-{route.name}", params, cache_dir,
        lambda: _render_views(world, cam, route.heading, geometry, progress=progress, threads=threads),
        spec.noise, cfg.seed)
    n = len(route.xy)
    meta = {"source": "route", "kind": "route", "world": str(spec.path), "route": route.name,
            "step_m": spec.step_m, "world_xy": route.xy.tolist(), "camera_z": cam[:, 2].tolist(),
            "camera_height_m": spec.camera_height_m, "cache_file": str(path), "from_cache": cached}
    return ImageDatabase(name=f"{cfg.name}:{route.name}", images=images,
                         positions=np.column_stack([np.arange(n), np.zeros(n, np.int64)]), grid_shape=(n, 1),
                         geometry=geometry, spacing_m=spec.step_m, headings=route.heading.copy(), meta=meta)
