"""Synthetic stand-ins for the image databases of thesis table 3.1.

``synthetic_database("sim_original")`` renders (or loads from the on-disk
cache) a grid of canonical panoramas in a procedurally generated world with
the grid shape, spacing and mirror field of view of the real database, adds
camera noise and 8-bit quantisation, and optionally rotates every image by a
random whole number of columns (Vardy's protocol for current views).

The stand-ins (:data:`bionav.db.standins.SYNTHETIC_DATABASES`):

=============== ======= ======= ======== ======= ==========================================
name            grid    spacing #images  mirror  world
=============== ======= ======= ======== ======= ==========================================
sim_original    10x17   0.3 m   170      ultra   laboratory, curtains closed, both bands on
sim_arboreal    10x17   0.3 m   170      ultra   + arboreal plant in the middle
sim_chairs      10x17   0.3 m   170      ultra   + office chairs
sim_day         10x17   0.3 m   170      ultra   curtains open, daylight
sim_doorlit     10x17   0.3 m   170      ultra   only the door-side light band on
sim_screen      10x17   0.3 m   170      ultra   + white projection screen
sim_twilight    10x17   0.3 m   170      ultra   curtains open, twilight
sim_winlit      10x17   0.3 m   170      ultra   only the window-side light band on
sim_hall1       10x20   0.5 m   170      ultra   dim achromatic hall with pillars
sim_hall2       10x20   0.5 m   170      ultra   another part of the hall
sim_moeller1    11x22   0.1 m   242      ultra   living room
sim_roeben1     11x36   0.1 m   396      ultra   living room with kitchen
sim_uni         10x17   1.0 m   170      normal  outdoors: buildings, trees, sky, sun
=============== ======= ======= ======== ======= ==========================================
"""

from __future__ import annotations

import dataclasses
import json
import logging
from pathlib import Path
from typing import Callable, Iterable

import numpy as np

from bionav.db.database import ImageDatabase
from bionav.db.standins import (  # noqa: F401  (the stand-ins' table: its home is db/standins.py)
    NATIVE_SIZE,
    SYNTHETIC_DATABASES,
    SyntheticSpec,
    get_spec,
    normal_view_geometry,
    synthetic_database_names,
    ultra_wide_geometry,
)
from bionav.errors import UserError
from bionav.files import cache_key, default_cache_dir, write_atomic
from bionav.geometry import PanoramaGeometry

log = logging.getLogger(__name__)

#: Bump when the database pipeline (noise, quantisation, layout) changes.
DATABASE_VERSION = 1


def read_cached_images(path: Path, key: str) -> np.ndarray | None:
    """The ``images`` array of a cached ``.npz`` whose ``key`` matches; None if absent, stale or unreadable."""
    if not Path(path).exists():
        return None
    try:
        with np.load(path, allow_pickle=False) as z:
            if str(z["key"]) == key:
                return z["images"]
    except (OSError, ValueError, KeyError):
        pass  # unreadable cache file: the caller renders again and overwrites it
    return None


def quantise(images: np.ndarray, *, noise: float, rng: np.random.Generator) -> np.ndarray:
    """Add Gaussian camera noise (std ``noise``) and quantise to 8 bits.

    Parameters
    ----------
    images : ndarray, float in [0, 1]
    noise : float
        Standard deviation of the additive noise in units of full scale.
    rng : numpy.random.Generator

    Returns
    -------
    ndarray, uint8, same shape
    """
    x = np.asarray(images, np.float64)
    if noise > 0:
        x = x + rng.normal(0.0, noise, size=x.shape)
    return np.clip(np.rint(x * 255.0), 0, 255).astype(np.uint8)


def render_world_images(world, positions: np.ndarray, geometry: PanoramaGeometry, *,
                        progress: Callable[[Iterable], Iterable] | None = None, threads: int | None = 1) -> np.ndarray:
    """Render the canonical panoramas (heading 0) at the given grid cells.

    Returns
    -------
    ndarray, shape (N, H, W, C), float32 in [0, 1]
    """
    from bionav.world.render import render_panorama

    out = np.empty((len(positions), geometry.height, geometry.width, world.scene.n_channels), np.float32)
    it = range(len(positions))
    if progress is not None:
        it = progress(it)
    for k in it:
        i, j = positions[k]
        out[k] = render_panorama(world.scene, position=world.cell_position(i, j), heading=0.0, geometry=geometry,
                                 threads=threads)
    return out


def synthetic_database(name: str, *, image_size: tuple[int, int] | list[int] | None = None, seed: int = 0,
                       noise: float = 0.01, rotate_current: bool = False, rotation_seed: int = 0,
                       cache_dir: str | Path | None = None,
                       progress: Callable[[Iterable], Iterable] | None = None,
                       threads: int | None = 1, realism: str = "ideal", camera=None,
                       pose_error=None) -> ImageDatabase:
    """Render (or load from cache) one synthetic stand-in database.

    Parameters
    ----------
    name : str
        One of :func:`synthetic_database_names` (``sim_original`` ...).
    image_size : (int, int), optional
        ``(W, H)``; the images are rendered directly at this size with the
        mirror's field of view (:meth:`PanoramaGeometry.resized`). Default
        :data:`NATIVE_SIZE`. Values are not checked here: the limits of
        ``db.image_size`` are declared once (:data:`bionav.db.config.IMAGE_SIZE`,
        W >= 8, H >= 2) and checked where the ``db`` node enters
        (:func:`bionav.db.loading.as_database_config`).
    seed : int
        Which world of this kind (``db.seed``); also seeds the camera noise.
    noise : float
        Standard deviation of the camera noise before 8-bit quantisation.
    rotate_current : bool
        Roll every image by a random whole number of columns ``k`` (Vardy's
        protocol, :func:`bionav.db.rotation.rotate_views`);
        ``headings[i] = 2*pi*k_i/W`` records the rotation (radians CCW from
        grid +x).
    rotation_seed : int
        Seed of the random rotations.
    cache_dir : path, optional
        Where rendered databases are cached (``.npz``, keyed by a hash of
        every world and render parameter); default :func:`default_cache_dir`.
    progress : callable, optional
        Wraps the render loop (e.g. ``ctx.progress``), called only on a cache miss.
    threads : int or None
        Render threads (see :func:`bionav.world.render.render_panorama`);
        the images do not depend on it.
    realism : {"ideal", "camera"}
        ``ideal``: panoramas rendered directly, Gaussian ``noise``, 8-bit (the
        original pipeline). ``camera``: the raw catadioptric frame through the
        mirror, sensor and unfolding of :mod:`bionav.db.camera`, at capture poses
        with errors (``noise`` is not used). The ``db=sim_*`` configs choose
        ``camera``.
    camera : CameraConfig, optional
        Camera of ``realism="camera"``; default: the stand-in's mirror
        (:func:`bionav.db.camera.camera_config_for`).
    pose_error : PoseErrorConfig, optional
        Pose errors of ``realism="camera"``; default: the stand-in's
        (:func:`bionav.db.camera.pose_error_config_for`).

    Returns
    -------
    ImageDatabase
        Canonical panoramas ``(N, H, W)`` (grey) or ``(N, H, W, C)``, float32
        in [0, 1], positions ``(N, 2)`` of the existing cells.
    """
    spec = get_spec(name)
    w, h = image_size if image_size is not None else spec.native_size
    geometry = spec.geometry(w, h)
    world = spec.builder(int(seed))
    positions = np.argwhere(world.cells).astype(np.int64)
    _check_world(name, spec, world, positions, w, h)
    params = _cache_params(name, int(seed), noise, geometry, world, positions)
    if realism == "camera":
        camera, pose_error = _add_camera_params(params, spec, world, camera, pose_error, geometry)
    key = cache_key(params)
    path = (Path(cache_dir) if cache_dir is not None else default_cache_dir()) / \
        f"{name}-{w}x{h}-seed{int(seed)}{'' if realism == 'ideal' else '-camera'}-{key[:20]}.npz"
    images_u8, cached = _cached_or_rendered(path, key, params, world, positions, geometry, spec, int(seed), noise,
                                            realism, camera, pose_error, progress, threads)
    meta = _meta(spec, world, path, cached, int(seed), noise, realism, rotate_current, rotation_seed, camera,
                 pose_error)
    db = ImageDatabase(name=name, images=_float_images(images_u8), positions=positions,
                       grid_shape=tuple(spec.grid_shape), geometry=geometry, spacing_m=float(spec.spacing_m), meta=meta)
    return _rotated(db, rotation_seed) if rotate_current else db


def _check_world(name: str, spec, world, positions: np.ndarray, w: int, h: int) -> None:
    """Refuse a render that would not fit in memory; the world's grid must be the table's."""
    from bionav.validation import check_allocation

    check_allocation(  # float32 render buffer plus the 8-bit images
        5.0 * len(positions) * w * h,
        what=f"rendering the {len(positions)} images of {name!r} at db.image_size=[{w},{h}]",
        fix="choose a smaller db.image_size=[W,H] (the thesis uses up to [600,100])",
    )
    if world.grid_shape != spec.grid_shape:
        raise RuntimeError(f"{name}: world grid {world.grid_shape} differs from table {spec.grid_shape}")


def _cache_params(name: str, seed: int, noise: float, geometry, world, positions: np.ndarray) -> dict:
    """Every world and render parameter the cached images depend on (hashed into the cache key)."""
    from bionav.world.render import RENDERER_VERSION

    compiled_digest = world.scene.compile().digest()
    params = {
        "renderer_version": RENDERER_VERSION,
        "database_version": DATABASE_VERSION,
        "name": name,
        "seed": seed,
        "noise": float(noise),
        "geometry": [geometry.width, geometry.height, geometry.horizon_row, geometry.rad_per_row],
        "grid_origin": list(map(float, world.grid_origin)),
        "spacing": float(world.spacing),
        "camera_height": float(world.camera_height),
        "positions": positions.tolist(),
        "exposure": float(world.scene.exposure),
        "scene": compiled_digest,
    }
    if "sky" in world.info:  # the scene's sky (not in the compiled digest): the campus' SimpleSky
        params["sky"] = world.info["sky"]
    return params


def _add_camera_params(params: dict, spec, world, camera, pose_error, geometry):
    """The camera and pose errors of ``realism="camera"`` (resolved), their keys added to ``params``."""
    from bionav.db.camera import resolve_pose_error
    from bionav.world.worlds.common import OpenSky, Windows

    camera, pose_error = _camera_configs(spec, camera, pose_error, geometry)
    pose_error = resolve_pose_error(pose_error, world)  # tilt_sigma_deg=None: the world's floor
    del params["noise"]
    pose_key = dataclasses.asdict(pose_error)
    if pose_key["heading_drift_deg"] == 0.0:  # no drift: the key (and cache) of the stand-ins before the drift
        del pose_key["heading_drift_deg"]
    params.update(realism="camera", camera_version=_camera_version(), camera=dataclasses.asdict(camera),
                  pose_error=pose_key, native_size=list(spec.native_size))
    light, aperture = getattr(world, "capture_light", None), getattr(world, "aperture", None)
    if light is not None and isinstance(aperture, Windows):  # the light of a recording session through windows
        params["daylight"] = light.describe()
        params["windows"] = dataclasses.asdict(aperture)
    if getattr(world, "supervisor", None) is not None:
        params["supervisor"] = dataclasses.asdict(world.supervisor)
    if getattr(world, "light_level", 1.0) != 1.0:  # a dim scene; 1 keeps the key of the other worlds
        params["light_level"] = float(world.light_level)
    if light is not None and isinstance(aperture, OpenSky):  # light changing during the capture outdoors (sim_uni)
        params["capture_light"] = light.describe()
        params.pop("sky", None)  # each capture's sky is the capture light's, not the scene's
    return camera, pose_error


def _cached_or_rendered(path: Path, key: str, params: dict, world, positions, geometry, spec, seed: int,
                        noise: float, realism: str, camera, pose_error, progress, threads):
    """The 8-bit images from the cache file ``path``, or rendered and written there; and whether cached."""
    images_u8 = read_cached_images(path, key)
    cached = images_u8 is not None
    if not cached:
        _prepare_renderer(spec, world)
    if not cached and realism == "camera":
        from bionav.db.camera import camera_images

        images_u8, _, _ = camera_images(world, positions, geometry, camera=camera, pose_error=pose_error,
                                        seed=seed, native_size=spec.native_size, progress=progress,
                                        threads=threads)
    elif not cached:
        imgs = render_world_images(world, positions, geometry, progress=progress, threads=threads)
        rng = np.random.default_rng(np.random.SeedSequence([seed & 0xFFFFFFFF, 0x6E6F6973]))
        images_u8 = quantise(imgs, noise=noise, rng=rng)
    if not cached:
        try:
            write_atomic(path, lambda f: np.savez(f, images=images_u8, positions=positions, key=np.array(key),
                                                  params=np.array(json.dumps(params))))
        except OSError:
            pass  # a read-only cache is not fatal: the database is still returned
    return images_u8, cached


def _prepare_renderer(spec, world) -> None:
    """Say what the first render waits for, and compile before the progress bar starts (its ETA is then honest)."""
    from bionav.world.render import prepare_renderer, renderer_compiled

    if not renderer_compiled():
        log.info("rendering %s (%d views) for the first time: compiling the renderer first (numba, once per "
                 "installation and cached; about 15 s on 2 idle cores) ...", spec.name, spec.n_images)
    prepare_renderer(world.scene)


def _float_images(images_u8: np.ndarray) -> np.ndarray:
    """8-bit images as float32 in [0, 1]; one channel dropped to ``(N, H, W)``."""
    images = images_u8.astype(np.float32) / np.float32(255.0)
    if images.shape[-1] == 1:
        images = images[..., 0]
    return images


def _meta(spec, world, path: Path, cached: bool, seed: int, noise: float, realism: str, rotate_current: bool,
          rotation_seed: int, camera, pose_error) -> dict:
    """The database's ``meta``: where it came from, its camera and the cache file."""
    meta = {
        "source": "synthetic",
        "world": spec.description,
        "seed": seed,
        "noise": float(noise),
        "mirror": spec.mirror,
        "channels": list(world.scene.channels),
        "grid_origin_m": list(map(float, world.grid_origin)),
        "camera_height_m": float(world.camera_height),
        "cache_file": str(path),
        "from_cache": cached,
        "rotate_current": bool(rotate_current),
        "rotation_seed": int(rotation_seed),
        "realism": realism,
    }
    from bionav.db.camera import raw_horizon_radius

    meta["raw_horizon_radius_px"] = raw_horizon_radius(spec.mirror, camera if realism == "camera" else None)
    if realism == "camera":
        meta.pop("noise")
        meta["camera"] = dataclasses.asdict(camera)
        meta["pose_error"] = dataclasses.asdict(pose_error)
    return meta


def _rotated(db: ImageDatabase, rotation_seed: int) -> ImageDatabase:
    """Every view rolled by a random whole number of columns (:func:`bionav.db.rotation.rotate_views`)."""
    from bionav.db.rotation import rotate_views

    return rotate_views(db, seed=rotation_seed)


def _camera_version() -> int:
    from bionav.db.camera import CAMERA_VERSION

    return CAMERA_VERSION


def _camera_configs(spec: SyntheticSpec, camera, pose_error, geometry: PanoramaGeometry):
    """Validated camera and pose-error configs of ``realism="camera"`` (defaults: the stand-in's own)."""
    from bionav.db.camera import camera_config_for, pose_error_config_for
    from bionav.db.config import CameraConfig, PoseErrorConfig
    from bionav.validation import checked_config

    if camera is None:
        camera = camera_config_for(spec.mirror)
    elif not isinstance(camera, CameraConfig):
        camera = CameraConfig(**dict(camera))
    if pose_error is None:
        pose_error = pose_error_config_for(spec.positions_from)
    elif not isinstance(pose_error, PoseErrorConfig):
        pose_error = PoseErrorConfig(**dict(pose_error))
    checked_config(camera, prefix="db.camera")  # built here or in Python; a typed db node's were checked once
    checked_config(pose_error, prefix="db.pose_error")
    xi, rim = float(camera.mirror_xi), float(camera.rim_elevation_deg)
    if not np.sin(np.radians(rim)) < xi:
        raise UserError(f"db.camera.mirror_xi={xi:g} must exceed sin(db.camera.rim_elevation_deg)="
                        f"{np.sin(np.radians(rim)):.3f}: a hyperbolic mirror sees only up to asin(xi) = "
                        f"{np.degrees(np.arcsin(min(xi, 1.0))):.1f} deg; raise mirror_xi or lower the rim elevation.")
    top = np.degrees((geometry.horizon_row + 0.5) * geometry.rad_per_row)
    if not top < rim:
        raise UserError(f"db.camera.rim_elevation_deg={rim:g} lies below the top of the panorama ({top:.1f} deg); "
                        f"choose a rim elevation above {top:.1f} deg.")
    if float(camera.rim_radius_px) > 0.5 * min(camera.raw_size):
        raise UserError(f"db.camera.rim_radius_px={camera.rim_radius_px:g} does not fit in the raw frame "
                        f"db.camera.raw_size={list(camera.raw_size)}; choose at most {0.5 * min(camera.raw_size):g}.")
    return camera, pose_error
