"""Clouds as spatially correlated random fields over the sky hemisphere.

A cloud field is a smooth Gaussian random field on a square grid covering the
azimuthal-equidistant projection of the upper hemisphere (zenith at the
centre, the horizon on the unit circle: ``r = zenith_angle / (pi / 2)``),
thresholded at the quantile that gives the requested cloud cover. Its value,
the *cloudiness* in ``[0, 1]``, ramps from 0 (clear) to 1 (overcast) over a
soft edge. A second independent field supplies the e-vector angle noise that
scattering in and under clouds adds. All randomness comes from the numpy
``Generator`` passed in.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class CloudField:
    """A sampled cloud field.

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


def random_cloud_field(
    rng: np.random.Generator,
    *,
    cover: float,
    correlation_length: float = np.deg2rad(15.0),
    edge: float = 0.2,
    resolution: int = 96,
    angle_noise_sigma: float = np.deg2rad(20.0),
    depolarization: float = 0.9,
    brightness: float = 1.5,
) -> CloudField:
    """Draw a cloud field with a given cloud cover.

    Parameters
    ----------
    rng : numpy.random.Generator
        Source of randomness.
    cover : float
        Fraction of the projection disk (approximately of the sky) covered by
        cloud, ``0`` (clear) to ``1`` (overcast).
    correlation_length : float, optional
        Standard deviation of the Gaussian smoothing kernel, as an angle on the
        sky (radians); sets the size of cloud patches.
    edge : float, optional
        Width of the clear-to-cloud ramp in standard deviations of the field.
    resolution : int, optional
        Grid size ``N``.
    angle_noise_sigma, depolarization, brightness : float, optional
        See :class:`CloudField`.

    Returns
    -------
    CloudField
    """
    from scipy.ndimage import gaussian_filter

    if not 0.0 <= cover <= 1.0:
        raise ValueError(f"cloud cover must be in [0, 1], got {cover}")
    sigma_px = correlation_length / (np.pi / 2.0) * (resolution - 1) / 2.0
    u = np.linspace(-1.0, 1.0, resolution)
    x, y = np.meshgrid(u, u)
    disk = np.hypot(x, y) <= 1.0

    def smooth_field():
        f = gaussian_filter(rng.standard_normal((resolution, resolution)), sigma_px, mode="wrap")
        return (f - f[disk].mean()) / f[disk].std()

    field = smooth_field()
    noise = smooth_field()
    if cover <= 0.0:
        cloudiness = np.zeros_like(field)
    elif cover >= 1.0:
        cloudiness = np.ones_like(field)
    else:
        threshold = np.quantile(field[disk], 1.0 - cover)
        cloudiness = np.clip(0.5 + (field - threshold) / edge, 0.0, 1.0)
    return CloudField(cloudiness, noise, angle_noise_sigma, depolarization, brightness)
