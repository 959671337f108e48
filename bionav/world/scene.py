"""Scene description: materials, primitives and lights of a synthetic world.

A :class:`Scene` is built by a world builder (``bionav.world.worlds``) and
rendered by :func:`bionav.world.render.render_panorama`. The world frame is
metric (metres), right-handed, ``+z`` up; a database's grid frame shares its
``x``/``y`` axes.

Primitives
----------
* **box** -- a box of half extents ``(hx, hy, hz)`` around a centre, turned
  by ``yaw`` radians CCW about ``+z``; one material per face, faces ordered
  ``-x, +x, -y, +y, -z, +z`` (box frame). With ``inside=True`` the box is a
  room shell seen from inside (walls, floor, ceiling).
* **frustum** -- a vertical truncated cone (cylinder when both radii agree,
  cone when the top radius is zero) with a side material and two cap
  materials (bottom, top).
* **ellipsoid** -- axis-aligned ellipsoid (tree crowns, plant foliage, lamps).

Surface coordinates ``(u, v)`` are in metres along the face (``v`` up on
vertical faces); a material either tiles its texture every ``scale`` metres
or stretches it over the whole face (``fit=True``, posters and pictures).
"""

from __future__ import annotations

import dataclasses
import hashlib
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

from bionav.world.lights import Ambient, DirectionalLight, PointLight, pack_lights
from bionav.world.textures import TEXTURE_SIZE, mip_pyramid, uniform

SkyFunction = Callable[[np.ndarray], np.ndarray]
"""``sky(directions) -> radiance``: directions ``(N, 3)`` unit vectors (world
frame), radiance ``(N, C)`` for rays that hit nothing."""


@dataclass(frozen=True)
class RenderMaterial:
    """How the renderer shades one surface: texture, albedo, emission (its physics: ``kind``).

    Parameters
    ----------
    texture : int
        Index of the scene texture modulating the albedo.
    albedo : ndarray, shape (C,)
        Reflectance per channel (multiplied by the texture value).
    emission : ndarray, shape (C,)
        Emitted radiance per channel (also multiplied by the texture value).
    scale : tuple of float
        Metres per texture repeat along ``u`` and ``v`` (tiling mode).
    fit : bool
        Stretch the texture once over each face instead of tiling.
    kind : str
        Physical kind (``"foliage"``, ``"concrete"`` ...), the surface kinds of
        :data:`bionav.light.materials.RENDER_KINDS` whose reflectance spectra
        give the per-band albedos of multi-band worlds
        (:func:`bionav.light.materials.band_albedos`).
    """

    texture: int
    albedo: np.ndarray
    emission: np.ndarray
    scale: tuple[float, float] = (1.0, 1.0)
    fit: bool = False
    kind: str = ""


@dataclass
class CompiledScene:
    """Flat arrays handed to the numba kernels (see :mod:`bionav.world.kernels`)."""

    boxes: np.ndarray  # (nb, 10) cx cy cz hx hy hz cos sin inside shadow
    box_mats: np.ndarray  # (nb, 6) int
    frusta: np.ndarray  # (nf, 7) cx cy z0 z1 r0 r1 shadow
    frustum_mats: np.ndarray  # (nf, 3) int
    ellipsoids: np.ndarray  # (ne, 7) cx cy cz rx ry rz shadow
    ellipsoid_mats: np.ndarray  # (ne,) int
    mat_tex: np.ndarray  # (nm,) int
    mat_fit: np.ndarray  # (nm,) float 0/1
    mat_scale: np.ndarray  # (nm, 2)
    mat_albedo: np.ndarray  # (nm, C)
    mat_emission: np.ndarray  # (nm, C)
    tex_data: np.ndarray  # flat float32, n_tex * texels_per_texture
    tex_size: int
    light_params: np.ndarray  # (nl, 5)
    light_power: np.ndarray  # (nl, C)
    ambient_up: np.ndarray  # (C,)
    ambient_down: np.ndarray  # (C,)
    prim_kind: np.ndarray = None  # (n,) 0 box, 1 frustum, 2 ellipsoid (all primitives, unified order)
    prim_idx: np.ndarray = None  # (n,) index within its kind
    spheres: np.ndarray = None  # (n, 4) bounding sphere cx cy cz radius
    casters: np.ndarray = None  # (k,) unified indices of shadow-casting primitives
    # derived from the lights, spheres and casters when first needed (:meth:`shadow_bins`)
    shadow_grids: np.ndarray = None  # (L, 6) per-light bin grid
    shadow_starts: np.ndarray = None  # (L, n_bins + 1) CSR offsets
    shadow_items: np.ndarray = None  # (L, total) caster indices

    def __post_init__(self) -> None:
        if self.prim_kind is None:
            self.prim_kind, self.prim_idx, self.spheres, self.casters = bounding_spheres(
                self.boxes, self.frusta, self.ellipsoids)

    def shadow_bins(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(shadow_grids, shadow_starts, shadow_items)``, built on first use (:func:`~bionav.world.shadow_bins.build_shadow_bins`).

        Built lazily: a world's cache key (:meth:`digest`) and a render from the cache need no
        shadow bins, and a first run compiles the render kernel before them (their compilation
        can then happen in another process, :mod:`bionav.experiments.warmup`).
        """
        if self.shadow_grids is None:
            from bionav.world.shadow_bins import build_shadow_bins

            self.shadow_grids, self.shadow_starts, self.shadow_items = build_shadow_bins(
                self.light_params, self.spheres, self.casters)
        return self.shadow_grids, self.shadow_starts, self.shadow_items

    def digest(self) -> str:
        """SHA-256 of every array but the shadow bins (derived from the others): identifies the world for caches."""
        h = hashlib.sha256()
        for name in self.__dataclass_fields__:
            if name.startswith("shadow_"):
                continue
            v = getattr(self, name)
            a = np.ascontiguousarray(np.asarray(v))
            h.update(name.encode())
            h.update(str(a.dtype).encode())
            h.update(str(a.shape).encode())
            h.update(a.tobytes())
        return h.hexdigest()


def bounding_spheres(boxes: np.ndarray, frusta: np.ndarray, ellipsoids: np.ndarray):
    """Unified primitive list with bounding spheres (used to cull rays).

    Returns
    -------
    kind : ndarray (n,) int, index : ndarray (n,) int, spheres : ndarray (n, 4), casters : ndarray (k,) int
    """
    kind, index, sph, shadow = [], [], [], []
    for i, b in enumerate(boxes):
        kind.append(0)
        index.append(i)
        sph.append((b[0], b[1], b[2], float(np.linalg.norm(b[3:6])) * (1 + 1e-9) + 1e-9))
        shadow.append(b[9] > 0.5)
    for i, f in enumerate(frusta):
        kind.append(1)
        index.append(i)
        r = max(f[4], f[5])
        hz = (f[3] - f[2]) / 2
        sph.append((f[0], f[1], (f[2] + f[3]) / 2, float(np.hypot(r, hz)) * (1 + 1e-9) + 1e-9))
        shadow.append(f[6] > 0.5)
    for i, e in enumerate(ellipsoids):
        kind.append(2)
        index.append(i)
        sph.append((e[0], e[1], e[2], float(max(e[3:6])) * (1 + 1e-9) + 1e-9))
        shadow.append(e[6] > 0.5)
    n = len(kind)
    return (np.array(kind, np.int64).reshape(n), np.array(index, np.int64).reshape(n),
            np.array(sph, np.float64).reshape(n, 4), np.flatnonzero(np.array(shadow, bool)).astype(np.int64))


@dataclass
class Scene:
    """A mutable world description, filled by a world builder.

    Parameters
    ----------
    channels : tuple of str
        Names of the image channels (``("grey",)`` by default; the outdoor
        world may use ``("UV", "B", "G", "R", "IR")``).
    sky : callable, optional
        :data:`SkyFunction` giving the radiance of rays that hit nothing;
        ``None`` renders them black.
    exposure : float
        Radiance-to-pixel gain applied by the renderer before clipping to
        ``[0, 1]`` (a camera's fixed exposure).
    name : str
        A label for humans.
    """

    channels: tuple[str, ...] = ("grey",)
    sky: SkyFunction | None = None
    exposure: float = 1.0
    name: str = ""
    textures: list[np.ndarray] = field(default_factory=list)
    materials: list[RenderMaterial] = field(default_factory=list)
    boxes: list[tuple] = field(default_factory=list)
    frusta: list[tuple] = field(default_factory=list)
    ellipsoids: list[tuple] = field(default_factory=list)
    lights: list = field(default_factory=list)
    ambient: Ambient = field(default_factory=Ambient)
    info: dict = field(default_factory=dict)

    @property
    def n_channels(self) -> int:
        """Number of channels ``C``."""
        return len(self.channels)

    # ------------------------------------------------------------------ materials
    def texture(self, image: np.ndarray) -> int:
        """Register a square grey texture (values in [0, 1]) and return its index."""
        img = np.asarray(image, np.float32)
        if img.shape != (TEXTURE_SIZE, TEXTURE_SIZE):
            raise ValueError(f"textures must be {TEXTURE_SIZE} x {TEXTURE_SIZE}, got {img.shape}")
        self.textures.append(img)
        return len(self.textures) - 1

    def material(self, *, texture: np.ndarray | int | None = None, albedo=1.0, emission=0.0,
                 scale: float | tuple[float, float] = 1.0, fit: bool = False, kind: str = "") -> int:
        """Register a material and return its index.

        Parameters
        ----------
        texture : ndarray (S, S) or int or None
            A texture image (registered on the fly), the index of a registered
            texture, or None for a plain (constant 1) surface.
        albedo, emission : float or sequence of float
            Per-channel reflectance and emitted radiance (a scalar applies to
            every channel).
        scale : float or (float, float)
            Metres per texture repeat (tiling mode).
        fit : bool
            Stretch the texture over each face (posters).
        kind : str
            Physical kind for multi-band albedo look-up.
        """
        if texture is None:
            texture = self._plain_texture()
        elif not isinstance(texture, (int, np.integer)):
            texture = self.texture(texture)
        sc = (float(scale), float(scale)) if np.isscalar(scale) else (float(scale[0]), float(scale[1]))
        c = self.n_channels
        alb = np.broadcast_to(np.asarray(albedo, np.float64).reshape(-1), (c,)).copy()
        em = np.broadcast_to(np.asarray(emission, np.float64).reshape(-1), (c,)).copy()
        self.materials.append(RenderMaterial(int(texture), alb, em, sc, bool(fit), kind))
        return len(self.materials) - 1

    def _plain_texture(self) -> int:
        key = "_plain_texture_index"
        if key not in self.info:
            self.info[key] = self.texture(uniform(1.0))
        return self.info[key]

    # ------------------------------------------------------------------ primitives
    def box(self, lo: Sequence[float], hi: Sequence[float], material: int | Sequence[int], *, yaw: float = 0.0,
            inside: bool = False, shadow: bool = True) -> int:
        """Add a box spanning ``lo`` to ``hi`` (its own frame, before ``yaw`` about the centre).

        Parameters
        ----------
        lo, hi : sequence of 3 float
            Opposite corners in metres (world frame when ``yaw == 0``).
        material : int or sequence of 6 int
            One material for all faces or one per face ``-x, +x, -y, +y, -z, +z``.
        yaw : float
            Rotation about the vertical axis through the centre, radians CCW.
        inside : bool
            Render the box from inside (a room shell).
        shadow : bool
            Whether the box blocks light (casts shadows).
        """
        lo = np.asarray(lo, float)
        hi = np.asarray(hi, float)
        if np.any(hi <= lo):
            raise ValueError(f"box needs hi > lo, got lo={lo}, hi={hi}")
        mats = [int(material)] * 6 if np.isscalar(material) else [int(m) for m in material]
        if len(mats) != 6:
            raise ValueError("a box needs 1 or 6 materials")
        c = (lo + hi) / 2
        h = (hi - lo) / 2
        self.boxes.append((*c, *h, np.cos(yaw), np.sin(yaw), float(inside), float(shadow), *mats))
        return len(self.boxes) - 1

    def frustum(self, centre: Sequence[float], z0: float, z1: float, r0: float, r1: float | None = None, *,
                material: int, bottom: int | None = None, top: int | None = None, shadow: bool = True) -> int:
        """Add a vertical cylinder / cone / truncated cone.

        Parameters
        ----------
        centre : (float, float)
            Axis position ``(x, y)`` in metres.
        z0, z1 : float
            Bottom and top heights (``z1 > z0``).
        r0, r1 : float
            Radius at the bottom and at the top (``r1`` defaults to ``r0``).
        material, bottom, top : int
            Materials of the side and the two caps (caps default to the side's).
        """
        r1 = r0 if r1 is None else r1
        if z1 <= z0 or r0 < 0 or r1 < 0 or (r0 == 0 and r1 == 0):
            raise ValueError("frustum needs z1 > z0 and non-negative radii, not both zero")
        b = material if bottom is None else bottom
        t = material if top is None else top
        self.frusta.append((float(centre[0]), float(centre[1]), float(z0), float(z1), float(r0), float(r1),
                            float(shadow), int(material), int(b), int(t)))
        return len(self.frusta) - 1

    def cylinder(self, centre, z0, z1, radius, *, material, top=None, bottom=None, shadow=True) -> int:
        """Add a vertical cylinder (see :meth:`frustum`)."""
        return self.frustum(centre, z0, z1, radius, radius, material=material, bottom=bottom, top=top,
                            shadow=shadow)

    def ellipsoid(self, centre: Sequence[float], radii: Sequence[float] | float, *, material: int,
                  shadow: bool = True) -> int:
        """Add an axis-aligned ellipsoid (a sphere when ``radii`` is a scalar)."""
        r = np.broadcast_to(np.asarray(radii, float).reshape(-1), (3,))
        if np.any(r <= 0):
            raise ValueError("ellipsoid radii must be positive")
        self.ellipsoids.append((*map(float, centre), *r, float(shadow), int(material)))
        return len(self.ellipsoids) - 1

    def add_light(self, light: PointLight | DirectionalLight | Sequence) -> None:
        """Add one light or a list of lights."""
        if isinstance(light, (PointLight, DirectionalLight)):
            self.lights.append(light)
        else:
            self.lights.extend(light)

    def compile_key(self) -> tuple:
        """What the cached compiled arrays (``info["_compiled"]``) depend on, cheaply compared."""
        return (len(self.textures), len(self.materials), len(self.boxes), len(self.frusta),
                len(self.ellipsoids), len(self.lights), id(self.ambient))

    def relit(self, *, lights: Sequence | None = None, ambient: Ambient | None = None,
              sky: SkyFunction | None = None) -> "Scene":
        """The same world under other light (a capture at another time of day, other weather).

        Geometry, materials and textures are shared with this scene, and so are
        their compiled arrays: only the lights' arrays (and the lights' shadow
        bins) are packed again, so relighting costs about a millisecond.

        Parameters
        ----------
        lights : sequence of PointLight or DirectionalLight, optional
            Replace all lights (default: keep them).
        ambient : Ambient, optional
            Replace the ambient term.
        sky : callable, optional
            Replace the sky (:data:`SkyFunction`).

        Returns
        -------
        Scene
        """
        base = self.compiled()
        new = dataclasses.replace(self, lights=list(self.lights if lights is None else lights),
                                  ambient=self.ambient if ambient is None else ambient,
                                  sky=self.sky if sky is None else sky, info=dict(self.info))
        compiled = dataclasses.replace(base, **new._light_arrays(), shadow_grids=None, shadow_starts=None,
                                       shadow_items=None)
        new.info["_compiled"] = (new.compile_key(), compiled)
        return new

    def compiled(self) -> CompiledScene:
        """The compiled arrays (:meth:`compile`), cached in ``info["_compiled"]`` until :meth:`compile_key` changes."""
        cached = self.info.get("_compiled")
        key = self.compile_key()
        if cached is None or cached[0] != key:
            cached = (key, self.compile())
            self.info["_compiled"] = cached
        return cached[1]

    def _light_arrays(self) -> dict:
        """The lights' and the ambient term's packed arrays (the light fields of :class:`CompiledScene`)."""
        c = self.n_channels
        lp, lpow = pack_lights(self.lights, c)
        amb = self.ambient
        return {"light_params": lp, "light_power": lpow,
                "ambient_up": np.broadcast_to(np.asarray(amb.up, float).reshape(-1), (c,)).copy(),
                "ambient_down": np.broadcast_to(np.asarray(amb.down, float).reshape(-1), (c,)).copy()}

    # ------------------------------------------------------------------ compile
    def compile(self) -> CompiledScene:
        """Pack the scene into the flat arrays the kernels read."""
        c = self.n_channels
        if not self.materials:
            self.material()
        nb = len(self.boxes)
        boxes = np.array([b[:10] for b in self.boxes], np.float64).reshape(nb, 10)
        box_mats = np.array([b[10:] for b in self.boxes], np.int64).reshape(nb, 6)
        nf = len(self.frusta)
        frusta = np.array([f[:7] for f in self.frusta], np.float64).reshape(nf, 7)
        frustum_mats = np.array([f[7:] for f in self.frusta], np.int64).reshape(nf, 3)
        ne = len(self.ellipsoids)
        ell = np.array([e[:7] for e in self.ellipsoids], np.float64).reshape(ne, 7)
        ell_mats = np.array([e[7] for e in self.ellipsoids], np.int64).reshape(ne)
        mats = self.materials
        n_mat = len(mats)
        for arr in (box_mats, frustum_mats, ell_mats):
            if arr.size and (arr.min() < 0 or arr.max() >= n_mat):
                raise ValueError("a primitive refers to an unknown material")
        tex = np.concatenate([np.concatenate([lv.ravel() for lv in mip_pyramid(t)]) for t in self.textures])
        return CompiledScene(
            boxes=boxes, box_mats=box_mats, frusta=frusta, frustum_mats=frustum_mats,
            ellipsoids=ell, ellipsoid_mats=ell_mats,
            mat_tex=np.array([m.texture for m in mats], np.int64),
            mat_fit=np.array([float(m.fit) for m in mats]),
            mat_scale=np.array([m.scale for m in mats], np.float64).reshape(n_mat, 2),
            mat_albedo=np.array([m.albedo for m in mats], np.float64).reshape(n_mat, c),
            mat_emission=np.array([m.emission for m in mats], np.float64).reshape(n_mat, c),
            tex_data=tex.astype(np.float32), tex_size=TEXTURE_SIZE,
            **self._light_arrays(),
        )
