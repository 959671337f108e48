"""Canonical panoramas of triangle-mesh worlds (:class:`MeshWorld`, :func:`render_mesh_panorama`).

A :class:`MeshWorld` is a :class:`~bionav.world.mesh.TriangleMesh` plus what
the file does not say: the ground (an infinite plane at ``ground_z``, as the
MATLAB ant-world renderer draws it, or the mesh's own lowest surface), the
sky behind the terrain (:class:`bionav.light.simple_sky.SimpleSky`, grey or the five
bands ``UV B G R IR`` of thesis chapter 6), shading and channels.

Conventions are bionav's (:mod:`bionav.geometry`): positions ``(x, y, z)`` in
metres in the mesh's frame, heading in radians counter-clockwise from ``+x``,
column ``j`` of a panorama looks along ``heading + 2*pi*j/W``, row 0 on top.
Camera heights are over the local terrain (:meth:`MeshWorld.terrain_height`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from bionav.errors import UserError
from bionav.geometry import PanoramaGeometry
from bionav.world.mesh import TriangleMesh
from bionav.world.mesh_kernels import build_grid, cast_kernel, edge_form, vertical_kernel
from bionav.world.render import _run_threads

#: Bump when a change to the mesh renderer changes pixels (invalidates cached databases).
MESH_RENDERER_VERSION = 1

#: Band sets a mesh world renders.
CHANNEL_SETS = {"grey": ("grey",), "spectral": ("UV", "B", "G", "R", "IR")}

#: Ground colour of the MATLAB ant-world renderer (ImgGrabber_2013.m): sand, RGB 229, 183, 90.
SAND_RGB = (229 / 255.0, 183 / 255.0, 90 / 255.0)


def _band_albedo(grey: np.ndarray, channels: tuple[str, ...], material: str) -> np.ndarray:
    """Per-band albedo ``(N, C)`` from grey values, scaled by the band-to-grey ratios of surface kind ``material``.

    The ratios are those of :func:`bionav.light.materials.band_albedos` (the kind's measured or tabulated
    reflectance in each band over its grey albedo).
    """
    from bionav.light.materials import band_albedos

    ratio = band_albedos(tuple(channels))[material] / band_albedos(("grey",))[material]
    return np.asarray(grey, float)[..., None] * ratio


@dataclass
class MeshWorld:
    """A triangle mesh made renderable: ground, sky, shading, acceleration grid.

    Parameters
    ----------
    mesh : TriangleMesh
    ground : {"plane", "mesh"}
        ``plane``: an infinite ground plane at ``ground_z`` (the ant-world
        convention: the mesh holds the vegetation, the renderer draws the
        ground); the terrain height is ``ground_z`` everywhere.
        ``mesh``: the mesh is the terrain; its height at ``(x, y)`` is the
        lowest mesh surface there (a vertical ray cast upwards from below the
        mesh); no plane is drawn.
    ground_z : float, optional
        Height of the ground plane; default 0 for ``plane``.
    ground_color : (3,) float
        RGB of the ground plane (default :data:`SAND_RGB`).
    channels : {"grey", "spectral"}
        One grey channel, or the five bands ``UV B G R IR`` (albedos scaled by
        :func:`bionav.light.materials.band_albedos` of ``foliage`` for the mesh and
        ``soil`` for the ground).
    shading : {"flat", "lambert"}
        ``flat``: a triangle shows its colour (the MATLAB renderer);
        ``lambert``: colour times ``ambient + (1 - ambient) |n . sun|``.
    sun_elevation, sun_azimuth : float
        Sun direction in radians (azimuth CCW from ``+x``); sky glow and shading.
    sky : callable, optional
        ``sky(directions (N, 3)) -> (N, C)``; default a cloudless
        :class:`~bionav.light.simple_sky.SimpleSky`.
    """

    mesh: TriangleMesh
    ground: str = "plane"
    ground_z: float | None = None
    ground_color: Sequence[float] = SAND_RGB
    channels: str = "grey"
    shading: str = "flat"
    ambient: float = 0.4
    sun_elevation: float = np.deg2rad(45.0)
    sun_azimuth: float = np.deg2rad(135.0)
    sky: object = None
    info: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.ground not in ("plane", "mesh"):
            raise UserError(f"ground={self.ground!r} is not a ground kind; use plane or mesh.")
        if self.channels not in CHANNEL_SETS:
            raise UserError(f"channels={self.channels!r} is not a channel set; use one of {', '.join(CHANNEL_SETS)}.")
        if self.shading not in ("flat", "lambert"):
            raise UserError(f"shading={self.shading!r} is not a shading mode; use flat or lambert.")
        if self.ground_z is None:
            self.ground_z = 0.0 if self.ground == "plane" else float(self.mesh.bounds[0, 2])
        self.band_names = CHANNEL_SETS[self.channels]
        self.grid = build_grid(self.mesh.triangles)
        self._edges = edge_form(self.mesh.triangles)
        se, ce = np.sin(self.sun_elevation), np.cos(self.sun_elevation)
        self.sun = np.array([ce * np.cos(self.sun_azimuth), ce * np.sin(self.sun_azimuth), se])
        if self.sky is None:
            from bionav.light.simple_sky import SimpleSky

            self.sky = SimpleSky(sun_direction=tuple(self.sun), channels=self.band_names, glow=0.6)
        grey = self.mesh.grey
        shade = np.ones(len(self.mesh))
        if self.shading == "lambert":
            t = self.mesh.triangles
            n = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
            n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
            shade = self.ambient + (1.0 - self.ambient) * np.abs(n @ self.sun)
        self.triangle_radiance = _band_albedo(grey * shade, self.band_names, "foliage")
        gshade = 1.0 if self.shading == "flat" else self.ambient + (1.0 - self.ambient) * max(self.sun[2], 0.0)
        self.ground_radiance = _band_albedo(np.array([np.mean(self.ground_color) * gshade]), self.band_names, "soil")[0]

    @property
    def n_channels(self) -> int:
        return len(self.band_names)

    def _grid_args(self):
        g = self.grid
        return (self._edges, g["origin"][0], g["origin"][1], g["cell"], g["shape"][0], g["shape"][1],
                g["starts"], g["items"], g["zlo"], g["zhi"], g["zmax"])

    def extent(self) -> np.ndarray:
        """``[[xmin, ymin], [xmax, ymax]]`` of the mesh in metres."""
        return self.mesh.bounds[:, :2]

    def terrain_height(self, xy) -> np.ndarray:
        """Height of the terrain surface under points ``xy`` (N, 2) in metres; NaN where there is none.

        ``ground="plane"``: ``ground_z``. ``ground="mesh"``: the lowest mesh
        surface above ``(x, y)`` (NaN outside the mesh's footprint).
        """
        xy = np.asarray(xy, np.float64).reshape(-1, 2)
        if self.ground == "plane":
            return np.full(len(xy), float(self.ground_z))
        z0 = np.full(len(xy), self.grid["zmin"] - 1.0)
        t = np.empty(len(xy))
        vertical_kernel(np.ascontiguousarray(xy[:, 0]), np.ascontiguousarray(xy[:, 1]), z0, True,
                        *self._grid_args(), t)
        return np.where(t < 1e29, z0 + t, np.nan)

    def clearance(self, xy, z) -> np.ndarray:
        """Free height above points ``(x, y, z)``: distance to the first triangle straight up (inf if none)."""
        xy = np.asarray(xy, np.float64).reshape(-1, 2)
        z = np.asarray(z, np.float64).reshape(-1)
        t = np.empty(len(xy))
        vertical_kernel(np.ascontiguousarray(xy[:, 0]), np.ascontiguousarray(xy[:, 1]), np.ascontiguousarray(z),
                        True, *self._grid_args(), t)
        return np.where(t < 1e29, t, np.inf)

    def camera_positions(self, xy, *, height: float, clearance_m: float | None = None):
        """Camera positions ``height`` metres over the terrain, and which of them are free.

        A position is not free when there is no terrain under it (outside a
        ``ground="mesh"`` world) or a triangle lies straight above the terrain
        point within ``clearance_m`` (``None``: at any height) -- the point is
        inside a tussock, under an overhang or under the terrain.

        Returns
        -------
        positions : ndarray, shape (N, 3)
        free : ndarray, shape (N,), bool
        """
        xy = np.asarray(xy, np.float64).reshape(-1, 2)
        zt = self.terrain_height(xy)
        ok = np.isfinite(zt)
        zs = np.where(ok, zt, 0.0) + 1e-4
        up = self.clearance(xy, zs)
        blocked = np.isfinite(up) if clearance_m is None else up <= float(clearance_m)
        free = ok & ~blocked
        pos = np.column_stack([xy, np.where(ok, zt, np.nan) + float(height)])
        return pos, free


def cast_mesh_directions(world: MeshWorld, *, position: Sequence[float], azimuths, elevations,
                         threads: int | None = 1):
    """Depth and hit index for the ray grid ``elevations x azimuths`` (any field of view).

    Parameters
    ----------
    position : (x, y, z) in metres
    azimuths : ndarray, shape (W,)
        World azimuths, radians CCW from ``+x``.
    elevations : ndarray, shape (H,)
        Radians above the horizontal.

    Returns
    -------
    depth, index : ndarray, shape (H, W)
        As :func:`cast_mesh_rays`.
    """
    az = np.ascontiguousarray(azimuths, np.float64).ravel()
    el = np.ascontiguousarray(elevations, np.float64).ravel()
    depth = np.empty((el.size, az.size))
    index = np.empty((el.size, az.size), np.int64)
    ox, oy, oz = (float(v) for v in position)
    _run_threads(threads, cast_kernel, ox, oy, oz, az, el, *world._grid_args(), float(world.ground_z),
         world.ground == "plane", depth, index)
    return depth, index


def cast_mesh_rays(world: MeshWorld, *, position: Sequence[float], heading: float = 0.0,
                   geometry: PanoramaGeometry, threads: int | None = 1):
    """Depth and what each pixel of a canonical panorama sees.

    Returns
    -------
    depth : ndarray, shape (H, W)
        Metres along the ray; ``inf`` for sky.
    index : ndarray, shape (H, W), int
        Triangle index; ``-2`` ground plane; ``-1`` sky.
    """
    from bionav.world.render import ray_grid

    az, el = ray_grid(geometry, heading)
    return cast_mesh_directions(world, position=position, azimuths=az, elevations=el, threads=threads)


def render_mesh_panorama(world: MeshWorld, *, position: Sequence[float], heading: float = 0.0,
                         geometry: PanoramaGeometry, threads: int | None = 1) -> np.ndarray:
    """Render the canonical unfolded panorama seen from a pose in a mesh world.

    One ray per pixel centre through the world's uniform grid
    (:mod:`bionav.world.mesh_kernels`); a triangle shows its (shaded) colour,
    the ground plane its colour, everything else the sky.

    Parameters
    ----------
    world : MeshWorld
    position : sequence of 3 float
        Camera ``(x, y, z)`` in metres (see :meth:`MeshWorld.camera_positions`
        for heights over the terrain).
    heading : float
        Radians CCW from ``+x``; column 0 looks along it. Headings of whole
        columns ``2*pi*k/W`` give exactly ``np.roll(view0, -k, axis=1)``.
    geometry : PanoramaGeometry
        Output size and elevations.
    threads : int or None
        Threads of the row-parallel kernel (result independent of it).

    Returns
    -------
    ndarray, shape (H, W, C), float32 in [0, 1]
        ``C`` = 1 (grey) or 5 (``UV B G R IR``).
    """
    from bionav.world.render import ray_grid

    depth, index = cast_mesh_rays(world, position=position, heading=heading, geometry=geometry, threads=threads)
    out = np.empty(index.shape + (world.n_channels,), np.float64)
    hit = index >= 0
    out[hit] = world.triangle_radiance[index[hit]]
    out[index == -2] = world.ground_radiance
    sky = index == -1
    if sky.any():
        az, el = ray_grid(geometry, heading)
        rr, jj = np.nonzero(sky)
        ce = np.cos(el[rr])
        dirs = np.stack([ce * np.cos(az[jj]), ce * np.sin(az[jj]), np.sin(el[rr])], axis=1)
        out[rr, jj] = np.asarray(world.sky(dirs), np.float64).reshape(len(rr), -1)
    np.clip(out, 0.0, 1.0, out=out)
    return out.astype(np.float32)
