"""Where light comes from: the sun, the sky, clouds, spectral daylight, bands and materials.

Modules
-------
* :mod:`~bionav.light.sun` -- the one :func:`sun_position` (PyEphem) and the
  one time parser :func:`parse_time`.
* :mod:`~bionav.light.rayleigh`, :mod:`~bionav.light.neutral_points`,
  :mod:`~bionav.light.radiance`, :mod:`~bionav.light.polarized_sky` -- sky
  polarization for the polarized-light compass (thesis chapter 4; Lambrinos
  et al. 2000, doi:10.1016/S0921-8890(99)00064-0; Berry et al. 2004,
  doi:10.1088/1367-2630/6/1/162).
* :mod:`~bionav.light.clouds` -- :class:`CloudLayer` (the one drifting cloud
  layer: cover, optical depth, direct-sun transmittance, polarization) and
  :class:`CloudMap` (the compass recordings' sampled sky map, chapter 4).
* :mod:`~bionav.light.capture` -- :class:`~bionav.light.capture.CaptureLight`,
  the light at each image of a capture that took a while (sun, clouds, sky),
  outdoors and through a room's windows.
* :mod:`~bionav.light.daylight` -- spectral sun, sky and cloud radiance and
  the irradiance they give on the ground (chapter 6).
* :mod:`~bionav.light.measured_spectra` -- the measured spectra shipped in
  ``bionav/data/spectra`` (ASTM G173 sun, Bird & Riordan gas absorption,
  bumbleview leaf and petal reflectances, D65).
* :mod:`~bionav.light.bands` -- the five sensor channels and their features.
* :mod:`~bionav.light.materials` -- material reflectance spectra (measured or from band tables).
* :mod:`~bionav.light.simple_sky` -- the rendered outdoor worlds' default sky.

Frame: east-north-up; azimuths are radians counter-clockwise from east,
elevations radians above the horizon.
"""

from bionav.light.clouds import CloudLayer, CloudMap, random_cloud_map
from bionav.light.neutral_points import berry_polarization
from bionav.light.polarized_sky import PolarizerLamp, SkyLight, SkyModel
from bionav.light.radiance import cie_relative_radiance
from bionav.light.rayleigh import (
    angle_in_frame,
    max_degree_from_turbidity,
    rayleigh_degree,
    rayleigh_polarization,
    scattering_angle,
)
from bionav.light.sun import SunPosition, parse_time, sun_position, sun_track

__all__ = [
    "CloudLayer",
    "CloudMap",
    "PolarizerLamp",
    "SkyLight",
    "SkyModel",
    "SunPosition",
    "angle_in_frame",
    "berry_polarization",
    "cie_relative_radiance",
    "max_degree_from_turbidity",
    "parse_time",
    "random_cloud_map",
    "rayleigh_degree",
    "rayleigh_polarization",
    "scattering_angle",
    "sun_position",
    "sun_track",
]
