"""Clouds: the one cloud layer, and the compass' sampled sky map.

* :class:`CloudLayer`: a drifting cloud layer at a given height, seen along
  any line of sight (parallax, wind, anti-aliasing). Its views: the cover
  (:meth:`CloudLayer.density_at`), the optical depth and the direct-sun
  transmittance (:meth:`CloudLayer.transmittance_at`; spectral daylight of
  :mod:`bionav.light.daylight`, the uni capture light of
  :mod:`bionav.light.capture`) and the polarization (cloudiness, e-vector
  noise; :class:`~bionav.light.polarized_sky.SkyModel` takes a layer as its
  ``clouds``) and the clouds of the rendered worlds' sky
  (:class:`~bionav.light.simple_sky.SimpleSky` takes a layer as its ``layer``).
* :class:`CloudMap` (polarized-light compass recordings, thesis chapter 4):
  a snapshot of a layer over the sky hemisphere (:meth:`CloudLayer.hemisphere_map`):
  its cloudiness and e-vector noise field sampled on a map, so that a
  compass simulation looks the sky up by interpolation instead of summing
  the layer's waves per ray. :func:`random_cloud_map` draws a layer from a
  ``Generator`` and returns its snapshot.

Cloud map
---------
The map is a square grid covering the azimuthal-equidistant projection of
the upper hemisphere (zenith at the centre, the horizon on the unit circle:
``r = zenith_angle / (pi / 2)``; grid points outside the disk hold the
horizon at their azimuth). Its *cloudiness* in ``[0, 1]`` is the layer's
:meth:`~CloudLayer.density_at` (0 clear, 1 overcast, a soft edge between,
anti-aliased at the map's pixel size); the second field is the layer's
e-vector noise field (:meth:`~CloudLayer.angle_noise_at` divided by
cloudiness and ``angle_noise_sigma``). All randomness comes from the layer's
seed, drawn from the numpy ``Generator`` passed to :func:`random_cloud_map`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.special import ndtr, ndtri


@dataclass(frozen=True)
class CloudMap:
    """A cloud layer sampled over the sky hemisphere (:meth:`CloudLayer.hemisphere_map`).

    Attributes
    ----------
    cloudiness : ndarray, shape ``(N, N)``
        Cloudiness in ``[0, 1]`` on the projection grid; row index grows with
        the projection's ``y`` (north), column index with ``x`` (east), both
        from -1 to 1.
    angle_noise : ndarray, shape ``(N, N)``
        Standard-normal correlated field used for the e-vector angle noise.
    angle_noise_sigma : float
        Angle noise (radians, one standard deviation) under full cloud.
    depolarization : float
        Fraction by which full cloud lowers the degree of polarization.
    brightness : float
        Radiance of full cloud relative to the clear zenith.
    """

    cloudiness: np.ndarray
    angle_noise: np.ndarray
    angle_noise_sigma: float = np.deg2rad(20.0)
    depolarization: float = 0.9
    brightness: float = 1.5

    def _sample(self, grid, view):
        from scipy.ndimage import map_coordinates

        view = np.asarray(view, float)
        zen = np.arccos(np.clip(view[..., 2], -1.0, 1.0))
        r = np.minimum(zen / (np.pi / 2.0), 1.0)
        az = np.arctan2(view[..., 1], view[..., 0])
        n = grid.shape[0]
        col = (r * np.cos(az) + 1.0) * (n - 1) / 2.0
        row = (r * np.sin(az) + 1.0) * (n - 1) / 2.0
        coords = np.stack([row.ravel(), col.ravel()])
        return map_coordinates(grid, coords, order=1, mode="nearest").reshape(zen.shape)

    def cloudiness_at(self, view):
        """Cloudiness in ``[0, 1]`` at unit viewing directions, shape ``(..., 3)`` -> ``(...)``."""
        return np.clip(self._sample(self.cloudiness, view), 0.0, 1.0)

    def angle_noise_at(self, view):
        """E-vector rotation (radians) added at the viewing directions: cloudiness x sigma x field."""
        return self.cloudiness_at(view) * self.angle_noise_sigma * self._sample(self.angle_noise, view)

    def clear_fraction(self, *, min_elevation: float = 0.0) -> float:
        """Solid-angle fraction of the sky above ``min_elevation`` (radians) with cloudiness < 0.5."""
        n = self.cloudiness.shape[0]
        u = np.linspace(-1.0, 1.0, n)
        x, y = np.meshgrid(u, u)
        r = np.hypot(x, y)
        zen = r * np.pi / 2.0
        inside = zen <= np.pi / 2.0 - min_elevation
        # Area element of the equidistant projection: sin(zen)/zen per unit plane area.
        weight = np.where(inside, np.sinc(zen / np.pi), 0.0)
        return float(np.sum(weight * (self.cloudiness < 0.5)) / np.sum(weight))


#: Layer wavelength scale per (height x angular correlation length): the plane waves' correlation
#: J0(k d) falls to 1/e at k d ~ 1.75, and the mean wavenumber of wavelengths ``scale_m * U(0.5, 2)``
#: is ``2 pi ln(4) / (1.5 scale_m)``; a Gaussian-smoothed field of kernel sigma falls to 1/e at 2 sigma.
#: Equal 1/e distances at the zenith give ``scale_m = 6.6 height_m sigma``.
SCALE_PER_CORRELATION = 2.0 * 2.0 * np.pi * np.log(4.0) / 1.5 / 1.75


def random_cloud_map(
    rng: np.random.Generator,
    *,
    cover: float,
    correlation_length: float = np.deg2rad(15.0),
    edge: float = 0.2,
    resolution: int = 96,
    angle_noise_sigma: float = np.deg2rad(20.0),
    depolarization: float = 0.9,
    brightness: float = 1.5,
    height_m: float = 1500.0,
) -> CloudMap:
    """Draw a cloud layer with a given cover and return its snapshot over the hemisphere.

    The layer (:class:`CloudLayer`, seeded from ``rng``) lies at
    ``height_m``; its wave scale makes its clouds at the zenith as wide as
    a Gaussian-smoothed field of angular standard deviation
    ``correlation_length`` (:data:`SCALE_PER_CORRELATION`); towards the
    horizon they shrink and merge by perspective. Its map is
    :meth:`CloudLayer.hemisphere_map` at time 0 over the origin.

    Parameters
    ----------
    rng : numpy.random.Generator
        Source of randomness (one draw: the layer's seed).
    cover : float
        Fraction of the layer covered by cloud, ``0`` (clear) to ``1``
        (overcast); about the fraction of the sky.
    correlation_length : float, optional
        Angular size of the cloud patches at the zenith (radians; the
        standard deviation of a Gaussian smoothing kernel of equal
        correlation length).
    edge : float, optional
        Width of the clear-to-cloud ramp in standard deviations of the field
        (the slope at the edge; the layer's ``softness`` is
        ``edge / sqrt(2 pi)``).
    resolution : int, optional
        Grid size ``N`` (the layer is anti-aliased at the grid's pixel angle).
    angle_noise_sigma, depolarization, brightness : float, optional
        See :class:`CloudMap`.
    height_m : float, optional
        Height of the layer, metres.

    Returns
    -------
    CloudMap
    """
    if not 0.0 <= cover <= 1.0:
        raise ValueError(f"cloud cover must be in [0, 1], got {cover}")
    layer = CloudLayer(cover=float(cover), seed=int(rng.integers(2**32)), height_m=float(height_m),
                       scale_m=float(SCALE_PER_CORRELATION * height_m * correlation_length),
                       softness=float(edge / np.sqrt(2.0 * np.pi)), resolution=float(np.pi / (resolution - 1)),
                       brightness=float(brightness), depolarization=float(depolarization),
                       angle_noise_sigma=float(angle_noise_sigma))
    return layer.hemisphere_map(resolution=resolution)


@dataclass(frozen=True)
class CloudLayer:
    """Smooth random cloud layer: optical depth as a function of viewing direction.

    Parameters
    ----------
    cover : float
        Fraction of the layer covered by cloud, 0 (clear) .. 1 (overcast).
    optical_depth : float
        Optical depth ``tau_c`` of a cloud's core (cirrus ~1, cumulus ~20,
        stratus ~40, nimbostratus ~100).
    seed : int
        Seed of the random field (the field is a pure function of it).
    height_m : float
        Cloud-base height.
    scale_m : float
        Typical cloud size (wavelength of the plane waves).
    wind_mps : tuple of float
        Drift of the field (east, north) in m/s; ``time_s`` in :meth:`optical_depth_at` moves it.
    softness : float
        Width of the cloud edge in units of the field's standard deviation.
    resolution : float
        Angular resolution (radians) of a line of sight; cloud detail finer than
        its footprint on the layer is averaged (no aliasing near the horizon,
        where distant clouds merge into a uniform cover).
    brightness : float
        Radiance of full cloud relative to the clear sky's reference radiance
        (the clear zenith of :class:`~bionav.light.polarized_sky.SkyModel`, the
        clear horizon of :class:`~bionav.light.simple_sky.SimpleSky`); the
        spectral daylight of :mod:`bionav.light.daylight` computes the cloud's
        radiance from ``optical_depth`` instead.
    depolarization : float
        Fraction by which full cloud lowers the sky's degree of polarization.
    angle_noise_sigma : float
        E-vector angle noise (radians, one standard deviation) under full cloud.

    Notes
    -----
    One layer, three views: :meth:`density_at` (cover),
    :meth:`transmittance_at` (shade of the direct sun) and
    :meth:`cloudiness_at` / :meth:`angle_noise_at` (polarization; the
    cloudiness also blends the rendered sky of
    :class:`~bionav.light.simple_sky.SimpleSky` towards ``brightness``). Frame:
    east-north-up; the field drifts with ``wind_mps`` (frozen turbulence).
    """

    cover: float = 0.0
    optical_depth: float = 20.0
    seed: int = 0
    height_m: float = 1500.0
    scale_m: float = 1500.0
    wind_mps: tuple = (5.0, 2.0)
    softness: float = 0.15
    n_waves: int = 24
    resolution: float = float(np.deg2rad(1.0))
    brightness: float = 1.5
    depolarization: float = 0.9
    angle_noise_sigma: float = float(np.deg2rad(20.0))

    def _waves(self):
        return _plane_waves(np.random.default_rng(self.seed), self.n_waves, self.scale_m)

    def density_at(self, directions, *, time_s: float = 0.0, origin_m=(0.0, 0.0)) -> np.ndarray:
        """Cloud fraction of each line of sight's footprint on the layer (the *cover* view), in [0, 1].

        Parameters
        ----------
        directions : array_like, shape (..., 3)
            Unit viewing directions (east-north-up).
        time_s : float
            Seconds since the field's epoch (wind drift).
        origin_m : tuple of float
            Observer position (east, north) in metres (parallax of the layer).

        Returns
        -------
        ndarray, shape (...)
            Probability that the footprint is cloud: 0 where the line of sight
            misses clouds, 1 inside a cloud; anti-aliased (distant, oblique
            footprints average many clouds and tend to ``cover``). Lines of
            sight below 1 degree see the layer at 1 degree (the horizon's cover).
        """
        d = np.asarray(directions, dtype=float)
        if self.cover <= 0:
            return np.zeros(d.shape[:-1])
        if self.cover >= 1:
            return np.ones(d.shape[:-1])
        dz = np.maximum(d[..., 2], np.sin(np.deg2rad(1.0)))
        reach = self.height_m / dz
        px = origin_m[0] + d[..., 0] * reach - self.wind_mps[0] * time_s
        py = origin_m[1] + d[..., 1] * reach - self.wind_mps[1] * time_s
        kvec, phase, amp = self._waves()
        # anti-aliasing: a line of sight averages the layer over a footprint that
        # grows with distance and obliquity; waves much smaller than it are damped
        footprint = reach * self.resolution / dz
        damp = np.exp(-0.5 * (np.linalg.norm(kvec, axis=1) * footprint[..., None]) ** 2)
        a = amp * damp
        f = np.sum(a * np.cos(px[..., None] * kvec[:, 0] + py[..., None] * kvec[:, 1] + phase), axis=-1)
        lost = np.clip(1.0 - 0.5 * np.sum(a**2, axis=-1), 0.0, 1.0)  # variance no longer resolved
        thr = ndtri(1.0 - self.cover)
        # probability that the resolved field plus unresolved detail exceeds the threshold
        return ndtr((f - thr) / np.sqrt(self.softness**2 + lost))

    def optical_depth_at(self, directions, *, time_s: float = 0.0, origin_m=(0.0, 0.0)) -> np.ndarray:
        """Cloud optical depth along each viewing direction: ``optical_depth * density_at(...)``, shape ``(...)``.

        Arguments as :meth:`density_at`; 0 where the line of sight misses clouds.
        """
        return self.optical_depth * self.density_at(directions, time_s=time_s, origin_m=origin_m)

    def transmittance_at(self, directions, *, air_mass, time_s: float = 0.0, origin_m=(0.0, 0.0)) -> np.ndarray:
        """Direct-beam transmittance of the layer along each direction (the *shade* view), shape ``(...)``.

        A footprint of cloud fraction ``f`` (:meth:`density_at`) passes
        ``(1 - f) + f exp(-tau m)``: the clear part unattenuated, the clouds'
        part through their full optical depth ``tau`` along the air mass ``m``
        (not through the footprint's mean depth, which would hide a low sun
        behind a 10 % cover: ``1 - exp(-x)`` is concave).

        Parameters
        ----------
        directions : array_like, shape (..., 3)
            Unit directions towards the source (east-north-up), e.g. the sun.
        air_mass : float or array_like, shape (...)
            Relative air mass of the path (``1 / sin(elevation)`` for a plane
            layer; :func:`bionav.light.daylight.relative_air_mass` near the horizon).
        time_s, origin_m
            As :meth:`density_at`.
        """
        f = self.density_at(directions, time_s=time_s, origin_m=origin_m)
        return (1.0 - f) + f * np.exp(-float(self.optical_depth) * np.asarray(air_mass, dtype=float))

    def cloudiness_at(self, view, *, time_s: float = 0.0, origin_m=(0.0, 0.0)) -> np.ndarray:
        """Cloudiness in ``[0, 1]`` at unit viewing directions ``(..., 3)`` (the *polarization* view).

        The same field as :meth:`density_at`; with :attr:`depolarization` and
        :attr:`angle_noise_sigma` it answers what :class:`~bionav.light.polarized_sky.SkyModel`
        asks of its ``clouds``, so a layer that shades the sun also depolarizes the sky.
        """
        return self.density_at(view, time_s=time_s, origin_m=origin_m)

    def angle_noise_at(self, view, *, time_s: float = 0.0, origin_m=(0.0, 0.0)) -> np.ndarray:
        """E-vector rotation (radians) at the viewing directions: cloudiness x ``angle_noise_sigma`` x field.

        The field is a second, independent plane-wave field of the layer (seeded
        from ``seed``), drifting with it, about standard normal.
        """
        d = np.asarray(view, dtype=float)
        c = self.cloudiness_at(d, time_s=time_s, origin_m=origin_m)
        return c * self.angle_noise_sigma * self._noise_field(d, time_s=time_s, origin_m=origin_m)

    def _noise_field(self, d: np.ndarray, *, time_s: float, origin_m) -> np.ndarray:
        """The layer's second plane-wave field (about standard normal) along directions ``d`` ``(..., 3)``."""
        dz = np.maximum(d[..., 2], np.sin(np.deg2rad(1.0)))
        reach = self.height_m / dz
        px = origin_m[0] + d[..., 0] * reach - self.wind_mps[0] * time_s
        py = origin_m[1] + d[..., 1] * reach - self.wind_mps[1] * time_s
        kvec, phase, amp = _plane_waves(np.random.default_rng([int(self.seed) & 0xFFFFFFFF, 1]), self.n_waves,
                                        self.scale_m)
        return np.sum(amp * np.cos(px[..., None] * kvec[:, 0] + py[..., None] * kvec[:, 1] + phase), axis=-1)

    def hemisphere_map(self, *, resolution: int = 96, time_s: float = 0.0, origin_m=(0.0, 0.0)) -> CloudMap:
        """The layer seen from ``origin_m`` at ``time_s``, sampled over the hemisphere (the *map* view).

        Parameters
        ----------
        resolution : int
            Grid size ``N`` of the azimuthal-equidistant map (see the module
            notes; points outside the disk hold the horizon at their azimuth).
        time_s, origin_m
            As :meth:`density_at`.

        Returns
        -------
        CloudMap
            ``cloudiness`` = :meth:`cloudiness_at` and ``angle_noise`` = the
            layer's noise field on the grid, ``(N, N)``, with this layer's
            ``angle_noise_sigma``, ``depolarization`` and ``brightness``.
        """
        n = int(resolution)
        if n < 2:
            raise ValueError(f"a cloud map needs a resolution of at least 2, got {resolution}")
        u = np.linspace(-1.0, 1.0, n)
        x, y = np.meshgrid(u, u)
        zen = np.minimum(np.hypot(x, y), 1.0) * (np.pi / 2.0)
        az = np.arctan2(y, x)
        d = np.stack([np.sin(zen) * np.cos(az), np.sin(zen) * np.sin(az), np.cos(zen)], axis=-1)
        return CloudMap(self.cloudiness_at(d, time_s=time_s, origin_m=origin_m),
                        self._noise_field(d, time_s=time_s, origin_m=origin_m),
                        float(self.angle_noise_sigma), float(self.depolarization), float(self.brightness))


def _plane_waves(r: np.random.Generator, n: int, scale_m: float):
    """``n`` random plane waves of wavelength ``scale_m * U(0.5, 2)``: wave vectors (1/m), phases, amplitudes.

    Amplitudes are normalised so that the sum of the waves has unit variance.
    """
    ang = r.uniform(0, 2 * np.pi, n)
    k = 2 * np.pi / (scale_m * r.uniform(0.5, 2.0, n))
    kvec = np.c_[k * np.cos(ang), k * np.sin(ang)]
    phase = r.uniform(0, 2 * np.pi, n)
    amp = r.uniform(0.5, 1.0, n)
    return kvec, phase, amp / np.sqrt(0.5 * np.sum(amp**2))
