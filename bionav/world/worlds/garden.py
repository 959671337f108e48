"""Small outdoor scenes seen by the five-channel sensor: a backyard and a garden (thesis chapter 6).

:class:`OutdoorScene` holds a handful of analytic primitives (ground with
patches, yawed boxes, ellipsoids, vertical cylinders, a distant tree line),
builds them into a :class:`bionav.world.scene.Scene` and renders them through
the renderer's kernels with the spectral shading of
:mod:`bionav.world.spectral_shading` (spectral daylight of
:mod:`bionav.light.daylight`, reflectance spectra of
:data:`bionav.light.materials.MATERIALS`, hard shadows of the sun, a smooth
log-normal texture per material, sun flecks on foliage).

The scene also serves as the "simulation" object of the pan-tilt experiment:
:meth:`OutdoorScene.set_pose` (called by a simulated pan-tilt unit) aims the
sensor and :meth:`OutdoorScene.band_radiance` returns what it sees.
Conventions: east-north-up frame, metres; pan = azimuth in radians
counter-clockwise, offset by ``pan_zero_azimuth`` (radians CCW from east);
tilt = elevation in radians (the spectral sensor is mounted looking
horizontally at tilt 0).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from bionav.geometry import direction_from_angles
from bionav.light.daylight import SkyState, illumination
from bionav.light.materials import MATERIALS
from bionav.world.lights import DirectionalLight
from bionav.world.scene import Scene
from bionav.world.spectral_shading import spectral_radiance, trace_surfaces

#: Materials lit by the sun in flecks (foliage).
FOLIAGE = ("shrub", "tree", "conifer")
#: Segments of the distant tree line (four per degree of azimuth around the scene's origin): its inner faces
#: lie within 0.5 mm of the circle and turn by 0.25 deg from one to the next.
TREE_LINE_SEGMENTS = 1440
#: Half the side of the ground square (m); the tree line, 120-150 m away, hides its edge.
GROUND_HALF_M = 400.0
#: Height (m) of the slab of a ground patch above the one before it (patches are slabs on the ground).
PATCH_LIFT_M = 1e-5


@dataclass(frozen=True)
class Box:
    """Vertical prism with a rectangular footprint (a building, a hedge).

    ``centre`` (x, y), ``size`` (sx, sy) before the ``yaw`` rotation (radians
    CCW), from ``z0`` to ``z1``; ``wall``/``top`` material names.
    """

    centre: tuple
    size: tuple
    z0: float
    z1: float
    wall: str
    top: str
    yaw: float = 0.0


@dataclass(frozen=True)
class Ellipsoid:
    """Axis-aligned ellipsoid (a tree crown, a bush): ``centre`` (x, y, z), ``radii`` (rx, ry, rz)."""

    centre: tuple
    radii: tuple
    material: str


@dataclass(frozen=True)
class Cylinder:
    """Vertical cylinder (a trunk, a post): ``centre`` (x, y), ``radius``, ``z0``..``z1``."""

    centre: tuple
    radius: float
    z0: float
    z1: float
    material: str


@dataclass(frozen=True)
class TreeLine:
    """Distant vegetation: the inside of a cylinder of ``radius`` around the origin whose top height
    varies smoothly with azimuth between ``height_min`` and ``height_max`` (seeded).

    Rendered as :data:`TREE_LINE_SEGMENTS` upright slabs (2 m deep) whose inner
    faces form a regular polygon circumscribed about the circle, each as high
    as :meth:`height` at its centre azimuth (radians CCW from east)."""

    radius: float = 150.0
    height_min: float = 8.0
    height_max: float = 25.0
    material: str = "tree"
    seed: int = 0

    def height(self, azimuth) -> np.ndarray:
        r = np.random.default_rng(self.seed)
        k = np.arange(1, 9)
        amp = r.normal(0, 1, 8) / k
        ph = r.uniform(0, 2 * np.pi, 8)
        f = np.sum(amp * np.cos(k * np.asarray(azimuth)[..., None] + ph), axis=-1)
        lo, hi = -np.sum(np.abs(amp)), np.sum(np.abs(amp))
        return self.height_min + (self.height_max - self.height_min) * (f - lo) / (hi - lo)


@dataclass(frozen=True)
class GroundPatch:
    """A rectangle ``[x0, x1] x [y0, y1]`` of the ground plane with another material (a path, a bed)."""

    x0: float
    x1: float
    y0: float
    y1: float
    material: str


@dataclass
class OutdoorScene:
    """Primitives, ground materials and the sky of an outdoor scene.

    Attributes
    ----------
    sky : SkyState
        Illumination; change it with :meth:`with_sky` (e.g. per scan time).
    boxes, ellipsoids, cylinders, patches : list
        Primitives (see the dataclasses of this module).
    tree_line : TreeLine or None
    ground : str
        Material of the ground plane outside patches.
    sensor_height : float
        Height of the sensor above the ground, metres (pose origin).
    position : tuple of float
        Sensor position (x, y) in metres.
    pan_zero_azimuth : float
        World azimuth (radians CCW from east) of pan 0.
    texture_sd : float
        Log-normal texture amplitude.
    seed : int
        Seed of textures and sun flecks.
    """

    sky: SkyState
    boxes: list = field(default_factory=list)
    ellipsoids: list = field(default_factory=list)
    cylinders: list = field(default_factory=list)
    patches: list = field(default_factory=list)
    tree_line: TreeLine | None = None
    ground: str = "grass"
    sensor_height: float = 1.2
    position: tuple = (0.0, 0.0)
    pan_zero_azimuth: float = np.pi / 2
    texture_sd: float = 0.18
    seed: int = 0
    pose: tuple = (0.0, 0.0)

    def __post_init__(self) -> None:
        self._materials = sorted(MATERIALS)
        self._mat_index = {m: i for i, m in enumerate(self._materials)}
        self._spectra = np.array([MATERIALS[m].mean_spectrum() for m in self._materials])
        self._ill_cache = {}
        self._prefetch = None
        r = np.random.default_rng(self.seed)
        self._tex_k = r.normal(0, 1, (12, 3)) * np.array([1.5, 1.5, 1.5])
        self._tex_p = r.uniform(0, 2 * np.pi, 12)
        self._geometry, self._surface = self._build()

    # -- simulation hooks -------------------------------------------------------------
    def set_pose(self, pan: float, tilt: float) -> None:
        """Aim the sensor (called by a simulated pan-tilt unit); radians."""
        self.pose = (float(pan), float(tilt))

    def with_sky(self, sky: SkyState) -> "OutdoorScene":
        """The same scene under another sky (shares nothing mutable)."""
        return replace(self, sky=sky)

    def origin(self, position=None) -> np.ndarray:
        p = self.position if position is None else position
        return np.array([p[0], p[1], self.sensor_height])

    def view_direction(self, pan, tilt) -> np.ndarray:
        """Unit viewing direction(s) ``(..., 3)`` for pan/tilt in radians."""
        return direction_from_angles(self.pan_zero_azimuth + np.asarray(pan), tilt)

    # -- geometry ------------------------------------------------------------------------
    def _build(self) -> tuple[Scene, np.ndarray]:
        """The primitives as a renderer :class:`Scene` (one material per name, ``kind`` the name) and the
        row of :attr:`_spectra` of each of its materials."""
        scene = Scene(channels=("grey",), name="spectral-outdoor")
        ids: dict[str, int] = {}

        def mat(name: str) -> int:
            if name not in ids:
                ids[name] = scene.material(kind=name)
            return ids[name]

        g = GROUND_HALF_M
        scene.box((-g, -g, -1.0), (g, g, 0.0), mat(self.ground), shadow=False)
        for k, patch in enumerate(self.patches):  # later patches lie on top of earlier ones
            scene.box((patch.x0, patch.y0, 0.0), (patch.x1, patch.y1, PATCH_LIFT_M * (k + 1)), mat(patch.material),
                      shadow=False)
        for b in self.boxes:
            lo = (b.centre[0] - b.size[0] / 2, b.centre[1] - b.size[1] / 2, b.z0)
            hi = (b.centre[0] + b.size[0] / 2, b.centre[1] + b.size[1] / 2, b.z1)
            scene.box(lo, hi, [mat(b.wall)] * 4 + [mat(b.top)] * 2, yaw=b.yaw)
        for e in self.ellipsoids:
            scene.ellipsoid(e.centre, e.radii, material=mat(e.material))
        for cyl in self.cylinders:
            scene.cylinder(cyl.centre, cyl.z0, cyl.z1, cyl.radius, material=mat(cyl.material))
        if self.tree_line is not None:
            tl = self.tree_line
            n = TREE_LINE_SEGMENTS
            az = 2 * np.pi * (np.arange(n) + 0.5) / n
            half = tl.radius * np.tan(np.pi / n) * 1.01  # inner faces meet (1 % overlap)
            for a, h in zip(az, tl.height(az)):
                c = (tl.radius + 1.0) * np.cos(a), (tl.radius + 1.0) * np.sin(a)
                scene.box((c[0] - 1.0, c[1] - half, 0.0), (c[0] + 1.0, c[1] + half, float(h)), mat(tl.material),
                          yaw=float(a))
        surface = np.array([self._mat_index[m.kind] for m in scene.materials], np.int64)
        return scene, surface

    def _lit_geometry(self) -> Scene:
        """The geometry with the sun as its one light (for its shadows)."""
        sun = tuple(float(v) for v in self.sky.sun_direction)
        cached = self._ill_cache.get("geometry")
        if cached is None or cached[0] != sun:
            cached = (sun, self._geometry.relit(lights=[DirectionalLight(sun, 1.0)]))
            self._ill_cache["geometry"] = cached
        return cached[1]

    def _texture(self, p, mat):
        phase = p @ self._tex_k.T + self._tex_p + mat[:, None] * 1.7
        f = np.sum(np.sin(phase), axis=1) / np.sqrt(6.0)
        return np.exp(self.texture_sd * f)

    def _illumination(self):
        cached = self._ill_cache.get("illumination")
        if cached is None or cached[0] != self.sky:
            cached = (self.sky, illumination(self.sky, origin_m=self.position))
            self._ill_cache["illumination"] = cached
        return cached[1]

    # -- rendering -----------------------------------------------------------------------
    def render(self, directions, *, position=None):
        """Band radiance along viewing directions from the sensor.

        Parameters
        ----------
        directions : array_like, shape (..., 3)
            Unit viewing directions (east-north-up).
        position : tuple of float, optional
            Sensor (x, y); default :attr:`position`.

        Returns
        -------
        radiance : ndarray, shape (..., 5)
            Band radiance (W m^-2 sr^-1 times nm) per channel.
        is_sky : ndarray of bool, shape (...)
            True where the line of sight reaches the sky (the ground truth of a skyline).
        """
        d = np.asarray(directions, dtype=float)
        shape = d.shape[:-1]
        d = d.reshape(-1, 3)
        o = self.origin(position)
        sun_up = self.sky.sun_direction[2] > 0
        hits = trace_surfaces(self._lit_geometry(), o, d, light=0 if sun_up else -1)
        surface = self._surface[np.maximum(hits["material"], 0)]
        hit = np.isfinite(hits["depth"])
        texture = np.ones(d.shape[0])
        texture[hit] = self._texture(hits["point"][hit], surface[hit])
        foliage = np.isin(surface, [self._mat_index[m] for m in FOLIAGE]) & hit
        out = spectral_radiance(hits, d, spectra=self._spectra, surface=surface, texture=texture, foliage=foliage,
                                sky=self.sky, illumination=self._illumination(), origin_m=tuple(o[:2]))
        return out.reshape(shape + (5,)), (~hit).reshape(shape)

    def _bundle(self, pan, tilt, aperture):
        off = np.array([-1.0, 0.0, 1.0]) * aperture
        pan = np.atleast_1d(np.asarray(pan, dtype=float))
        tilt = np.atleast_1d(np.asarray(tilt, dtype=float))
        dp = off[None, None, :] / np.maximum(np.cos(tilt), 0.2)[:, None, None]
        pp = pan[:, None, None] + dp + 0 * off[None, :, None]
        tt = tilt[:, None, None] + off[None, :, None] + 0 * dp
        return self.view_direction(pp, tt)  # (n, 3, 3, 3)

    def prefetch(self, pans, tilts, *, aperture: float = np.deg2rad(1.0)) -> None:
        """Render the sensor's view for many poses at once under the current sky (a speed-up only).

        Later :meth:`band_radiance` calls for a prefetched pose (within 1e-7
        rad) under the same sky return the prefetched value instead of casting
        the same rays again; other poses are rendered as usual. Prefetch the
        poses a pan-tilt unit will actually reach (after its quantisation).
        """
        pans = np.asarray(pans, dtype=float).ravel()
        tilts = np.asarray(tilts, dtype=float).ravel()
        rad, _ = self.render(self._bundle(pans, tilts, aperture))
        self._prefetch = (self.sky, aperture, pans, tilts, rad.reshape(len(pans), 9, 5).mean(axis=1))

    def band_radiance(self, pan=None, tilt=None, *, aperture: float = np.deg2rad(1.0)) -> np.ndarray:
        """What the sensor sees at a pan/tilt (default: the current :attr:`pose`), shape ``(5,)``.

        The sensor's opening angle is modelled by averaging a 3 x 3 bundle of
        rays within +-``aperture`` (radians) around the optical axis.
        """
        pan = self.pose[0] if pan is None else float(pan)
        tilt = self.pose[1] if tilt is None else float(tilt)
        pf = self._prefetch
        if pf is not None and pf[0] == self.sky and pf[1] == aperture:
            dist = np.hypot(np.abs(pf[2] - pan) * np.cos(tilt), np.abs(pf[3] - tilt))
            k = int(np.argmin(dist))
            if dist[k] < 1e-7:
                return pf[4][k].copy()
        rad, _ = self.render(self._bundle(pan, tilt, aperture))
        return rad.reshape(9, 5).mean(axis=0)


def backyard_scene(sky: SkyState, *, seed: int = 0) -> OutdoorScene:
    """The thesis' second scan location (6.4.1): a backyard with plants about 2 m from the sensor,
    a summer house to the north, trees, a hedge and a distant tree line.

    Pan 0 looks north-east (the thesis: "the center of the reference image points towards the northeast").
    """
    r = np.random.default_rng(seed)
    ellipsoids = []
    cylinders = []
    for _ in range(7):  # shrubs close to the sensor
        az = r.uniform(-0.6, 2.6)
        dist = r.uniform(2.0, 4.5)
        rad = r.uniform(0.5, 1.0)
        c = (dist * np.cos(az), dist * np.sin(az), rad * r.uniform(0.6, 1.0))
        ellipsoids.append(Ellipsoid(c, (rad, rad, rad * r.uniform(0.8, 1.4)), "shrub"))
    for _ in range(6):  # trees further away
        az = r.uniform(-0.8, 3.4)
        dist = r.uniform(9.0, 22.0)
        h = r.uniform(5.0, 11.0)
        rad = r.uniform(1.8, 3.5)
        x, y = dist * np.cos(az), dist * np.sin(az)
        cylinders.append(Cylinder((x, y), 0.2, 0.0, h - rad, "dead_wood"))
        ellipsoids.append(Ellipsoid((x, y, h - 0.3 * rad), (rad, rad, rad * 1.2), "tree" if r.random() < 0.7 else "conifer"))
    boxes = [
        Box((0.5, 8.0), (4.0, 3.0), 0.0, 2.4, "wood_painted", "roof_tile", yaw=0.2),  # summer house (north)
        Box((0.5, 8.0), (4.4, 3.4), 2.4, 2.7, "roof_tile", "roof_tile", yaw=0.2),
        Box((-6.0, 3.0), (0.8, 9.0), 0.0, 1.8, "shrub", "shrub", yaw=-0.1),  # hedge (west)
        Box((7.5, -2.0), (5.0, 4.0), 0.0, 3.0, "brick", "roof_tile", yaw=0.5),  # garage (south-east)
    ]
    patches = [GroundPatch(-0.6, 0.6, -10.0, 6.4, "concrete"), GroundPatch(1.5, 5.0, -3.0, -1.0, "soil"),
               GroundPatch(1.5, 4.0, 1.0, 2.5, "flowers")]  # a flower bed (measured petal spectra)
    return OutdoorScene(sky=sky, boxes=boxes, ellipsoids=ellipsoids, cylinders=cylinders, patches=patches,
                        tree_line=TreeLine(seed=seed), ground="grass", pan_zero_azimuth=np.pi / 4, seed=seed)


def garden_scene(sky: SkyState, *, seed: int = 0, grid_extent: float = 4.0) -> OutdoorScene:
    """An outdoor garden around a free square ``[0, grid_extent]^2`` (metres) for homing on a grid.

    Shrubs at 3-9 m, trees at 9-30 m, a summer house, a garage, a hedge, a shed
    and a distant tree line, on a lawn with a paved path; nothing stands inside
    the square (plus a 1.5 m margin). The sensor (camera) is 0.8 m above the ground.
    """
    r = np.random.default_rng([seed, 17])
    c = grid_extent / 2

    def around(dmin, dmax):
        while True:
            az = r.uniform(0, 2 * np.pi)
            dist = r.uniform(dmin, dmax)
            x, y = c + dist * np.cos(az), c + dist * np.sin(az)
            if not (-1.5 < x < grid_extent + 1.5 and -1.5 < y < grid_extent + 1.5):
                return x, y

    ellipsoids, cylinders = [], []
    for _ in range(10):
        x, y = around(3.5, 9.0)
        rad = r.uniform(0.5, 1.1)
        ellipsoids.append(Ellipsoid((x, y, rad * r.uniform(0.6, 1.0)), (rad, rad * r.uniform(0.8, 1.2),
                                                                          rad * r.uniform(0.8, 1.5)), "shrub"))
    for _ in range(9):
        x, y = around(9.0, 30.0)
        h = r.uniform(5.0, 13.0)
        rad = r.uniform(1.8, 3.8)
        cylinders.append(Cylinder((x, y), 0.22, 0.0, h - rad, "dead_wood"))
        ellipsoids.append(Ellipsoid((x, y, h - 0.3 * rad), (rad, rad, rad * 1.25),
                                    "tree" if r.random() < 0.7 else "conifer"))
    boxes = [
        Box((c + 1.0, c + 9.5), (4.0, 3.0), 0.0, 2.4, "wood_painted", "roof_tile", yaw=0.15),   # summer house (N)
        Box((c + 1.0, c + 9.5), (4.4, 3.4), 2.4, 2.8, "roof_tile", "roof_tile", yaw=0.15),
        Box((c + 11.0, c - 3.0), (6.0, 4.0), 0.0, 3.0, "brick", "roof_tile", yaw=0.5),         # garage (E)
        Box((c - 8.5, c + 1.0), (0.9, 12.0), 0.0, 1.9, "shrub", "shrub", yaw=-0.1),           # hedge (W)
        Box((c - 3.0, c - 8.0), (2.5, 2.0), 0.0, 2.1, "paint_green", "roof_tile", yaw=0.3),    # shed (S)
    ]
    patches = [GroundPatch(c - 0.5, c + 0.5, c - 20.0, c + 8.0, "concrete"),
               GroundPatch(c + 3.0, c + 6.0, c - 6.0, c - 4.0, "soil")]
    return OutdoorScene(sky=sky, boxes=boxes, ellipsoids=ellipsoids, cylinders=cylinders, patches=patches,
                        tree_line=TreeLine(radius=120.0, seed=seed), ground="grass", sensor_height=0.8,
                        position=(c, c), pan_zero_azimuth=0.0, seed=seed)


def render_spectral_panorama(scene: OutdoorScene, geometry, *, position, heading: float = 0.0):
    """Band radiance of a canonical panorama seen from ``position`` (see :mod:`bionav.geometry`).

    Column ``j`` looks at world azimuth ``heading + 2 pi j / W`` (radians CCW
    from east), row ``r`` at elevation ``(horizon_row - r) * rad_per_row``.

    Returns
    -------
    radiance : ndarray, shape (H, W, 5)
    is_sky : ndarray of bool, shape (H, W)
    """
    az = heading + geometry.column_azimuths()
    el = geometry.row_elevations()
    ee, aa = np.meshgrid(el, az, indexing="ij")
    return scene.render(direction_from_angles(aa, ee), position=position)


def render_garden_counts(scene: OutdoorScene, geometry, world_positions, *, sensor_model, rng, progress=None):
    """Five-channel sensor counts ``(N, H, W, 5)`` and true sky masks ``(N, H, W)`` of ``scene`` at world positions.

    ``world_positions`` ``(N, 2)`` or ``(N, 3)`` in metres; each panorama is
    :func:`render_spectral_panorama` at heading 0, read by ``sensor_model``
    (``read(radiance, rng=rng)``, e.g. :class:`bionav.spectral.sensor_model.LogSensorModel`) with ``rng``;
    ``progress`` wraps the loop over positions.
    """
    counts, skies = [], []
    it = world_positions if progress is None else progress(world_positions, desc="render", total=len(world_positions))
    for p in it:
        rad, sky = render_spectral_panorama(scene, geometry, position=tuple(p))
        counts.append(sensor_model.read(rad, rng=rng)[0, ..., :5].astype(np.float32))
        skies.append(sky)
    return np.stack(counts), np.stack(skies)
