"""A small outdoor scene seen by the five-channel sensor: geometry, materials, daylight.

:class:`OutdoorScene` ray-casts viewing directions against a handful of
analytic primitives (ground plane, yawed boxes, ellipsoids, vertical
cylinders, a distant tree line) and shades the hits with the spectral daylight
of :mod:`bionav.light.daylight`:

``L_b = tex * int S_b rho (sunlit * cos_i * E_dir + (1 + n_z)/2 * E_diff + (1 - n_z)/2 * a_g * E_glob) dlambda / pi``

attenuated towards the sensor by the air (extinction per band) plus airlight
(horizon sky radiance); lines of sight that hit nothing get the sky radiance
with clouds. ``rho(lambda)`` is the material's mean reflectance spectrum from
:data:`bionav.light.materials.MATERIALS` (measured leaf and petal spectra for
vegetation and flowers), ``S_b`` the channel sensitivity, ``tex`` is a smooth multiplicative
texture (log-normal, per material), shadows are cast by every primitive except
the ground, foliage is lit in patches (sun flecks).

The scene also serves as the "simulation" object of the pan-tilt experiment:
:meth:`set_pose` (called by a simulated pan-tilt unit) aims the sensor and
:meth:`band_radiance` returns what it sees. Conventions: east-north-up frame,
metres; pan = azimuth in radians counter-clockwise, offset by
``pan_zero_azimuth`` (radians CCW from east); tilt = elevation in radians
(the spectral sensor is mounted looking horizontally at tilt 0).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from bionav.geometry import direction_from_angles
from bionav.light.bands import PEAK_NM, band_integrate
from bionav.light.daylight import (
    SkyState,
    aerosol_optical_depth,
    band_sky_radiance,
    illumination,
    rayleigh_optical_depth,
)
from bionav.light.materials import MATERIALS

_MISS = np.inf


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
    varies smoothly with azimuth between ``height_min`` and ``height_max`` (seeded)."""

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
    def _intersect(self, o, d, *, shadow=False):
        n = d.shape[0]
        t = np.full(n, _MISS)
        normal = np.zeros((n, 3))
        mat = np.full(n, -1, dtype=np.int64)
        foliage = np.zeros(n, dtype=bool)

        def take(tt, nn, mm, fol=False):
            hit = tt < t
            t[hit] = tt[hit]
            normal[hit] = nn[hit] if nn.ndim == 2 else nn
            mat[hit] = mm[hit] if np.ndim(mm) else mm
            foliage[hit] = fol

        if not shadow:
            with np.errstate(divide="ignore", invalid="ignore"):
                tg = np.where(d[:, 2] < -1e-9, -o[..., 2] / d[:, 2], _MISS)
            tg = np.where(tg > 1e-6, tg, _MISS)
            p = o + np.where(np.isfinite(tg), tg, 0.0)[:, None] * d
            gm = np.full(n, self._mat_index[self.ground])
            for patch in self.patches:
                inside = (p[:, 0] >= patch.x0) & (p[:, 0] <= patch.x1) & (p[:, 1] >= patch.y0) & (p[:, 1] <= patch.y1)
                gm[inside] = self._mat_index[patch.material]
            take(tg, np.array([0.0, 0.0, 1.0]), gm)
        for b in self.boxes:
            c, s = np.cos(b.yaw), np.sin(b.yaw)
            rot = np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]])  # world -> box frame
            ol = (o - np.array([b.centre[0], b.centre[1], 0.0])) @ rot.T
            dl = d @ rot.T
            lo = np.array([-b.size[0] / 2, -b.size[1] / 2, b.z0])
            hi = np.array([b.size[0] / 2, b.size[1] / 2, b.z1])
            with np.errstate(divide="ignore", invalid="ignore"):
                inv = 1.0 / dl
                t1 = (lo - ol) * inv
                t2 = (hi - ol) * inv
            tmin = np.nanmax(np.minimum(t1, t2), axis=1)
            tmax = np.nanmin(np.maximum(t1, t2), axis=1)
            ok = (tmax >= tmin) & (tmax > 1e-6)
            th = np.where(ok, np.where(tmin > 1e-6, tmin, tmax), _MISS)
            axis = np.argmax(np.where(np.isfinite(t1) | np.isfinite(t2), np.minimum(t1, t2), -np.inf), axis=1)
            sign = -np.sign(dl[np.arange(n), axis])
            nl = np.zeros((n, 3))
            nl[np.arange(n), axis] = sign
            nw = nl @ rot  # back to world
            m = np.where(axis == 2, self._mat_index[b.top], self._mat_index[b.wall])
            take(th, nw, m, fol=b.wall in ("shrub", "tree", "conifer"))
        for e in self.ellipsoids:
            r = np.asarray(e.radii, dtype=float)
            oc = (o - np.asarray(e.centre)) / r
            dc = d / r
            a = np.sum(dc * dc, axis=1)
            bq = 2 * np.sum(oc * dc, axis=1)
            cq = np.sum(oc * oc, axis=-1) - 1
            disc = bq * bq - 4 * a * cq
            sq = np.sqrt(np.maximum(disc, 0))
            ta = (-bq - sq) / (2 * a)
            tb = (-bq + sq) / (2 * a)
            th = np.where(disc > 0, np.where(ta > 1e-6, ta, np.where(tb > 1e-6, tb, _MISS)), _MISS)
            p = o + np.where(np.isfinite(th), th, 0)[:, None] * d
            nn = (p - np.asarray(e.centre)) / r**2
            nn /= np.linalg.norm(nn, axis=1, keepdims=True) + 1e-12
            take(th, nn, np.full(n, self._mat_index[e.material]), fol=e.material in ("shrub", "tree", "conifer"))
        for cyl in self.cylinders:
            oc = o[..., :2] - np.asarray(cyl.centre)
            dxy = d[:, :2]
            a = np.sum(dxy * dxy, axis=1)
            bq = 2 * np.sum(oc * dxy, axis=-1)
            cq = np.sum(oc * oc, axis=-1) - cyl.radius**2
            disc = bq * bq - 4 * a * cq
            sq = np.sqrt(np.maximum(disc, 0))
            with np.errstate(divide="ignore", invalid="ignore"):
                ta = (-bq - sq) / (2 * a)
            z = o[..., 2] + ta * d[:, 2]
            ok = (disc > 0) & (ta > 1e-6) & (z >= cyl.z0) & (z <= cyl.z1)
            th = np.where(ok, ta, _MISS)
            p = o + np.where(ok, ta, 0)[:, None] * d
            nn = np.zeros((n, 3))
            nn[:, :2] = (p[:, :2] - np.asarray(cyl.centre)) / cyl.radius
            take(th, nn, np.full(n, self._mat_index[cyl.material]))
        if self.tree_line is not None:
            tl = self.tree_line
            oxy = o[..., :2] * np.ones((n, 1))
            dxy = d[:, :2]
            a = np.sum(dxy * dxy, axis=1)
            bq = 2 * np.sum(oxy * dxy, axis=1)
            cq = np.sum(oxy * oxy, axis=1) - tl.radius**2
            with np.errstate(divide="ignore", invalid="ignore"):
                tt = (-bq + np.sqrt(np.maximum(bq * bq - 4 * a * cq, 0))) / (2 * a)
            p = oxy + np.where(np.isfinite(tt), tt, 0)[:, None] * dxy
            z = o[..., 2] + tt * d[:, 2]
            h = tl.height(np.arctan2(p[:, 1], p[:, 0]))
            ok = np.isfinite(tt) & (tt > 0) & (z >= 0) & (z <= h)
            nn = np.zeros((n, 3))
            nn[:, :2] = -p / tl.radius
            take(np.where(ok, tt, _MISS), nn, np.full(n, self._mat_index[tl.material]), fol=True)
        return t, normal, mat, foliage

    def _texture(self, p, mat):
        phase = p @ self._tex_k.T + self._tex_p + mat[:, None] * 1.7
        f = np.sum(np.sin(phase), axis=1) / np.sqrt(6.0)
        return np.exp(self.texture_sd * f)

    def _illumination(self):
        key = self.sky
        if key not in self._ill_cache:
            self._ill_cache.clear()
            self._ill_cache[key] = illumination(self.sky, origin_m=self.position)
        return self._ill_cache[key]

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
        t, normal, mat, foliage = self._intersect(o, d)
        sky = ~np.isfinite(t)
        out = np.zeros((d.shape[0], 5))
        origin_xy = tuple(o[:2])
        if np.any(sky):
            out[sky] = band_sky_radiance(self.sky, d[sky], origin_m=origin_xy)
        hit = ~sky
        if np.any(hit):
            ill = self._illumination()
            # per material and channel: int S_b rho_m E dlambda of each light component, shape (M, 5)
            e_dir = band_integrate(self._spectra * ill.direct_normal)
            e_dif = band_integrate(self._spectra * ill.diffuse_horizontal)
            e_glob = band_integrate(self._spectra * ill.global_horizontal)
            p = o + t[hit, None] * d[hit]
            n = normal[hit]
            sun = self.sky.sun_direction
            cos_i = np.clip(n @ sun, 0, None)
            lit = np.ones(p.shape[0])
            if sun[2] > 0:
                ts, _, _, _ = self._intersect(p + 1e-3 * n, np.broadcast_to(sun, p.shape).copy(), shadow=True)
                lit = np.where(np.isfinite(ts), 0.0, 1.0)
            fol = foliage[hit]
            fleck = 0.5 + 0.5 * np.sin(p @ np.array([3.1, 2.3, 4.7]) + np.sin(p @ np.array([1.3, -2.9, 0.7])) * 2)
            lit = np.where(fol, lit * fleck, lit)
            sky_view = (1 + n[:, 2:3]) / 2
            m = mat[hit]
            refl_irr = lit[:, None] * cos_i[:, None] * e_dir[m] + sky_view * e_dif[m] + (1 - sky_view) * 0.15 * e_glob[m]
            rad = self._texture(p, m)[:, None] * refl_irr / np.pi
            beta = (rayleigh_optical_depth(np.asarray(PEAK_NM)) / 8000.0
                    + aerosol_optical_depth(np.asarray(PEAK_NM), beta=self.sky.turbidity) / 1200.0)
            trans = np.exp(-beta * t[hit, None])
            az = np.arctan2(d[hit, 1], d[hit, 0])
            horizon = band_sky_radiance(self.sky, direction_from_angles(az, np.deg2rad(2.0)), origin_m=origin_xy)
            out[hit] = rad * trans + horizon * (1 - trans)
        return out.reshape(shape + (5,)), sky.reshape(shape)

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
