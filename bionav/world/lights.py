"""Light sources of the synthetic worlds (Lambertian shading, no inter-reflection).

Conventions: world frame in metres, ``+z`` up. A surface point ``X`` with unit
normal ``n`` (facing the viewer) and albedo ``a`` (per channel) reflects

``a * tex * (E_amb(n) + sum_k E_k)``

where ``E_amb(n) = down + (up - down) * (1 + n_z) / 2`` is a hemispherical
ambient term (light from above vs. bounced from the floor) and ``E_k`` the
irradiance from light ``k``, zero where a shadow-casting primitive blocks it.
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass

import numpy as np


def _channels(value, n_channels: int) -> np.ndarray:
    arr = np.asarray(value, np.float64).reshape(-1)
    if arr.size == 1:
        return np.full(n_channels, float(arr[0]))
    if arr.size != n_channels:
        raise ValueError(f"expected 1 or {n_channels} channel values, got {arr.size}")
    return arr


@dataclass(frozen=True)
class PointLight:
    """An isotropic or downward-facing Lambertian point emitter.

    Parameters
    ----------
    position : tuple of float
        ``(x, y, z)`` in metres.
    intensity : float or sequence of float
        Radiant intensity per channel; irradiance at distance ``d`` is
        ``intensity * cos(theta_surface) [* cos(theta_emitter)] / d**2``.
    downward : bool
        If True the emitter is a small Lambertian panel facing ``-z`` (ceiling
        lights): it emits nothing upwards.
    group : int, optional
        Lights with the same group (the point lights of one light band) share
        one shadow ray per surface point, aimed at the group's light that
        contributes most there: the group is either seen or shadowed as a
        whole. ``None`` makes the light its own group.
    """

    position: tuple[float, float, float]
    intensity: float | tuple[float, ...] = 1.0
    downward: bool = True
    group: int | None = None


@dataclass(frozen=True)
class DirectionalLight:
    """A distant light (the sun).

    Parameters
    ----------
    direction : tuple of float
        Unit vector *towards* the light, world frame.
    irradiance : float or sequence of float
        Irradiance per channel on a surface facing the light.
    """

    direction: tuple[float, float, float]
    irradiance: float | tuple[float, ...] = 1.0


@dataclass(frozen=True)
class Ambient:
    """Hemispherical ambient light: ``up`` on upward faces, ``down`` on downward faces (per channel)."""

    up: float | tuple[float, ...] = 0.2
    down: float | tuple[float, ...] = 0.1


def light_band(start, end, *, n: int = 4, intensity: float | tuple[float, ...] = 1.0,
               group: int | None = None) -> list[PointLight]:
    """A ceiling light band (fluorescent tubes) approximated by ``n`` downward point lights.

    Parameters
    ----------
    start, end : sequence of 3 float
        End points of the band in metres (world frame).
    n : int
        Number of point lights spread evenly along the band.
    intensity : float or sequence of float
        Total intensity of the band, split evenly over the point lights.
    group : int, optional
        Shadow group of the band's lights (see :class:`PointLight`); ``None``
        picks a group id derived from the band's end points.

    Returns
    -------
    list of PointLight
    """
    a = np.asarray(start, float)
    b = np.asarray(end, float)
    inten = np.asarray(intensity, float) / n
    if group is None:
        group = zlib.crc32(np.concatenate([a, b]).tobytes())
    out = []
    for k in range(n):
        p = a + (b - a) * (k + 0.5) / n
        out.append(PointLight(tuple(float(v) for v in p), tuple(float(v) for v in np.atleast_1d(inten)), True,
                              group))
    return out


def pack_lights(lights, n_channels: int) -> tuple[np.ndarray, np.ndarray]:
    """Pack lights into kernel arrays.

    Returns
    -------
    params : ndarray, shape (L, 6)
        ``[kind, x, y, z, downward, group]`` with kind 0 = point, 1 =
        directional (``x, y, z`` is then the unit direction towards the
        light); lights are ordered so that each shadow group is contiguous.
    power : ndarray, shape (L, C)
        Intensity (point) or irradiance (directional) per channel.
    """
    params = np.zeros((len(lights), 6))
    power = np.zeros((len(lights), n_channels))
    groups = {}
    for i, light in enumerate(lights):
        g = getattr(light, "group", None)
        key = ("own", i) if g is None else ("grp", g)
        groups.setdefault(key, len(groups))
        if isinstance(light, PointLight):
            params[i] = (0, *light.position, float(light.downward), groups[key])
            power[i] = _channels(light.intensity, n_channels)
        elif isinstance(light, DirectionalLight):
            d = np.asarray(light.direction, float)
            d = d / np.linalg.norm(d)
            params[i] = (1, *d, 0.0, groups[key])
            power[i] = _channels(light.irradiance, n_channels)
        else:
            raise TypeError(f"unknown light {light!r}")
    order = np.argsort(params[:, 5], kind="stable")
    return params[order], power[order]
