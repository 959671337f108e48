"""Rendering canonical unfolded panoramas of a :class:`~bionav.world.scene.Scene`."""

from __future__ import annotations

import collections
import itertools
import threading
from concurrent.futures import ThreadPoolExecutor
from typing import Callable, Iterable, Iterator, Sequence, TypeVar

import numba
import numpy as np

from bionav.geometry import TWO_PI, PanoramaGeometry
from bionav.world.kernels import depth_kernel, render_kernel
from bionav.world.scene import CompiledScene, Scene

#: Bump whenever a change to the renderer or a world builder changes pixels (invalidates caches).
RENDERER_VERSION = 2

A = TypeVar("A")
T = TypeVar("T")

#: shadow bins of no light, for renders without shadow rays (the kernel's argument types)
_NO_SHADOW_BINS = (np.zeros((0, 6)), np.zeros((0, 1), np.int64), np.zeros((0, 1), np.int64))


def thread_count(threads: int | None) -> int:
    """Render threads: ``threads`` capped to numba's thread count (``NUMBA_NUM_THREADS``, all cores by default; None: that many)."""
    cap = numba.config.NUMBA_NUM_THREADS
    return cap if threads is None else max(1, min(int(threads), cap))


_POOL: ThreadPoolExecutor | None = None
_POOL_LOCK = threading.Lock()


def map_in_threads(fn: Callable[[A], T], items: Iterable[A], *, threads: int) -> Iterator[T]:
    """``map(fn, items)`` on ``threads`` threads of one shared pool: results in order, as they are taken.

    For work that releases the GIL (the render kernel, most of NumPy). At most ``2 * threads``
    items are handed out ahead of the one taken, and those not started are cancelled when the
    caller stops taking (an error, Ctrl-C), so nothing renders on after it. ``fn`` must not itself
    wait for this pool (a render inside runs with ``threads=1``).
    """
    global _POOL
    with _POOL_LOCK:
        if _POOL is None or _POOL._max_workers < threads:
            _POOL = ThreadPoolExecutor(max_workers=threads, thread_name_prefix="bionav-render")
        pool = _POOL
    items = iter(items)
    pending = collections.deque(pool.submit(fn, x) for x in itertools.islice(items, 2 * threads))
    try:
        while pending:
            done = pending.popleft()
            for x in itertools.islice(items, 1):
                pending.append(pool.submit(fn, x))
            yield done.result()
    finally:
        for future in pending:
            future.cancel()


def _in_column_blocks(render_columns: Callable[[int, int], T], width: int, threads: int) -> list[T]:
    """``render_columns(j0, j1)`` over blocks of the ``width`` columns, on ``threads`` threads, in column order.

    Rays are independent, so the blocks give the same values as one call over all columns. With
    more than one thread the columns are cut into ``4 * threads`` blocks (a block of sky costs less
    than one of walls) taken by the threads of one shared pool as they come free; the render kernel
    releases the GIL.
    """
    n_blocks = 1 if threads <= 1 else min(width, 4 * threads)
    if n_blocks <= 1:
        return [render_columns(0, width)]
    edges = np.linspace(0, width, n_blocks + 1).round().astype(int)
    return list(map_in_threads(lambda edge: render_columns(*edge), zip(edges[:-1].tolist(), edges[1:].tolist()),
                               threads=threads))


def _run_threads(threads: int | None, kernel, *args) -> None:
    """Run a ``parallel=True`` kernel on ``threads`` threads (None = numba's default); the result does not depend on it."""
    n = thread_count(threads)
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
        Threads rendering blocks of columns (``None``: numba's thread count,
        all cores unless ``NUMBA_NUM_THREADS`` says otherwise). One thread by
        default: on a shared machine the threads cost more than they gain for
        small images. Results are identical for any number of threads.

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
    grids, starts, items = cs.shadow_bins() if shadows else _NO_SHADOW_BINS

    def columns(j0: int, j1: int):
        block_out = np.empty((el.size, j1 - j0, C), np.float64)
        block_depth = np.empty((el.size, j1 - j0))
        block_sky = np.zeros((el.size, j1 - j0), np.bool_)
        render_kernel(ox, oy, oz, az[j0:j1], el, float(pixel_angle),
                      cs.boxes, cs.box_mats, cs.frusta, cs.frustum_mats, cs.ellipsoids, cs.ellipsoid_mats,
                      cs.prim_kind, cs.prim_idx, cs.spheres, grids, starts, items,
                      cs.mat_tex, cs.mat_fit, cs.mat_scale, cs.mat_albedo, cs.mat_emission, cs.tex_data,
                      cs.tex_size, cs.light_params, cs.light_power, cs.ambient_up, cs.ambient_down, bool(shadows),
                      block_out, block_depth, block_sky)
        return block_out, block_sky

    blocks = _in_column_blocks(columns, az.size, thread_count(threads))
    out = blocks[0][0] if len(blocks) == 1 else np.concatenate([b[0] for b in blocks], axis=1)
    sky_mask = blocks[0][1] if len(blocks) == 1 else np.concatenate([b[1] for b in blocks], axis=1)
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
    It casts no shadow ray, so the scene's shadow bins are not built yet (nor compiled).
    """
    render_ray_grid(scene, position=(0.0, 0.0, 0.0), azimuths=np.zeros(1), elevations=np.zeros(1),
                    pixel_angle=1e-3, shadows=False)


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
