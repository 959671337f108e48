"""The camera of the synthetic stand-ins (``db.realism=camera``): mirror, sensor, unfolding, pose errors.

For every capture pose the raw catadioptric frame is rendered by ray casting
(:mod:`bionav.world.catadioptric`), passed through a sensor model and 8-bit
quantised, then unfolded with bionav's own unfolding
(:func:`bionav.db.unfold.unfold_panorama`) into the database's canonical
panorama geometry, so the resolution of the panorama varies with elevation as
on the real robots (thesis 3.1). The sensor model, in the order light meets it:

1. optics blur: Gaussian point-spread function, ``psf_sigma_px`` raw pixels;
2. vignetting: relative illumination ``1 - vignetting * (r / r_rim)**2``
   (the quadratic term of the cos^4 law; r the raw radius);
3. automatic exposure: the mean level of the unfolded annulus is driven to
   ``ae_target`` by the exposure time (at most ``max_exposure`` times the
   world's nominal exposure), then by analogue gain (at most ``max_gain``);
   dark scenes stay dark and get noisier (a world's ``light_level`` below 1,
   the night hall, scales the light before the sensor);
4. photon shot noise (``full_well_e`` electrons at full scale, Poisson,
   approximated as Gaussian) and read noise (``read_noise_e`` electrons), both
   amplified by the gain; clipping at full scale; 8-bit quantisation;
5. unfolding (bilinear) and 8-bit quantisation of the panorama (the real
   databases are 8-bit unfolded images).

Capture poses get Gaussian position and heading errors
(:func:`pose_offsets`); the database keeps the nominal grid positions.

Below the native size (561 x 81) the raw frame is rendered at a
proportionally reduced resolution, as if the sensor binned pixels (the blur
radius scales along; the full-well capacity and the read noise add up over the
binned pixels), so tiny databases stay cheap. Above it the raw frame keeps its
size: a larger ``db.image_size`` unfolds the same raw pixels, as in the thesis.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Callable, Iterable

import numpy as np

from bionav.db.config import CameraConfig, PoseErrorConfig
from bionav.db.unfold import unfold_panorama
from bionav.geometry import PanoramaGeometry
from bionav.world.catadioptric import MirrorProjection, RawFrameLayout, raw_frame_layout, render_raw_frame
from bionav.world.render import thread_count, map_in_threads
from bionav.world.scene import Scene

#: Bump whenever a change to the camera pipeline changes pixels (part of the cache key).
CAMERA_VERSION = 2

#: The two mirrors of thesis 3.1 (Accowle Ltd.): the rim elevation is the upper limit of the field
#: of view (thesis: about 26-46 deg for the ultra-wide-view mirror, 10-26 deg for the normal-view
#: mirror; we take 36 and 20 deg); mirror_xi and the rim radius on a 640 x 480 frame are assumptions
#: (docs/databases.md).
MIRRORS = {
    "ultra-wide": dict(mirror_xi=0.82, rim_elevation_deg=36.0, rim_radius_px=230.0),
    "normal-view": dict(mirror_xi=0.60, rim_elevation_deg=20.0, rim_radius_px=230.0),
}

#: Capture-pose errors per kind of position record (thesis 3.1): robot odometry (Vardy's lab and
#: hall databases), odometry supervised and corrected semi-automatically (moeller1, roeben1;
#: Kreft 2007), odometry of the four-wheeled outdoor robot on a 1 m grid (uni; Schatz 2006).
#: The thesis gives no numbers: these are stated assumptions (docs/databases.md).
POSE_ERRORS = {
    "odometry": dict(position_sigma_m=0.02, heading_sigma_deg=1.5),
    "semi-automatic": dict(position_sigma_m=0.01, heading_sigma_deg=1.0),
    "outdoor-odometry": dict(position_sigma_m=0.05, heading_sigma_deg=3.0),
}


def raw_horizon_radius(mirror: str, camera: CameraConfig | None = None) -> float:
    """Radius in pixels of the horizon circle in the full raw frame, ``gamma / xi`` (thesis Butterworth cutoffs).

    Parameters
    ----------
    mirror : str
        ``ultra-wide`` or ``normal-view`` (:data:`MIRRORS`), used when ``camera`` is None.
    camera : CameraConfig, optional
        An explicit camera.
    """
    cam = camera if camera is not None else CameraConfig(**MIRRORS[mirror])
    proj = MirrorProjection.from_rim(xi=float(cam.mirror_xi), rim_elevation_deg=float(cam.rim_elevation_deg),
                                     rim_radius_px=float(cam.rim_radius_px), center=(0.0, 0.0))
    return float(proj.radius_from_elevation(0.0))


def camera_config_for(mirror: str, **overrides) -> CameraConfig:
    """The :class:`CameraConfig` of a mirror type (``ultra-wide`` or ``normal-view``) plus overrides."""
    return CameraConfig(**{**MIRRORS[mirror], **overrides})


def pose_error_config_for(kind: str, **overrides) -> PoseErrorConfig:
    """The :class:`PoseErrorConfig` of a position record kind (:data:`POSE_ERRORS`) plus overrides."""
    return PoseErrorConfig(**{**POSE_ERRORS[kind], **overrides})


def _seeded_normals(keys, n: int, *, seed: int, db_seed: int, tag: int) -> np.ndarray:
    """``n`` standard normal draws per row of ``keys`` (M, k) ints, each row from its own stream.

    The stream of a row is ``SeedSequence([seed, db_seed, tag, *row])`` (seeds
    taken modulo 2**32), so a draw depends only on its key and the seeds, not
    on which other keys are drawn. Returns shape ``(M, n)``.
    """
    keys = np.asarray(keys, dtype=np.int64)
    head = [int(seed) & 0xFFFFFFFF, int(db_seed) & 0xFFFFFFFF, int(tag)]
    draw = np.empty((len(keys), int(n)))
    for k, key in enumerate(keys):
        draw[k] = np.random.default_rng(np.random.SeedSequence([*head, *map(int, key)])).standard_normal(int(n))
    return draw


def pose_offsets(cells, *, position_sigma_m: float, heading_sigma_deg: float, seed: int,
                 db_seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Gaussian capture-pose errors of the images at grid ``cells``.

    The error of a cell depends only on the cell and the seeds, not on which
    other cells are rendered (a contact sheet shows the database's poses).

    Parameters
    ----------
    cells : array_like, shape (N, 2), int
        Grid cells ``(i, j)``.
    position_sigma_m : float
        Standard deviation of the position error per axis, metres.
    heading_sigma_deg : float
        Standard deviation of the heading error, degrees.
    seed, db_seed : int
        ``db.pose_error.seed`` and ``db.seed``; the errors are a function of both.

    Returns
    -------
    offsets : ndarray, shape (N, 2)
        ``(dx, dy)`` in metres, world frame.
    headings : ndarray, shape (N,)
        Heading errors in radians (counter-clockwise).
    """
    cells = np.asarray(cells, dtype=np.int64).reshape(-1, 2)
    draw = _seeded_normals(cells, 3, seed=seed, db_seed=db_seed, tag=0x706F7365)
    return draw[:, :2] * float(position_sigma_m), draw[:, 2] * math.radians(float(heading_sigma_deg))


def lane_heading_drift(cells, *, drift_sigma_deg: float, seed: int, db_seed: int = 0) -> np.ndarray:
    """Odometry's heading drift at grid ``cells``: a random walk over the turns between lanes.

    The robot drives its lanes along the grid's ``j`` axis, lane ``i`` after
    lane ``i - 1`` (:func:`bionav.world.worlds.common.lane_order` with
    ``lane_axis=1``); each turn between two
    lanes adds a Gaussian heading error (std ``drift_sigma_deg``) that stays
    with all later lanes, since correcting the position does not correct the
    heading. Lane 0 has no drift. A lane's drift depends only on the seeds and
    the lane, not on which cells are rendered.

    Parameters
    ----------
    cells : array_like, shape (N, 2), int
        Grid cells ``(i, j)``; ``i`` is the lane.
    drift_sigma_deg : float
        Standard deviation of the heading change per lane turn, degrees.
    seed, db_seed : int
        ``db.pose_error.seed`` and ``db.seed``.

    Returns
    -------
    ndarray, shape (N,)
        Heading errors in radians (counter-clockwise), to be added to those of :func:`pose_offsets`.
    """
    cells = np.asarray(cells, dtype=np.int64).reshape(-1, 2)
    if len(cells) == 0 or float(drift_sigma_deg) == 0.0:
        return np.zeros(len(cells))
    lanes = np.arange(1, int(cells[:, 0].max()) + 1)
    steps = _seeded_normals(lanes[:, None], 1, seed=seed, db_seed=db_seed, tag=0x64726674)[:, 0]
    walk = np.concatenate([[0.0], np.cumsum(steps)])
    return walk[np.clip(cells[:, 0], 0, None)] * math.radians(float(drift_sigma_deg))


def noise_rng(seed: int, cell) -> np.random.Generator:
    """The generator of the sensor noise of the image at grid ``cell = (i, j)`` (``seed`` = ``db.seed``)."""
    return np.random.default_rng(np.random.SeedSequence([int(seed) & 0xFFFFFFFF, 0x63616D65, int(cell[0]),
                                                         int(cell[1])]))


def tilt_offsets(cells, *, tilt_sigma_deg: float, seed: int, db_seed: int = 0) -> np.ndarray:
    """Gaussian camera tilts of the captures at grid ``cells`` (N, 2) (uneven floor, mast sway;
    :attr:`World.floor_tilt_deg`).

    Drawn per cell from their own random stream, so the position and heading
    errors of :func:`pose_offsets` do not depend on them, nor a cell's tilt on
    the other cells rendered.

    Returns
    -------
    ndarray, shape (n, 2)
        ``(t_a, t_b)`` in radians: a view at panorama azimuth ``phi`` (column
        angle) is raised by ``t_a cos(phi) + t_b sin(phi)`` (small-angle tilt).
    """
    cells = np.asarray(cells, dtype=np.int64).reshape(-1, 2)
    draw = _seeded_normals(cells, 2, seed=seed, db_seed=db_seed, tag=0x74696C74)
    return draw * math.radians(float(tilt_sigma_deg))


def resolve_pose_error(pose_error: PoseErrorConfig, world) -> PoseErrorConfig:
    """``pose_error`` with ``tilt_sigma_deg=None`` and ``heading_drift_deg=None`` replaced by the world's floor
    (``World.floor_tilt_deg``, ``World.heading_drift_deg``)."""
    if pose_error.tilt_sigma_deg is None:
        pose_error = dataclasses.replace(pose_error, tilt_sigma_deg=float(getattr(world, "floor_tilt_deg", 0.0)))
    if pose_error.heading_drift_deg is None:
        pose_error = dataclasses.replace(pose_error,
                                         heading_drift_deg=float(getattr(world, "heading_drift_deg", 0.0)))
    return pose_error


def tilted_row_radii(setup: "CameraSetup", geometry: PanoramaGeometry, tilt) -> np.ndarray:
    """Raw radius of every panorama pixel ``(H, W)`` for a camera tilted by ``tilt = (t_a, t_b)`` radians.

    A tilted camera, unfolded as if upright, shows at row ``r`` and column
    ``j`` the world direction at elevation ``e_r + t_a cos(phi_j) + t_b
    sin(phi_j)`` (first order in the tilt; the azimuth change is of second
    order near the horizon), which the upright raw frame holds at
    ``radius_from_elevation`` of that elevation. Elevations beyond the mirror
    rim fall outside the frame (read 0).
    """
    phi = 2.0 * np.pi * np.arange(geometry.width) / geometry.width
    el = geometry.row_elevations()[:, None] + float(tilt[0]) * np.cos(phi)[None, :] + float(tilt[1]) * np.sin(phi)[None, :]
    proj = setup.projection
    inside = el < proj.rim_elevation
    return np.where(inside, proj.radius_from_elevation(np.where(inside, el, 0.0)), 1e6)


@dataclass(frozen=True)
class CameraSetup:
    """A camera prepared for one output geometry (see :func:`camera_setup`)."""

    camera: CameraConfig
    layout: RawFrameLayout
    projection: MirrorProjection
    scale: float
    band: tuple[float, float]  # radii of the unfolded annulus (bottom and top pixel edges)
    row_radii: np.ndarray  # (H,) raw radius of every panorama row
    psf_sigma: float
    full_well: float
    read_noise: float


def camera_setup(camera: CameraConfig, geometry: PanoramaGeometry, *, native_size=(561, 81),
                 tilt_margin: float = 0.0) -> CameraSetup:
    """Mirror projection, ray layout and sensor constants for unfolding to ``geometry``.

    Parameters
    ----------
    camera : CameraConfig
    geometry : PanoramaGeometry
        The unfolded panorama (rows evenly spaced in elevation).
    native_size : (int, int)
        The stand-in's native panorama size; smaller outputs bin the raw frame by
        ``scale = max(W / W_native, H / H_native)`` (at most 1).
    tilt_margin : float
        Largest camera tilt in radians the rendered annulus must allow for
        (:func:`tilted_row_radii`); widens the annulus accordingly.

    Returns
    -------
    CameraSetup
    """
    w_raw, h_raw = (int(v) for v in camera.raw_size)
    scale = min(1.0, max(geometry.width / native_size[0], geometry.height / native_size[1]))
    w_eff, h_eff = max(16, int(round(w_raw * scale))), max(16, int(round(h_raw * scale)))
    center = ((w_eff - 1) / 2.0, (h_eff - 1) / 2.0)
    full = MirrorProjection.from_rim(xi=float(camera.mirror_xi), rim_elevation_deg=float(camera.rim_elevation_deg),
                                     rim_radius_px=float(camera.rim_radius_px), center=((w_raw - 1) / 2.0,
                                                                                         (h_raw - 1) / 2.0))
    proj = full.scaled(scale, center)
    top = (geometry.horizon_row + 0.5) * geometry.rad_per_row
    bottom = (geometry.horizon_row - geometry.height + 0.5) * geometry.rad_per_row
    if not top < proj.rim_elevation:
        raise ValueError(f"the panorama reaches {math.degrees(top):.1f} deg, above the mirror rim at "
                         f"{math.degrees(proj.rim_elevation):.1f} deg (db.camera.rim_elevation_deg)")
    band = (float(proj.radius_from_elevation(bottom)), float(proj.radius_from_elevation(top)))
    psf = float(camera.psf_sigma_px) * scale
    margin = 3.0 * psf + 2.0
    if tilt_margin > 0:  # a tilted camera shows elevations up to tilt_margin beyond the panorama's rows
        low = max(bottom - float(tilt_margin), -0.5 * math.pi + 1e-3)
        high = min(top + float(tilt_margin), proj.rim_elevation)
        margin += max(abs(band[0] - float(proj.radius_from_elevation(low))),
                      abs(float(proj.radius_from_elevation(high)) - band[1]))
    layout = raw_frame_layout(proj, raw_size=(w_eff, h_eff),
                              radius_range=(band[0] - margin, min(band[1] + margin, proj.rim_radius)))
    return CameraSetup(camera, layout, proj, scale, band, proj.radius_from_elevation(geometry.row_elevations()),
                       psf, float(camera.full_well_e) / scale ** 2, float(camera.read_noise_e) / scale)


def raw_frame_from_radiance(radiance: np.ndarray, setup: CameraSetup, *, rng: np.random.Generator) -> np.ndarray:
    """The 8-bit raw frame a sensor makes of a raw radiance frame (steps 1-4 of the module docstring).

    Parameters
    ----------
    radiance : ndarray, shape (h, w, C), float
        Raw radiance frame times the world's nominal exposure (1.0 = full scale at gain 1).
    setup : CameraSetup
    rng : numpy.random.Generator
        Draws the noise.

    Returns
    -------
    ndarray, shape (h, w, C), uint8
    """
    import cv2

    cam = setup.camera
    h, w, n_ch = radiance.shape
    # the sensor is simulated on the square around the rendered annulus; the rest of the frame reads 0
    reach = setup.layout.radius_range[1] + 1.0
    cx, cy = setup.projection.center
    y0, y1 = max(0, int(math.floor(cy - reach))), min(h, int(math.ceil(cy + reach)) + 1)
    x0, x1 = max(0, int(math.floor(cx - reach))), min(w, int(math.ceil(cx + reach)) + 1)
    x = np.ascontiguousarray(radiance[y0:y1, x0:x1], dtype=np.float32)
    if setup.psf_sigma > 0.05:
        k = 2 * int(math.ceil(3.0 * setup.psf_sigma)) + 1
        x = cv2.GaussianBlur(x, (k, k), setup.psf_sigma, borderType=cv2.BORDER_REFLECT).reshape(x.shape)
    rad = setup.layout.radius[y0:y1, x0:x1]
    x = x * (1.0 - float(cam.vignetting) * (rad / setup.projection.rim_radius) ** 2)[:, :, None].astype(np.float32)
    time, gain = 1.0, 1.0
    if cam.auto_exposure:
        inside = (rad >= setup.band[0]) & (rad <= setup.band[1])
        level = float(x[inside].mean(dtype=np.float64)) if inside.any() else 0.0
        if level > 0:
            time = min(float(cam.ae_target) / level, float(cam.max_exposure))
            gain = float(np.clip(float(cam.ae_target) / (level * time), 1.0, float(cam.max_gain)))
        else:
            time, gain = float(cam.max_exposure), float(cam.max_gain)
    electrons = np.maximum(x.astype(np.float64) * (time * setup.full_well), 0.0)
    noisy = electrons + np.sqrt(electrons) * rng.standard_normal(electrons.shape)
    if setup.read_noise > 0:
        noisy += setup.read_noise * rng.standard_normal(electrons.shape)
    value = noisy * (gain / setup.full_well)
    out = np.zeros((h, w, n_ch), np.uint8)
    out[y0:y1, x0:x1] = np.clip(np.rint(value * 255.0), 0, 255).astype(np.uint8)
    return out


def unfold_frame(raw_u8: np.ndarray, setup: CameraSetup, geometry: PanoramaGeometry, *, tilt=None) -> np.ndarray:
    """Unfold an 8-bit raw frame ``(h, w, C)`` into the 8-bit canonical panorama ``(H, W, C)``.

    ``tilt = (t_a, t_b)`` radians: the frame of an upright camera unfolded as the
    frame of a camera tilted by that much would be (:func:`tilted_row_radii`).
    """
    raw = np.asarray(raw_u8, dtype=np.float64) / 255.0
    radii = setup.row_radii if tilt is None or not np.any(tilt) else tilted_row_radii(setup, geometry, tilt)
    chans = [unfold_panorama(raw[:, :, c], center=setup.projection.center, radii=radii,
                             size=(geometry.width, geometry.height)) for c in range(raw.shape[2])]
    return np.clip(np.rint(np.stack(chans, axis=-1).astype(np.float64) * 255.0), 0, 255).astype(np.uint8)


def session_seed(seed: int, db_seed: int = 0) -> int:
    """Seed of what happened during a recording session besides the pose errors.

    A recording session is one draw of everything that happened while the
    database was taken: the pose errors, the clouds
    (:class:`bionav.light.capture.CaptureLight`) and where the supervisor
    stood (:class:`bionav.world.worlds.common.Supervisor`) share
    ``db.pose_error.seed`` (and ``db.seed``); the world as it was at each capture is
    :meth:`bionav.world.worlds.common.World.capture_scenes` with this seed.
    """
    return int(np.random.SeedSequence([int(db_seed) & 0xFFFFFFFF, int(seed) & 0xFFFFFFFF, 0x44415921])
               .generate_state(1)[0])


def camera_images(world, positions: np.ndarray, geometry: PanoramaGeometry, *, camera: CameraConfig,
                  pose_error: PoseErrorConfig, seed: int, native_size=(561, 81),
                  progress: Callable[[Iterable], Iterable] | None = None, threads: int | None = 1,
                  keep_raw: bool = False):
    """8-bit unfolded panoramas (and optionally raw frames) of a world at grid cells, through the camera model.

    Parameters
    ----------
    world : bionav.world.worlds.common.World
        Has ``scene`` and ``cell_position(i, j) -> (x, y, z)``.
    positions : ndarray, shape (N, 2), int
        Grid cells ``(i, j)``.
    geometry : PanoramaGeometry
        Unfolded panorama geometry.
    camera : CameraConfig
    pose_error : PoseErrorConfig
    seed : int
        ``db.seed``; seeds the sensor noise (per cell, :func:`noise_rng`) and,
        with ``pose_error.seed``, the pose errors (per cell, :func:`pose_offsets`).
    native_size : (int, int)
        The stand-in's native panorama size (see :func:`camera_setup`).
    progress : callable, optional
        Wraps the loop over images.
    threads : int or None
        Render threads.
    keep_raw : bool
        Also return the 8-bit raw frames.

    Returns
    -------
    images : ndarray, shape (N, H, W, C), uint8
    raw : ndarray, shape (N, h, w, C), uint8, or None
    poses : dict
        ``offsets_m`` (N, 2), ``heading_errors`` (N,) and ``tilts`` (N, 2)
        radians actually used (:func:`tilt_offsets`).
    """
    pose_error = resolve_pose_error(pose_error, world)
    n = len(positions)
    offsets, dheads = pose_offsets(positions, position_sigma_m=float(pose_error.position_sigma_m),
                                   heading_sigma_deg=float(pose_error.heading_sigma_deg),
                                   seed=int(pose_error.seed), db_seed=int(seed))
    dheads = dheads + lane_heading_drift(positions, drift_sigma_deg=float(pose_error.heading_drift_deg),
                                         seed=int(pose_error.seed), db_seed=int(seed))
    tilts = tilt_offsets(positions, tilt_sigma_deg=float(pose_error.tilt_sigma_deg), seed=int(pose_error.seed),
                         db_seed=int(seed))
    setup = camera_setup(camera, geometry, native_size=native_size,
                         tilt_margin=float(np.abs(tilts).sum(axis=1).max(initial=0.0)))
    out = np.empty((n, geometry.height, geometry.width, world.scene.n_channels), np.uint8)
    w, h = setup.layout.raw_size
    raws = np.empty((n, h, w, world.scene.n_channels), np.uint8) if keep_raw else None
    it = range(n)
    if progress is not None:
        it = progress(it)
    # the world as it was at each capture (the capture light, outdoors or through windows; the supervisor)
    scene_at = world.capture_scenes(positions, seed=session_seed(int(pose_error.seed), int(seed)))
    light_level = float(getattr(world, "light_level", 1.0))
    n_threads = thread_count(threads)
    if scene_at is None and n_threads > 1:
        world.scene.compiled().shadow_bins()  # built once before the threads share the scene

    def capture(k: int) -> tuple[np.ndarray, np.ndarray]:
        """View ``k``'s raw frame (8 bits) and its unfolded panorama; every view on its own (own noise stream)."""
        i, j = positions[k]
        x, y, z = world.cell_position(i, j)
        scene = world.scene if scene_at is None else scene_at(k)
        radiance = render_raw_frame(scene, position=(x + offsets[k, 0], y + offsets[k, 1], z),
                                    heading=float(dheads[k]), layout=setup.layout, threads=1)
        if not isinstance(scene, Scene):  # a compiled session scene renders without the scene's exposure
            radiance *= float(world.scene.exposure)
        if light_level != 1.0:  # a dim scene (the night hall): the automatic exposure has to make up for it
            radiance *= light_level
        raw = raw_frame_from_radiance(radiance, setup, rng=noise_rng(seed, (i, j)))
        return raw, unfold_frame(raw, setup, geometry, tilt=tilts[k])

    # whole views on the threads (render and camera model), not the columns of one view: the camera model's
    # NumPy work, a quarter of a view's time, then runs beside another view's render instead of alone
    views = map_in_threads(capture, range(n), threads=n_threads) if n_threads > 1 else map(capture, range(n))
    try:
        for k in it:
            raw, out[k] = next(views)
            if raws is not None:
                raws[k] = raw
    finally:
        close = getattr(views, "close", None)
        if close is not None:  # the views handed out and not started are cancelled
            close()
    return out, raws, {"offsets_m": offsets, "heading_errors": dheads, "tilts": tilts}
