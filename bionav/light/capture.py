"""The light during a capture that took a while: sun, drifting clouds and sky at each image's time.

A grid of images taken one after the other outdoors (thesis 3.1: *uni*, 170
images on a 1 m grid, Schatz 2006) sees the light change between captures:
the sun moves (:func:`bionav.light.sun.sun_position`), a cloud layer
(:class:`bionav.light.clouds.CloudLayer`) drifts across the sky and over the
sun. :class:`CaptureLight` answers, for each capture, where the sun stands,
how much of its direct light the layer lets through, the sky radiance
(:class:`~bionav.light.simple_sky.SimpleSky` behind the layer) and the diffuse
light that sky gives, per band. The renderer's side (relighting a scene with
these) is :func:`bionav.world.worlds.outdoor.build_uni`.

Frame: east-north-up (x east, y north, z up); times in seconds after the
capture's start (UTC).
"""

from __future__ import annotations

import datetime as dt
from dataclasses import dataclass

import numpy as np

from bionav.light.clouds import CloudLayer
from bionav.light.simple_sky import SKY_GAIN, SUN_GAIN, SimpleSky
from bionav.light.sun import parse_time, sun_position


def hemisphere_directions(n: int = 1024) -> tuple[np.ndarray, np.ndarray]:
    """Fibonacci directions over the upper hemisphere and their cosine weights.

    Returns
    -------
    directions : ndarray, shape (n, 3)
        Unit vectors (east-north-up), ``z > 0``.
    weights : ndarray, shape (n,)
        ``cos(zenith angle)`` weights summing to 1 (irradiance on a horizontal plane).
    """
    k = np.arange(n) + 0.5
    z = 1.0 - k / n
    phi = np.pi * (3.0 - np.sqrt(5.0)) * k
    rho = np.sqrt(1.0 - z ** 2)
    d = np.stack([rho * np.cos(phi), rho * np.sin(phi), z], axis=1)
    return d, z / z.sum()


@dataclass(frozen=True)
class CaptureLight:
    """The light at each capture of a grid recorded one image after the other.

    Capture ``k`` (``order[i, j]``) is taken ``seconds_per_capture * k``
    seconds after ``start_utc``. Then the sun stands where
    :func:`~bionav.light.sun.sun_position` puts it over ``site_deg``; its
    direct light passes the cloud layer with
    :meth:`CloudLayer.transmittance_at` (air mass ``1 / sin(elevation)``);
    the sky is :class:`~bionav.light.simple_sky.SimpleSky` behind the layer at
    that time, and the diffuse light follows the sky's cosine-weighted
    radiance relative to the clear sky's.

    Parameters
    ----------
    order : ndarray, shape (nx, ny), int
        Capture index of every grid cell, -1 where none was captured.
    clouds : CloudLayer
        The drifting layer (its ``time_s`` is seconds after ``start_utc``).
    site_deg : (float, float)
        Latitude and longitude of the site, degrees.
    start_utc : str
        Time of the first capture (ISO 8601, UTC).
    seconds_per_capture : float
        Seconds from one capture to the next.
    sun_irradiance, sky_irradiance : float
        Direct-sun irradiance (unclouded) and diffuse sky irradiance on an
        upward face (clear sky), in the renderer's units; per band times
        :data:`~bionav.light.simple_sky.SUN_GAIN` / :data:`~bionav.light.simple_sky.SKY_GAIN`.
    channels : tuple of str
        Band names.
    seed : int
        Seed of the sky (:class:`SimpleSky`).
    """

    order: np.ndarray
    clouds: CloudLayer
    site_deg: tuple[float, float]
    start_utc: str
    seconds_per_capture: float
    sun_irradiance: float = 2.2
    sky_irradiance: float = 1.2
    channels: tuple[str, ...] = ("grey",)
    seed: int = 0

    def describe(self) -> dict:
        """The model's parameters (JSON; part of the render cache key)."""
        c = self.clouds
        return {"model": "capture-light-2", "start_utc": self.start_utc, "site_deg": list(self.site_deg),
                "seconds_per_capture": float(self.seconds_per_capture), "cloud_cover": float(c.cover),
                "cloud_optical_depth": float(c.optical_depth), "cloud_height_m": float(c.height_m),
                "cloud_scale_m": float(c.scale_m), "cloud_softness": float(c.softness),
                "cloud_resolution": float(c.resolution), "wind_mps": [float(v) for v in c.wind_mps],
                "cloud_brightness": float(c.brightness), "cloud_seed": int(c.seed), "seed": int(self.seed)}

    def time_s(self, i: int, j: int) -> float:
        """Seconds after the start at which cell ``(i, j)`` was captured."""
        k = int(self.order[int(i), int(j)])
        if k < 0:
            raise ValueError(f"cell ({i}, {j}) was not captured")
        return k * float(self.seconds_per_capture)

    def sun_direction(self, t: float) -> np.ndarray:
        """Unit vector towards the sun (east-north-up), shape ``(3,)``, ``t`` seconds after the start."""
        when = parse_time(self.start_utc) + dt.timedelta(seconds=float(t))
        return np.asarray(sun_position(when, latitude_deg=self.site_deg[0], longitude_deg=self.site_deg[1]).direction,
                          float)

    def conditions(self, i: int, j: int) -> dict:
        """The light at cell ``(i, j)``'s capture.

        Returns
        -------
        dict
            ``t_s`` (seconds after the start), ``sun`` (3,) unit vector,
            ``sun_transmittance`` (direct light passed by the layer),
            ``sky`` (the sky callable, ``(N, 3) -> (N, C)``), ``diffuse_ratio``
            (cosine-weighted sky radiance relative to the clear sky's),
            ``sun_irradiance`` and ``sky_irradiance`` (C,) per band.
        """
        t = self.time_s(i, j)
        sun = self.sun_direction(t)
        air_mass = 1.0 / max(float(sun[2]), np.sin(np.deg2rad(1.0)))
        transmittance = float(self.clouds.transmittance_at(sun, air_mass=air_mass, time_s=t))
        clear = SimpleSky(sun_direction=tuple(sun), channels=self.channels, clouds=0.0, seed=int(self.seed))
        sky = SimpleSky(sun_direction=tuple(sun), channels=self.channels, clouds=0.0, seed=int(self.seed),
                        layer=self.clouds, time_s=t)
        dirs, w = hemisphere_directions()
        ratio = float((sky(dirs)[:, 0] * w).sum() / (clear(dirs)[:, 0] * w).sum())
        sun_e = np.array([self.sun_irradiance * SUN_GAIN.get(ch, 1.0) * transmittance for ch in self.channels])
        sky_e = np.array([self.sky_irradiance * SKY_GAIN.get(ch, 1.0) * ratio for ch in self.channels])
        return {"t_s": t, "sun": sun, "sun_transmittance": transmittance, "sky": sky, "diffuse_ratio": ratio,
                "sun_irradiance": sun_e, "sky_irradiance": sky_e}
