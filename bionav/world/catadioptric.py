"""Raw frames of a catadioptric (camera + hyperbolic mirror) panoramic camera.

The robots of thesis 3.1 carry a camera looking up into a hyperbolic mirror
(Accowle normal-view mirror on the Pioneer 2-DX, ultra-wide-view mirror on the
Pioneer 3-DX). A hyperbolic mirror with the camera's pinhole in its second
focus has a single effective viewpoint (Baker and Nayar 1999,
doi:10.1023/A:1008128724364), and its projection is the unified central
catadioptric model (Geyer and Daniilidis 2000, doi:10.1007/3-540-45053-X_29;
Mei and Rives 2007, doi:10.1109/ROBOT.2007.364084): a ray of elevation ``e``
(radians above the horizon) lands at the raw-image radius

    r(e) = gamma * cos(e) / (xi - sin(e))          (pixels from the mirror centre)

with the mirror parameter ``0 < xi < 1`` (``xi = d / sqrt(d**2 + 4 p**2)`` for a
hyperbola of focal distance ``d`` and latus rectum ``4 p``) and the generalised
focal length ``gamma`` in pixels. ``r`` grows monotonically from 0 (straight
down, the camera's own reflection) towards infinity at ``e = asin(xi)``; the
mirror rim cuts it off at the *rim elevation*. The thesis gives only that rim
(the upper limit of the visual field, from the Accowle specification: about
26-46 degrees for the ultra-wide-view mirror, 10-26 degrees for the
normal-view mirror); ``xi`` and the rim radius are documented assumptions
(docs/databases.md).

The raw frame is rendered by ray casting: the annulus the unfolding needs is
covered by polar ray grids (rows at the elevations of evenly spaced radii,
columns at evenly spaced azimuths, at least one ray per raw pixel), which are
resampled bilinearly at the centres of the raw pixels. Raw polar angle
``theta`` (from the +column axis towards +row, i.e. clockwise as displayed)
shows the azimuth ``heading + theta`` (counter-clockwise from world +x), so
:func:`bionav.db.unfold.unfold_panorama` unfolds the frame into a canonical
panorama.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from bionav.geometry import TWO_PI


@dataclass(frozen=True)
class MirrorProjection:
    """Where rays land in the raw frame of a central catadioptric camera.

    Parameters
    ----------
    xi : float
        Mirror parameter of the unified model, ``0 < xi < 1`` (hyperbolic mirror).
    gamma : float
        Generalised focal length in raw pixels.
    center : (float, float)
        Mirror centre ``(cx, cy)`` in raw pixels (column, row).
    rim_elevation : float
        Elevation of the mirror rim in radians (upper limit of the field of view).
    """

    xi: float
    gamma: float
    center: tuple[float, float]
    rim_elevation: float

    @classmethod
    def from_rim(cls, *, xi: float, rim_elevation_deg: float, rim_radius_px: float,
                 center: Sequence[float]) -> "MirrorProjection":
        """The projection whose mirror rim (elevation ``rim_elevation_deg``) lies at radius ``rim_radius_px``.

        Raises ``ValueError`` unless ``sin(rim elevation) < xi < 1``.
        """
        e = math.radians(float(rim_elevation_deg))
        if not (0.0 < xi < 1.0) or not math.sin(e) < xi:
            raise ValueError(f"mirror_xi={xi} must lie in (sin(rim elevation)={math.sin(e):.3f}, 1): "
                             "the mirror rim must be seen at a finite radius")
        gamma = float(rim_radius_px) * (xi - math.sin(e)) / math.cos(e)
        return cls(float(xi), gamma, (float(center[0]), float(center[1])), e)

    def radius_from_elevation(self, elevation):
        """Raw-image radius in pixels of rays at ``elevation`` (radians), ``gamma cos e / (xi - sin e)``."""
        e = np.asarray(elevation, dtype=np.float64)
        return self.gamma * np.cos(e) / (self.xi - np.sin(e))

    def elevation_from_radius(self, radius):
        """Inverse of :meth:`radius_from_elevation`: ``asin(r xi / sqrt(r^2 + gamma^2)) - atan2(gamma, r)``."""
        r = np.asarray(radius, dtype=np.float64)
        return np.arcsin(r * self.xi / np.hypot(r, self.gamma)) - np.arctan2(self.gamma, r)

    def radial_resolution(self, elevation):
        """``dr/de`` in raw pixels per radian at ``elevation``: ``gamma (1 - xi sin e) / (xi - sin e)^2``."""
        e = np.asarray(elevation, dtype=np.float64)
        return self.gamma * (1.0 - self.xi * np.sin(e)) / (self.xi - np.sin(e)) ** 2

    @property
    def rim_radius(self) -> float:
        """Radius of the mirror rim in raw pixels."""
        return float(self.radius_from_elevation(self.rim_elevation))

    def pixel_from_direction(self, azimuth, elevation):
        """Raw pixel coordinates ``(column, row)`` of rays (azimuth relative to the heading, radians)."""
        r = self.radius_from_elevation(elevation)
        a = np.asarray(azimuth, dtype=np.float64)
        return self.center[0] + r * np.cos(a), self.center[1] + r * np.sin(a)

    def scaled(self, factor: float, center: Sequence[float]) -> "MirrorProjection":
        """The same mirror imaged at ``factor`` times the pixel resolution (binned or enlarged sensor)."""
        return MirrorProjection(self.xi, self.gamma * float(factor), (float(center[0]), float(center[1])),
                                self.rim_elevation)


@dataclass(frozen=True)
class _Band:
    elevations: np.ndarray  # (nr,) elevation of each ray row
    n_az: int
    pixel_angle: float
    flat: np.ndarray  # flat indices of the raw pixels this band fills
    i0: np.ndarray
    i1: np.ndarray
    j0: np.ndarray
    j1: np.ndarray
    tr: np.ndarray
    ta: np.ndarray


@dataclass(frozen=True)
class RawFrameLayout:
    """Precomputed ray grids and resampling weights of a raw frame (see :func:`raw_frame_layout`)."""

    projection: MirrorProjection
    raw_size: tuple[int, int]
    radius_range: tuple[float, float]
    bands: tuple
    radius: np.ndarray  # (h, w) radius of every raw pixel centre

    @property
    def n_rays(self) -> int:
        """Rays cast per frame."""
        return int(sum(b.elevations.size * b.n_az for b in self.bands))


def raw_frame_layout(projection: MirrorProjection, *, raw_size: Sequence[int], radius_range: Sequence[float],
                     n_bands: int = 4) -> RawFrameLayout:
    """Ray grids covering the annulus ``radius_range`` of a raw frame, and the weights that resample them.

    The annulus is split into ``n_bands`` rings; each ring is a polar ray grid
    with rows at the elevations of the integer radii that bracket it and
    ``ceil(2 pi r_max)`` azimuths, so every raw pixel is covered by
    at least one ray per pixel pitch in both directions. Raw pixel centres
    are resampled bilinearly in (radius, azimuth), periodic in azimuth.

    Parameters
    ----------
    projection : MirrorProjection
    raw_size : (int, int)
        Raw frame ``(width, height)``.
    radius_range : (float, float)
        Inner and outer radius (pixels) of the annulus to render.
    n_bands : int
        Number of rings.

    Returns
    -------
    RawFrameLayout
    """
    w, h = int(raw_size[0]), int(raw_size[1])
    r_lo, r_hi = max(0.0, float(radius_range[0])), float(radius_range[1])
    cx, cy = projection.center
    ys, xs = np.mgrid[0:h, 0:w]
    dx, dy = (xs - cx).ravel(), (ys - cy).ravel()
    rad = np.hypot(dx, dy)
    theta = np.mod(np.arctan2(dy, dx), TWO_PI)
    edges = np.linspace(r_lo, r_hi, max(1, int(n_bands)) + 1)
    bands = []
    for b in range(edges.size - 1):
        b0, b1 = edges[b], edges[b + 1]
        flat = np.flatnonzero((rad >= b0) & ((rad < b1) if b + 2 < edges.size else (rad <= b1)))
        if flat.size == 0:
            continue
        r0 = math.floor(b0)
        radii = np.arange(r0, max(math.ceil(b1), r0 + 1) + 1.0, 1.0)  # brackets every radius in [b0, b1]
        n_az = max(8, int(math.ceil(TWO_PI * b1)))  # at least one ray per pixel along the band's outer circle
        el = projection.elevation_from_radius(np.maximum(radii, 1e-6))
        step_el = float(np.max(np.abs(np.diff(el)))) if el.size > 1 else TWO_PI / n_az
        fr = np.clip(rad[flat] - radii[0], 0.0, radii.size - 1.0)
        fa = theta[flat] * n_az / TWO_PI
        i0 = np.minimum(np.floor(fr).astype(np.int64), radii.size - 2)
        j0 = np.floor(fa).astype(np.int64) % n_az
        bands.append(_Band(el, n_az, max(TWO_PI / n_az, step_el), flat, i0, i0 + 1, j0, (j0 + 1) % n_az,
                           (fr - i0)[:, None], (fa - np.floor(fa))[:, None]))
    return RawFrameLayout(projection, (w, h), (r_lo, r_hi), tuple(bands), rad.reshape(h, w))


def render_raw_frame(scene, *, position: Sequence[float], heading: float, layout: RawFrameLayout,
                     fill: float = 0.0, threads: int | None = 1) -> np.ndarray:
    """Render the raw frame of a catadioptric camera by ray casting (radiance, before any sensor effect).

    Parameters
    ----------
    scene : bionav.world.scene.Scene or CompiledScene
    position : sequence of 3 float
        Effective viewpoint (mirror focus) ``(x, y, z)`` in metres, world frame.
    heading : float
        Robot heading, radians counter-clockwise from world +x; raw polar angle 0 looks along it.
    layout : RawFrameLayout
        From :func:`raw_frame_layout`; pixels outside its annulus read ``fill``.
    fill : float
        Value of the pixels that are not rendered.
    threads : int or None
        Render threads (the result does not depend on it).

    Returns
    -------
    ndarray, shape (h, w, C), float64
        Radiance times the scene's exposure (``scene.exposure`` for a
        :class:`~bionav.world.scene.Scene`, 1 otherwise), not clipped.
    """
    from bionav.world.render import _compiled, render_ray_grid
    from bionav.world.scene import Scene

    exposure = scene.exposure if isinstance(scene, Scene) else 1.0
    sky = scene.sky if isinstance(scene, Scene) else None
    w, h = layout.raw_size
    n_ch = _compiled(scene).mat_albedo.shape[1]
    frame = np.full((h * w, n_ch), float(fill), np.float64)
    for band in layout.bands:
        az = np.mod(float(heading) + TWO_PI * np.arange(band.n_az) / band.n_az, TWO_PI)
        grid = render_ray_grid(scene, position=position, azimuths=az, elevations=band.elevations,
                               pixel_angle=band.pixel_angle, sky=sky, threads=threads)
        grid *= exposure
        tr, ta = band.tr, band.ta
        frame[band.flat] = ((1.0 - tr) * ((1.0 - ta) * grid[band.i0, band.j0] + ta * grid[band.i0, band.j1])
                            + tr * ((1.0 - ta) * grid[band.i1, band.j0] + ta * grid[band.i1, band.j1]))
    return frame.reshape(h, w, n_ch)
