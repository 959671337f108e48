"""Sky polarization and sun position (thesis chapter 4, Lambrinos et al. 2000, Berry et al. 2004)."""

from bionav.sky.clouds import CloudField, random_cloud_field
from bionav.sky.model import PolarizerLamp, SkyLight, SkyModel
from bionav.sky.neutral_points import berry_polarization
from bionav.sky.radiance import cie_relative_radiance
from bionav.sky.rayleigh import (
    angle_in_frame,
    max_degree_from_turbidity,
    rayleigh_degree,
    rayleigh_polarization,
    scattering_angle,
)
from bionav.sky.sun import SunPosition, direction_from_angles, sun_position

__all__ = [
    "CloudField",
    "PolarizerLamp",
    "SkyLight",
    "SkyModel",
    "SunPosition",
    "angle_in_frame",
    "berry_polarization",
    "cie_relative_radiance",
    "direction_from_angles",
    "max_degree_from_turbidity",
    "random_cloud_field",
    "rayleigh_degree",
    "rayleigh_polarization",
    "scattering_angle",
    "sun_position",
]
