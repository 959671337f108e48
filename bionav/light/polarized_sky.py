"""The sky as a light source: radiance, degree and e-vector in any direction.

:class:`SkyModel` combines the sun position, the polarization model (Rayleigh
single scattering, or Berry et al. 2004 with neutral points), the
turbidity-limited maximum degree, the CIE clear-sky radiance and optional
clouds. :class:`PolarizerLamp` is the artificial source of the thesis' filter
test (section 4.2.1): unpolarized indirect light seen through a linear
polarizer. Both answer :meth:`light` for unit viewing directions in the sky
frame (east-north-up, azimuth counter-clockwise from east, radians).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.geometry import direction_from_angles
from bionav.light.clouds import CloudLayer, CloudMap
from bionav.light.neutral_points import berry_polarization
from bionav.light.radiance import cie_relative_radiance
from bionav.light.rayleigh import perpendicular, rayleigh_polarization
from bionav.light.sun import SunPosition


@dataclass(frozen=True)
class SkyLight:
    """Light arriving from a set of directions.

    Attributes
    ----------
    radiance : ndarray, shape ``(...)``
        Relative radiance.
    degree : ndarray, shape ``(...)``
        Degree of linear polarization in ``[0, 1]``.
    evector : ndarray, shape ``(..., 3)``
        Unit e-vectors perpendicular to the viewing directions (axial).
    """

    radiance: np.ndarray
    degree: np.ndarray
    evector: np.ndarray


@dataclass(frozen=True)
class SkyModel:
    """Polarized skylight for a sun position.

    Parameters
    ----------
    sun : SunPosition
        Sun azimuth (CCW from east) and elevation, radians.
    max_degree : float
        Degree of polarization 90 degrees from the sun (see
        :func:`bionav.light.rayleigh.max_degree_from_turbidity`).
    neutral_point_separation : float
        ``0`` selects the Rayleigh model; a positive angle (radians) the
        Berry et al. (2004) model with that Babinet-Brewster separation.
    clouds : CloudLayer, CloudMap or None
        Optional clouds (lower the degree, add e-vector angle noise, brighten):
        a :class:`~bionav.light.clouds.CloudLayer` (its polarization view at
        time 0) or a sampled :class:`~bionav.light.clouds.CloudMap`.
    """

    sun: SunPosition
    max_degree: float = 0.76
    neutral_point_separation: float = 0.0
    clouds: CloudLayer | CloudMap | None = None

    def light(self, view) -> SkyLight:
        """Radiance, degree and e-vector for unit viewing directions ``(..., 3)``."""
        view = np.asarray(view, float)
        s = self.sun.direction
        if self.neutral_point_separation > 0.0:
            degree, evector = berry_polarization(
                view, s, neutral_point_separation=self.neutral_point_separation, max_degree=self.max_degree
            )
        else:
            degree, evector = rayleigh_polarization(view, s, max_degree=self.max_degree)
        radiance = cie_relative_radiance(view, s)
        if self.clouds is not None:
            c = self.clouds.cloudiness_at(view)
            degree = degree * (1.0 - self.clouds.depolarization * c)
            radiance = radiance * (1.0 - c) + self.clouds.brightness * c
            turn = self.clouds.angle_noise_at(view)
            evector = np.cos(turn)[..., None] * evector + np.sin(turn)[..., None] * np.cross(view, evector)
        return SkyLight(radiance, degree, evector)


@dataclass(frozen=True)
class PolarizerLamp:
    """Unpolarized light through a linear polarizer held over the compass.

    Parameters
    ----------
    axis_azimuth : float
        Transmission axis of the polarizer in the horizontal plane, radians
        counter-clockwise from east (axial).
    degree : float
        Degree of polarization after the foil (its efficiency).
    """

    axis_azimuth: float = 0.0
    degree: float = 0.99

    def light(self, view) -> SkyLight:
        """Uniform radiance, constant degree, e-vector = the axis projected perpendicular to the view."""
        view = np.asarray(view, float)
        axis = direction_from_angles(self.axis_azimuth, 0.0)
        e = axis - np.sum(view * axis, axis=-1, keepdims=True) * view
        norm = np.linalg.norm(e, axis=-1, keepdims=True)
        e = np.where(norm < 1e-12, perpendicular(view), e / np.maximum(norm, 1e-12))
        shape = view.shape[:-1]
        return SkyLight(np.ones(shape), np.full(shape, self.degree), e)
