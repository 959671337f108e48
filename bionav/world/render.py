"""Rendering canonical unfolded panoramas of a :class:`~bionav.world.scene.Scene`."""

from __future__ import annotations

from typing import Sequence

import numba
import numpy as np

from bionav.geometry import TWO_PI, PanoramaGeometry
from bionav.world.kernels import depth_kernel, render_kernel
from bionav.world.scene import CompiledScene, Scene

#: Bump whenever a change to the renderer or a world builder changes pixels (invalidates caches).
RENDERER_VERSION = 2


def _run_threads(threads: int | None, kernel, *args) -> None:
    """Run a parallel kernel on ``threads`` threads (None = numba's default); the result does not depend on it."""
    n = numba.config.NUMBA_NUM_THREADS if threads is None else max(1, min(int(threads),
                                                                          numba.config.NUMBA_NUM_THREADS))
    prev = numba.get_num_threads()
    numba.set_num_threads(n)
    try:
        kernel(*args)
    finally:
        numba.set_num_threads(prev)


def _compiled(scene: Scene | CompiledScene) -> CompiledScene:
    return scene if isinstance(scene, CompiledScene) else scene.compiled()


def ray_grid(geometry: PanoramaGeometry, heading: float = 0.0, *, supersample: int = 1):
    """Azimuths (world frame) and elevations of the rays of a canonical panorama.

    Column ``j`` looks at azimuth ``heading + 2*pi*j/W`` (radians CCW from world
    ``+x``); row ``r`` at elevation ``(horizon_row - r) * rad_per_row``. With
    ``supersample = s`` every pixel is split into ``s x s`` sub-pixel rays
    (centred on the pixel), giving arrays of ``W*s`` and ``H*s`` entries.

    Returns
    -------
    az : ndarray, shape (W*s,)
    el : ndarray, shape (H*s,)
    """
    w, h = geometry.width, geometry.height
    off = float(heading) * w / TWO_PI
    if abs(off - round(off)) < 1e-9:  # exact integer column shifts make rotations exact rolls
        off = float(round(off))
    s = int(supersample)
    sub = (np.arange(s) + 0.5) / s - 0.5
    cols = (np.arange(w)[:, None] + sub[None, :]).ravel()
    rows = (np.arange(h)[:, None] + sub[None, :]).ravel()
    az = TWO_PI * (((cols + off) % w) / w)
    el = (geometry.horizon_row - rows) * geometry.rad_per_row
    return az, el


def render_panorama(scene: Scene | CompiledScene, *, position: Sequence[float], heading: float = 0.0,
                    geometry: PanoramaGeometry, supersample: int = 1, shadows: bool = True,
                    exposure: float | None = None, sky=None, clip: bool = True,
                    threads: int | None = 1) -> np.ndarray:
    """Render the canonical unfolded panorama seen from a pose.

    Ray casting with analytic intersections, Lambertian shading with a
    hemispherical ambient term, point and directional lights with hard
    shadows, and mip-mapped procedural textures. Deterministic: the same scene
    and pose give bit-identical images.

    Parameters
    ----------
    scene : Scene or CompiledScene
        The world (a :class:`Scene` caches its compiled form between calls).
    position : sequence of 3 float
        Camera (mirror) position ``(x, y, z)`` in metres, world frame.
    heading : float
        Robot heading in radians CCW from world ``+x``; column 0 of the result
        looks along it. Rendering with heading ``h = 2*pi*k/W`` equals the
        heading-0 panorama rolled by ``-k`` columns (``np.roll(img, -k, 1)``).
    geometry : PanoramaGeometry
        Output size ``W x H``, horizon row and elevation step (see
        :mod:`bionav.geometry`); rendering happens directly at this size.
    supersample : int
        Rays per pixel along each axis (1 = one ray through each pixel centre).
    shadows : bool
        Trace shadow rays towards the lights.
    exposure : float, optional
        Radiance-to-pixel gain; defaults to ``scene.exposure`` (1 for a
        :class:`CompiledScene`).
    sky : callable, optional
        ``sky(directions (N, 3)) -> (N, C)`` radiance of rays that hit nothing;
        defaults to ``scene.sky`` (black if None).
    clip : bool
        Clip the result to ``[0, 1]``.
    threads : int or None
        Threads for the row-parallel kernel (``None``: numba's default, all
        cores). One thread by default: on a shared machine the thread pool
        costs more than it gains for small images. Results are identical for
        any number of threads.

    Returns
    -------
    ndarray, shape (H, W, C), float32
        Pixel values (``exposure * radiance``), row 0 on top.
    """
    cs = _compiled(scene)
    if exposure is None:
        exposure = scene.exposure if isinstance(scene, Scene) else 1.0
    if sky is None and isinstance(scene, Scene):
        sky = scene.sky
    ss = int(supersample)
    if ss < 1:
        raise ValueError("supersample must be >= 1")
    az, el = ray_grid(geometry, heading, supersample=ss)
    pix = max(geometry.rad_per_column, geometry.rad_per_row) / ss
    out = render_ray_grid(cs, position=position, azimuths=az, elevations=el, pixel_angle=pix, sky=sky,
                          shadows=shadows, threads=threads)
    C = out.shape[2]
    if ss > 1:
        out = out.reshape(geometry.height, ss, geometry.width, ss, C).mean(axis=(1, 3))
    out *= exposure
    if clip:
        np.clip(out, 0.0, 1.0, out=out)
    return out.astype(np.float32)


def render_ray_grid(scene: Scene | CompiledScene, *, position: Sequence[float], azimuths: np.ndarray,
                    elevations: np.ndarray, pixel_angle: float, sky=None, shadows: bool = True,
                    threads: int | None = 1) -> np.ndarray:
    """Radiance along a separable grid of rays (any azimuths x any elevations).

    The building block of :func:`render_panorama` (evenly spaced rows) and of
    the catadioptric raw-frame renderer (:mod:`bionav.world.catadioptric`),
    whose rows are the elevations of evenly spaced mirror radii.

    Parameters
    ----------
    scene : Scene or CompiledScene
    position : sequence of 3 float
        Ray origin ``(x, y, z)`` in metres, world frame.
    azimuths : ndarray, shape (W,)
        World azimuths in radians, counter-clockwise from world ``+x``.
    elevations : ndarray, shape (H,)
        Elevations in radians above the horizon.
    pixel_angle : float
        Angular footprint of one ray in radians (selects the texture mip level).
    sky : callable, optional
        ``sky(directions (N, 3)) -> (N, C)`` for rays that hit nothing (black if None;
        a :class:`Scene`'s own sky is *not* used here, pass it explicitly).
    shadows, threads
        As in :func:`render_panorama`.

    Returns
    -------
    ndarray, shape (H, W, C), float64
        Radiance (no exposure, no clipping).
    """
    cs = _compiled(scene)
    az = np.ascontiguousarray(azimuths, dtype=np.float64)
    el = np.ascontiguousarray(elevations, dtype=np.float64)
    ox, oy, oz = (float(v) for v in position)
    C = cs.mat_albedo.shape[1]
    out = np.empty((el.size, az.size, C), np.float64)
    depth = np.empty((el.size, az.size))
    sky_mask = np.zeros((el.size, az.size), np.bool_)
    _run_threads(threads, render_kernel, ox, oy, oz, az, el, float(pixel_angle),
                  cs.boxes, cs.box_mats, cs.frusta, cs.frustum_mats, cs.ellipsoids, cs.ellipsoid_mats,
                  cs.prim_kind, cs.prim_idx, cs.spheres, cs.shadow_grids, cs.shadow_starts, cs.shadow_items,
                  cs.mat_tex, cs.mat_fit, cs.mat_scale, cs.mat_albedo, cs.mat_emission, cs.tex_data,
                  cs.tex_size, cs.light_params, cs.light_power, cs.ambient_up, cs.ambient_down, bool(shadows),
                  out, depth, sky_mask)
    if sky is not None and sky_mask.any():
        rr, jj = np.nonzero(sky_mask)
        ce = np.cos(el[rr])
        dirs = np.stack([ce * np.cos(az[jj]), ce * np.sin(az[jj]), np.sin(el[rr])], axis=1)
        rad = np.asarray(sky(dirs), np.float64).reshape(len(rr), -1)
        out[rr, jj, :] = rad
    return out


def renderer_compiled() -> bool:
    """True when the render kernel's compiled code is at hand (this process, or numba's on-disk cache)."""
    from bionav.files import numba_cached

    return numba_cached(render_kernel)


def prepare_renderer(scene: Scene | CompiledScene) -> None:
    """Compile (or load from numba's cache) the render kernel for ``scene`` before a long render.

    One ray is rendered: the same argument types as every view of the scene, so the views that follow
    run at their own speed and a progress bar's rate (and ETA) is the render's, not the compiler's.
    """
    render_ray_grid(scene, position=(0.0, 0.0, 0.0), azimuths=np.zeros(1), elevations=np.zeros(1),
                    pixel_angle=1e-3)


def render_depth(scene: Scene | CompiledScene, *, position: Sequence[float], heading: float = 0.0,
                 geometry: PanoramaGeometry, threads: int | None = 1) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Distance to the nearest surface for every pixel of a canonical panorama.

    Parameters
    ----------
    scene, position, heading, geometry, threads
        As in :func:`render_panorama`.

    Returns
    -------
    depth : ndarray, shape (H, W)
        Distance along the ray in metres (``inf`` where nothing is hit).
    kind : ndarray, shape (H, W), int
        Primitive kind hit: 0 box, 1 frustum, 2 ellipsoid, -1 none.
    index : ndarray, shape (H, W), int
        Index of the primitive within its kind (-1 for none).
    """
    cs = _compiled(scene)
    az, el = ray_grid(geometry, heading)
    depth = np.empty((el.size, az.size))
    kind = np.empty((el.size, az.size), np.int64)
    index = np.empty((el.size, az.size), np.int64)
    ox, oy, oz = (float(v) for v in position)
    pix = max(geometry.rad_per_column, geometry.rad_per_row)
    _run_threads(
        threads,
        depth_kernel,
        ox,
        oy,
        oz,
        az,
        el,
        pix,
        cs.prim_kind,
        cs.prim_idx,
        cs.spheres,
        cs.boxes,
        cs.frusta,
        cs.ellipsoids,
        depth,
        kind,
        index,
    )
    return depth, kind, index
