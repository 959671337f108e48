"""Outdoor campus world (stand-in for *uni*, thesis 3.1): buildings, trees, sky and sun.

The 10 x 17 grid (1 m spacing, 9 m x 16 m) lies north of a large university
building's entrance (``+y`` is north), in the building's shadow as in the
thesis; other buildings, trees (deciduous and conifers), hedges, lamp posts,
bike racks, benches and bollards stand around it at 2-80 m.

Channels are pluggable: pass band names plus per-kind albedos and a sky
callable to render multi-band (e.g. UV, B, G, R, IR) images; the defaults of
:mod:`bionav.light.materials` and :mod:`bionav.light.simple_sky` are used otherwise.
"""

from __future__ import annotations

from typing import Callable, Mapping, Sequence

import numpy as np

from bionav.geometry import direction_from_angles
from bionav.light.capture import CaptureLight
from bionav.light.clouds import CloudLayer
from bionav.light.materials import band_albedos
from bionav.light.simple_sky import SKY_GAIN, SUN_GAIN, SimpleSky
from bionav.world import textures as tx
from bionav.world.lights import Ambient, DirectionalLight
from bionav.world.scene import Scene, SkyFunction
from bionav.world.worlds.common import OpenSky, World, lane_order, stream
from bionav.world.worlds.furniture import tree

GRID_SHAPE = (10, 17)
SPACING = 1.0
CAMERA_HEIGHT = 0.8
#: Least distance in metres between a tree and the capture area (thesis 3.1: distant buildings and trees).
TREE_CLEARANCE = 7.0
#: Camera tilt std (degrees) of the four-wheeled robot on the level paving (joints, mast sway; World.floor_tilt_deg).
FLOOR_TILT_DEG = 0.35
#: Value range of the paving texture (worn grey slabs, low contrast in the building's shadow).
PAVING_TEXTURE = (0.45, 0.6)

# The capture of uni took a while outdoors (thesis 3.1: 170 images on a 1 m grid, Schatz 2006), so the
# light changed between captures. The thesis gives neither date nor duration; these are stated
# assumptions (docs/databases.md, "uni: light changes during the capture").
#: Bielefeld University, north entrance (latitude, longitude in degrees).
SITE_DEG = (52.037, 8.494)
#: Start of the capture (UTC): a day near the equinox, late morning, so the sun stands about 31-33 deg
#: high in the south during the whole capture and the grid stays in the main building's shadow.
CAPTURE_START_UTC = "2006-03-06T10:50:00"
#: Seconds per capture: drive 1 m, stop, let the mast settle, grab and store (one lane after the other).
SECONDS_PER_CAPTURE = 30.0
#: Fraction of the sky covered by (fair-weather cumulus) clouds.
CLOUD_COVER = 0.4
#: Cloud base height (m) and horizontal scale (m) of the cloud layer (:class:`~bionav.light.clouds.CloudLayer`:
#: waves of 300-1200 m wavelength, fair-weather cumulus a few hundred metres across).
CLOUD_HEIGHT_M, CLOUD_SCALE_M = 1500.0, 600.0
#: Cloud edge width (standard deviations of the field) and the angular resolution (degrees) at which the
#: layer is seen: sharper than the sun's disk (0.53 deg), so a cloud covers the sun fully or not at all
#: but for its edge.
CLOUD_SOFTNESS, CLOUD_RESOLUTION_DEG = 0.2, 0.1
#: Wind at the cloud base (east, north) in m/s: 8 m/s from the west (the prevailing westerlies).
WIND_MPS = (8.0, 0.0)
#: Radiance of a cloud relative to the clear sky's horizon value (sunlit cumulus are brighter than blue sky).
CLOUD_RADIANCE = 1.25
#: Optical depth of a cloud for the direct sun: with the sun 31-33 deg high (air mass 1.9) a cloud in front of
#: it lets exp(-1.9) = 15 % of the direct sunlight through.
CLOUD_OPTICAL_DEPTH = 1.0


def capture_order(cells: np.ndarray) -> np.ndarray:
    """Capture index of every existing grid cell (:func:`~bionav.world.worlds.common.lane_order`, lanes along y).

    Parameters
    ----------
    cells : ndarray, shape (nx, ny), bool

    Returns
    -------
    ndarray, shape (nx, ny), int
        0, 1, 2 ... in the order the robot visited the cells; -1 where no cell exists.
    """
    cells = np.asarray(cells, bool)
    order = np.full(cells.shape, -1, np.int64)
    order[cells] = np.argsort(np.argsort(lane_order(cells.shape, lane_axis=1)[cells]))
    return order


def campus_clouds(seed: int) -> CloudLayer:
    """The campus' cloud layer (:class:`~bionav.light.clouds.CloudLayer`) with this module's assumptions.

    One layer for the campus' sky and the uni capture's light: the default sky
    of :func:`build_campus` shows it at ``time_s=0`` (the clouds of the first
    capture, frozen), :func:`uni_capture_light` lets it drift over the sky and
    the sun during the capture.

    Parameters
    ----------
    seed : int
        The world's seed (the layer's).
    """
    return CloudLayer(cover=CLOUD_COVER, optical_depth=CLOUD_OPTICAL_DEPTH, seed=int(seed), height_m=CLOUD_HEIGHT_M,
                      scale_m=CLOUD_SCALE_M, wind_mps=WIND_MPS, softness=CLOUD_SOFTNESS,
                      resolution=float(np.deg2rad(CLOUD_RESOLUTION_DEG)), brightness=CLOUD_RADIANCE)


def uni_capture_light(cells: np.ndarray, seed: int) -> CaptureLight:
    """The light of the uni capture (:class:`~bionav.light.capture.CaptureLight`) with this module's assumptions.

    Parameters
    ----------
    cells : ndarray, shape (10, 17), bool
        The grid cells that exist (their :func:`capture_order`).
    seed : int
        The world's seed (the cloud layer's, :func:`campus_clouds`).
    """
    return CaptureLight(order=capture_order(cells), clouds=campus_clouds(seed), site_deg=SITE_DEG,
                        start_utc=CAPTURE_START_UTC, seconds_per_capture=SECONDS_PER_CAPTURE)


def build_campus(seed: int = 0, *, channels: Sequence[str] = ("grey",),
                 albedos: Mapping[str, Sequence[float]] | None = None, sky: SkyFunction | None = None,
                 sun_elevation: float = np.deg2rad(35.0), sun_azimuth: float = -np.pi / 2,
                 sun_irradiance: Sequence[float] | float | None = None,
                 sky_irradiance: Sequence[float] | float | None = None, exposure: float = 1.1) -> World:
    """Build the outdoor campus world.

    Parameters
    ----------
    seed : int
        Which campus (building sizes, tree placement, textures).
    channels : sequence of str
        Band names, e.g. ``("grey",)`` or ``("UV", "B", "G", "R", "IR")``.
    albedos : mapping, optional
        Material kind -> per-band albedo (length ``len(channels)``). Kinds used:
        ``concrete brick glass foliage bark grass paving asphalt metal paint
        wood soil``. Default :func:`bionav.light.materials.band_albedos`.
    sky : callable, optional
        ``sky(directions (N, 3)) -> radiance (N, C)``; default
        :class:`~bionav.light.simple_sky.SimpleSky` for the sun position behind
        the campus' cloud layer (:func:`campus_clouds`, at ``time_s=0``);
        its parameters are recorded as ``World.info["sky"]`` (a render cache key).
    sun_elevation, sun_azimuth : float
        Sun position in radians (azimuth CCW from world ``+x``; ``-pi/2`` is
        south, so the grid north of the main building lies in its shadow).
    sun_irradiance, sky_irradiance : float or sequence, optional
        Per-band direct-sun irradiance and diffuse sky irradiance (ambient on
        upward faces); defaults scale :data:`~bionav.light.simple_sky.SUN_GAIN` /
        :data:`~bionav.light.simple_sky.SKY_GAIN`.
    exposure : float
        Camera gain.

    Returns
    -------
    World
        10 x 17 grid at 1.0 m, camera 0.8 m above the ground.
    """
    channels = tuple(channels)
    c = len(channels)
    table = band_albedos(channels) if albedos is None else {k: np.asarray(v, float) for k, v in albedos.items()}
    for k, v in table.items():
        if np.asarray(v).reshape(-1).size not in (1, c):
            raise ValueError(f"albedo of {k!r} must have 1 or {c} values")
    sun = tuple(float(v) for v in direction_from_angles(sun_azimuth, sun_elevation))
    info = {"sun_elevation": float(sun_elevation), "sun_azimuth": float(sun_azimuth), "channels": channels}
    if sky is None:
        sky = SimpleSky(sun_direction=sun, channels=channels, layer=campus_clouds(seed))
        info["sky"] = sky.describe()
    if sun_irradiance is None:
        sun_irradiance = [2.2 * SUN_GAIN.get(ch, 1.0) for ch in channels]
    if sky_irradiance is None:
        sky_irradiance = [1.2 * SKY_GAIN.get(ch, 1.0) for ch in channels]
    scene = Scene(channels=channels, sky=sky, name="campus")

    def alb(kind: str):
        if kind not in table:
            raise ValueError(f"albedos has no entry for material kind {kind!r}")
        return table[kind]

    def mat(kind: str, texture=None, **kw) -> int:
        return scene.material(texture=texture, albedo=alb(kind), kind=kind, **kw)

    g = stream(seed, "campus/layout")
    gx0, gy0 = 0.0, 0.0
    _campus_ground(seed, scene, mat)
    glass = _campus_main_building(seed, scene, mat, g)
    _campus_buildings(seed, scene, mat)
    _campus_greenery(seed, scene, mat, gx0, gy0)
    _campus_props(seed, scene, mat, glass)

    scene.add_light(DirectionalLight(sun, tuple(np.broadcast_to(np.asarray(sun_irradiance, float), (c,)))))
    up = np.broadcast_to(np.asarray(sky_irradiance, float), (c,))
    scene.ambient = Ambient(up=tuple(up), down=tuple(0.4 * up))
    scene.exposure = exposure
    return World(scene=scene, grid_origin=(gx0, gy0), spacing=SPACING, grid_shape=GRID_SHAPE,
                 camera_height=CAMERA_HEIGHT, info=info, floor_tilt_deg=FLOOR_TILT_DEG)


def _campus_ground(seed: int, scene: Scene, mat: Callable[..., int]) -> None:
    """The campus ground: paving slabs with grass areas and an asphalt road (``mat(kind, texture, ...)``: a material)."""
    r = stream(seed, "campus/ground")
    paving = mat("paving", tx.tiles(r, n=4, lo=PAVING_TEXTURE[0], hi=PAVING_TEXTURE[1], grout_level=0.4), scale=2.0)
    grass = mat("grass", tx.foliage(r), scale=1.5)
    asphalt = mat("asphalt", tx.carpet(r, lo=0.3, hi=0.6), scale=3.0)
    scene.box((-300, -300, -1.0), (300, 300, 0.0), paving, shadow=False)
    for x0, y0, x1, y1 in ((-30, 20, -4, 45), (14, -6, 24, 30), (-22, -6, -6, 16), (-60, 50, 80, 58)):
        scene.box((x0, y0, 0.0), (x1, y1, 0.02), grass, shadow=False)
    scene.box((-300, 60, 0.0), (300, 68, 0.01), asphalt, shadow=False)


def _campus_main_building(seed: int, scene: Scene, mat: Callable[..., int], g: np.random.Generator) -> int:
    """The main building south of the grid with its north entrance; its height from the layout stream ``g``.

    Returns the glass material (also of the parked cars' windows).
    """
    r = stream(seed, "campus/main")
    main_h = 20.0 + g.uniform(-2, 2)
    facade = mat("concrete", tx.facade(r, floors=4, windows=4), scale=(10.4, 15.2))
    roof = mat("concrete")
    scene.box((-45, -26, 0.0), (55, -9, main_h), [facade, facade, facade, facade, roof, roof])
    canopy = mat("concrete", tx.stripes(r, n=3, lo=0.5, hi=0.8), scale=(4.0, 0.5))
    scene.box((-3, -9, 3.6), (12, -4.5, 4.0), canopy)
    pillar = mat("concrete", tx.value_noise(r, lo=0.5, hi=0.75), scale=1.0)
    for px in (-2.5, 3.5, 9.5):
        scene.cylinder((px, -5.0), 0.0, 3.6, 0.25, material=pillar)
    glass = mat("glass", tx.facade(r, floors=1, windows=6), scale=(15.0, 3.5))
    scene.box((-3, -9.1, 0.0), (12, -8.9, 3.5), glass, shadow=False)
    return glass


def _campus_buildings(seed: int, scene: Scene, mat: Callable[..., int]) -> None:
    """The other buildings around the campus."""
    r = stream(seed, "campus/buildings")
    for x0, y0, x1, y1, h, kind in ((38, 4, 58, 34, 12.0, "brick"), (-62, -4, -36, 22, 15.0, "concrete"),
                                    (-40, 75, 10, 95, 22.0, "concrete"), (20, 72, 60, 90, 9.0, "brick"),
                                    (60, -20, 85, 20, 25.0, "concrete")):
        jx, jy = r.uniform(-2, 2, size=2)
        hh = h + r.uniform(-2, 2)
        fac = mat(kind, tx.facade(r, floors=4, windows=int(r.integers(3, 6))) if kind == "concrete"
                  else tx.bricks(r), scale=(10.0, 14.0) if kind == "concrete" else (2.0, 1.2))
        top = mat(kind)
        scene.box((x0 + jx, y0 + jy, 0.0), (x1 + jx, y1 + jy, hh), [fac, fac, fac, fac, top, top])


def _campus_greenery(seed: int, scene: Scene, mat: Callable[..., int], gx0: float, gy0: float) -> None:
    """Trees and hedges, none within ``TREE_CLEARANCE`` metres of the grid (origin ``gx0, gy0``)."""
    r = stream(seed, "campus/trees")
    bark_mat = mat("bark", tx.bark(r), scale=0.8)
    leaf_mats = [mat("foliage", tx.foliage(r), scale=1.5) for _ in range(3)]

    def free(x, y, margin):
        return not (gx0 - margin < x < gx0 + 9 + margin and gy0 - margin < y < gy0 + 16 + margin)

    placed = 0
    while placed < 22:
        x, y = r.uniform(-40, 50), r.uniform(-4, 60)
        if not free(x, y, TREE_CLEARANCE) or (-64 < x < -34 and -6 < y < 24) or (36 < x < 60 and 2 < y < 36):
            continue
        conifer = r.random() < 0.3
        h = r.uniform(6, 14)
        tree(scene, r, x=x, y=y, height=h, crown=r.uniform(1.8, 3.5) if not conifer else r.uniform(1.5, 2.5),
             conifer=conifer, bark_mat=bark_mat, leaf_mat=leaf_mats[placed % 3])
        placed += 1
    hedge = mat("foliage", tx.foliage(r), scale=1.0)
    scene.box((-6, 18.5, 0.0), (16, 19.5, 1.1), hedge)
    scene.box((13.5, -3, 0.0), (14.3, 12, 0.9), hedge)


def _campus_props(seed: int, scene: Scene, mat: Callable[..., int], glass: int) -> None:
    """Lamp posts, a bike rack, benches, bollards, a notice board and parked cars."""
    r = stream(seed, "campus/props")
    metal = mat("metal", tx.value_noise(r, lo=0.4, hi=0.7), scale=0.5)
    paint = mat("paint", tx.poster(r, n_shapes=10), fit=True)
    for k in range(6):  # lamp posts along the path
        lx_, ly_ = -2.5 if k % 2 == 0 else 11.5, -2.0 + 4.5 * k
        scene.cylinder((lx_, ly_), 0.0, 4.5, 0.07, material=metal)
        scene.box((lx_ - 0.3, ly_ - 0.12, 4.5), (lx_ + 0.3, ly_ + 0.12, 4.7), metal)
    for k in range(8):  # bike rack
        bx = 1.0 + 0.8 * k
        scene.box((bx, -3.2, 0.0), (bx + 0.05, -2.4, 0.8), metal)
    scene.box((0.8, -3.0, 0.7), (7.4, -2.95, 0.75), metal)
    wood = mat("wood", tx.wood(r), scale=1.0)
    for bx, by in ((-3.5, 6.0), (12.5, 9.0), (-3.5, 12.0)):
        scene.box((bx - 0.25, by - 0.9, 0.42), (bx + 0.25, by + 0.9, 0.47), wood)
        scene.box((bx - 0.25, by - 0.85, 0.0), (bx + 0.25, by - 0.8, 0.42), metal)
        scene.box((bx - 0.25, by + 0.8, 0.0), (bx + 0.25, by + 0.85, 0.42), metal)
    for k in range(5):  # bollards
        scene.cylinder((-1.5 + 3.0 * k, 17.5), 0.0, 0.9, 0.1, material=metal)
    scene.box((16.5, 2.0, 0.0), (16.6, 4.0, 2.2), paint)  # notice board
    scene.box((16.5, 1.9, 0.0), (16.6, 2.0, 2.3), metal)
    scene.box((16.5, 4.0, 0.0), (16.6, 4.1, 2.3), metal)
    car = mat("paint", tx.value_noise(r, lo=0.3, hi=0.8), scale=1.5)
    for k in range(4):  # parked cars along the road
        cx = -12 + 6.5 * k + r.uniform(-0.5, 0.5)
        scene.box((cx, 58.5, 0.3), (cx + 4.3, 60.3, 1.0), car)
        scene.box((cx + 1.0, 58.6, 1.0), (cx + 3.2, 60.2, 1.45), glass)


def build_uni(seed: int = 0) -> World:
    """The *uni* stand-in: :func:`build_campus` (grey) plus the light changing while the grid was captured.

    The capture light (:func:`uni_capture_light`) enters through the whole sky
    (:class:`~bionav.world.worlds.common.OpenSky`): :meth:`World.capture_scenes
    <bionav.world.worlds.common.World.capture_scenes>` gives the scene as lit at each cell's
    capture time, which the camera model (``db.realism=camera``) renders. ``world.scene``
    itself (used by ``db.realism=ideal``) is the campus of :func:`build_campus`
    unchanged.
    """
    world = build_campus(seed)
    world.capture_light, world.aperture = uni_capture_light(world.cells, seed), OpenSky()
    world.info["capture_light"] = world.capture_light.describe()
    return world


def campus_world(sky, *, seed: int) -> World:
    """The campus (:func:`build_campus`) in five bands under a spectral sky (:class:`bionav.light.daylight.SkyState`).

    Per-kind albedos are the campus' default five-band albedos
    (:func:`bionav.light.materials.band_albedos`: the reflectances of the
    kinds' materials), the sun and the hemispherical ambient light from
    :func:`bionav.light.daylight.illumination` (``E/pi``, so that pixel values are
    band radiances in the unit of the sensor model), rays that hit nothing from
    :func:`bionav.light.daylight.band_sky_radiance`.
    """
    from bionav.light.bands import CHANNELS, band_integrate
    from bionav.light.daylight import band_sky_radiance, illumination

    ill = illumination(sky)
    e_dir = band_integrate(ill.direct_normal) / np.pi
    e_dif = band_integrate(ill.diffuse_horizontal) / np.pi
    world = build_campus(seed, channels=CHANNELS, sky=lambda d: band_sky_radiance(sky, d),
                         sun_elevation=float(sky.sun_elevation), sun_azimuth=float(sky.sun_azimuth),
                         sun_irradiance=e_dir, sky_irradiance=e_dif, exposure=1.0)
    return world


def render_campus_counts(world, geometry, cells, *, sensor_model, rng, progress=None):
    """Five-channel sensor counts ``(N, H, W, 5)`` and true sky masks ``(N, H, W)`` of a :func:`campus_world`.

    ``cells`` ``(N, 2)`` are grid cells (may be fractional: :meth:`World.cell_position`); each
    panorama is rendered at heading 0 without clipping and read by ``sensor_model``
    (``read(radiance, rng=rng)``) with ``rng``; ``progress`` wraps the loop.
    """
    from bionav.world.render import render_depth, render_panorama

    counts, skies = [], []
    it = cells if progress is None else progress(cells, desc="render", total=len(cells))
    for i, j in it:
        pos = world.cell_position(float(i), float(j))
        rad = render_panorama(world.scene, position=pos, geometry=geometry, clip=False, exposure=1.0)
        depth, _, _ = render_depth(world.scene, position=pos, geometry=geometry)
        counts.append(sensor_model.read(np.asarray(rad, float), rng=rng)[0, ..., :5].astype(np.float32))
        skies.append(~np.isfinite(depth))
    return np.stack(counts), np.stack(skies)
