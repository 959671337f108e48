"""The light during a capture that took a while: sun, clouds and sky at each image's time.

A database recorded one image after the other sees the light change between
captures. Outdoors (thesis 3.1: *uni*, 170 images on a 1 m grid, Schatz 2006)
the sun moves (:func:`bionav.light.sun.sun_position`), a cloud layer
(:class:`bionav.light.clouds.CloudLayer`) drifts across the sky and over the
sun. Indoors (the living rooms, Kreft 2007: hours of supervised recording) the
same light enters through a room's windows: the sun's patches move across the
room and come and go with passing clouds, and the sky seen through the
windows brightens and darkens with them.

:class:`CaptureLight` is that light, one class for both: per capture, where
the sun stands, how much of its direct light the clouds let through and how
bright the sky is. Where the light enters (the whole sky outdoors, a room's
windows indoors) is geometry and belongs to the renderer: a world's aperture,
:class:`bionav.world.worlds.common.OpenSky` (relights an outdoor scene) or
:class:`bionav.world.worlds.common.Windows` (lets the light into a room), both
behind the one capture interface :meth:`bionav.world.worlds.common.World.capture_scenes`.

Frame: east-north-up (x east, y north, z up; azimuths counter-clockwise from
``+x``); times in seconds after the first capture (UTC).
"""

from __future__ import annotations

import datetime as dt
import hashlib
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


@dataclass(frozen=True, kw_only=True)
class CaptureLight:
    """The light at each capture of a grid recorded one image after the other.

    Capture ``k`` (``order[i, j]``) is taken ``seconds_per_capture * k``
    seconds after the first. The sun follows one of two paths:

    * the ephemeris (``site_deg`` and ``start_utc`` given): where
      :func:`~bionav.light.sun.sun_position` puts it over the site;
    * a stated path (``sun_azimuth_deg`` and ``sun_elevation_deg`` given):
      from the first to the last capture, azimuth and elevation linear in the
      capture index (the living-room stand-ins, whose recording day is not
      known).

    The clouds are one of two models:

    * a drifting :class:`~bionav.light.clouds.CloudLayer` (``clouds``): the
      sun's direct light passes it with :meth:`CloudLayer.transmittance_at`
      (air mass ``1 / sin(elevation)``), the sky is
      :class:`~bionav.light.simple_sky.SimpleSky` behind it (:meth:`conditions`);
    * without a layer, the sun's transmission along the capture order: a
      stationary AR(1) log-normal process of log-standard deviation
      ``cloud_sigma`` and correlation length ``cloud_images`` captures, mean 1
      (:meth:`session_conditions`; ``cloud_sigma=0``: a clear day).

    Parameters
    ----------
    order : ndarray, shape (nx, ny), int
        Capture index of every grid cell, -1 where none was captured.
    seconds_per_capture : float
        Seconds from one capture to the next.
    site_deg : (float, float), optional
        Latitude and longitude of the site, degrees (ephemeris path).
    start_utc : str, optional
        Time of the first capture (ISO 8601, UTC; ephemeris path).
    sun_azimuth_deg, sun_elevation_deg : (float, float), optional
        Direction towards the sun at the first and at the last capture,
        degrees (stated path; azimuth counter-clockwise from east, ``+x``).
    clouds : CloudLayer, optional
        The drifting layer (its ``time_s`` is seconds after the first capture).
    cloud_sigma : float
        Log-standard deviation of the sun's transmission (no layer).
    cloud_images : float
        Correlation length of that transmission, in captures (no layer).
    sun_irradiance : float
        Irradiance of the unclouded sun on a surface facing it, in the
        renderer's units (outdoors per band times
        :data:`~bionav.light.simple_sky.SUN_GAIN`).
    sky_irradiance : float
        Diffuse sky irradiance on an upward face (clear sky), in the
        renderer's units; per band times :data:`~bionav.light.simple_sky.SKY_GAIN`.
    channels : tuple of str
        Band names.
    """

    order: np.ndarray
    seconds_per_capture: float
    site_deg: tuple[float, float] | None = None
    start_utc: str | None = None
    sun_azimuth_deg: tuple[float, float] | None = None
    sun_elevation_deg: tuple[float, float] | None = None
    clouds: CloudLayer | None = None
    cloud_sigma: float = 0.0
    cloud_images: float = 20.0
    sun_irradiance: float = 2.2
    sky_irradiance: float = 1.2
    channels: tuple[str, ...] = ("grey",)

    def __post_init__(self) -> None:
        ephemeris = self.site_deg is not None and self.start_utc is not None
        stated = self.sun_azimuth_deg is not None and self.sun_elevation_deg is not None
        if ephemeris == stated:
            raise ValueError("CaptureLight needs one sun path: site_deg and start_utc (the ephemeris) or "
                             "sun_azimuth_deg and sun_elevation_deg (a stated path), not both or neither")
        if not (np.isfinite(self.seconds_per_capture) and self.seconds_per_capture >= 0):
            raise ValueError(f"CaptureLight.seconds_per_capture must be a finite number >= 0, "
                             f"got {self.seconds_per_capture!r}")

    @property
    def n_captures(self) -> int:
        """Number of captures (the largest capture index plus one)."""
        return int(np.max(self.order)) + 1

    def describe(self) -> dict:
        """The model's parameters (JSON; part of the render cache key)."""
        c = self.clouds
        if c is not None and self.start_utc is not None:  # the uni capture's key (capture-light-2)
            return {"model": "capture-light-2", "start_utc": self.start_utc, "site_deg": list(self.site_deg),
                    "seconds_per_capture": float(self.seconds_per_capture), "cloud_cover": float(c.cover),
                    "cloud_optical_depth": float(c.optical_depth), "cloud_height_m": float(c.height_m),
                    "cloud_scale_m": float(c.scale_m), "cloud_softness": float(c.softness),
                    "cloud_resolution": float(c.resolution), "wind_mps": [float(v) for v in c.wind_mps],
                    "cloud_brightness": float(c.brightness), "cloud_seed": int(c.seed)}
        order = np.ascontiguousarray(self.order, np.int64)
        out = {"model": "capture-light-3", "order_sha256": hashlib.sha256(order.tobytes()).hexdigest()[:16],
               "grid_shape": list(order.shape), "seconds_per_capture": float(self.seconds_per_capture),
               "sun_irradiance": float(self.sun_irradiance), "sky_irradiance": float(self.sky_irradiance),
               "channels": list(self.channels)}
        if self.start_utc is not None:
            out.update(start_utc=self.start_utc, site_deg=[float(v) for v in self.site_deg])
        else:
            out.update(sun_azimuth_deg=[float(v) for v in self.sun_azimuth_deg],
                       sun_elevation_deg=[float(v) for v in self.sun_elevation_deg])
        if c is not None:
            out["clouds"] = {"cover": float(c.cover), "optical_depth": float(c.optical_depth),
                             "height_m": float(c.height_m), "scale_m": float(c.scale_m),
                             "softness": float(c.softness), "resolution": float(c.resolution),
                             "wind_mps": [float(v) for v in c.wind_mps], "brightness": float(c.brightness),
                             "seed": int(c.seed)}
        else:
            out.update(cloud_sigma=float(self.cloud_sigma), cloud_images=float(self.cloud_images))
        return out

    def time_s(self, i: int, j: int) -> float:
        """Seconds after the start at which cell ``(i, j)`` was captured."""
        k = int(self.order[int(i), int(j)])
        if k < 0:
            raise ValueError(f"cell ({i}, {j}) was not captured")
        return k * float(self.seconds_per_capture)

    def capture_fraction(self, cells: np.ndarray) -> np.ndarray:
        """Capture time of each cell as a fraction ``0 .. 1`` of the session.

        Parameters
        ----------
        cells : ndarray, shape (N, 2), int
            Grid cells ``(i, j)`` (captured ones).

        Returns
        -------
        ndarray, shape (N,)
            0 for the first capture, 1 for the last.
        """
        cells = np.asarray(cells, np.int64).reshape(-1, 2)
        return self.order[cells[:, 0], cells[:, 1]] / max(self.n_captures - 1, 1)

    def _stated_sun(self, fraction: np.ndarray) -> np.ndarray:
        """Sun directions ``(N, 3)`` of the stated path at capture-time fractions ``(N,)``."""
        a, e = self.sun_azimuth_deg, self.sun_elevation_deg
        az = np.radians(a[0] + fraction * (a[1] - a[0]))
        el = np.radians(e[0] + fraction * (e[1] - e[0]))
        return np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=1)

    def sun_direction(self, t: float) -> np.ndarray:
        """Unit vector towards the sun (east-north-up), shape ``(3,)``, ``t`` seconds after the start."""
        if self.start_utc is None:
            duration = float(self.seconds_per_capture) * max(self.n_captures - 1, 1)
            return self._stated_sun(np.array([float(t) / duration if duration > 0 else 0.0]))[0]
        when = parse_time(self.start_utc) + dt.timedelta(seconds=float(t))
        return np.asarray(sun_position(when, latitude_deg=self.site_deg[0], longitude_deg=self.site_deg[1]).direction,
                          float)

    def conditions(self, i: int, j: int) -> dict:
        """The light of the whole sky at cell ``(i, j)``'s capture (outdoors; needs ``clouds``).

        Returns
        -------
        dict
            ``t_s`` (seconds after the start), ``sun`` (3,) unit vector,
            ``sun_transmittance`` (direct light passed by the layer),
            ``sky`` (the sky callable, ``(N, 3) -> (N, C)``), ``diffuse_ratio``
            (cosine-weighted sky radiance relative to the clear sky's),
            ``sun_irradiance`` and ``sky_irradiance`` (C,) per band.
        """
        if self.clouds is None:
            raise ValueError("CaptureLight.conditions needs a cloud layer (clouds=CloudLayer(...)); "
                             "without one use session_conditions")
        t = self.time_s(i, j)
        sun = self.sun_direction(t)
        air_mass = 1.0 / max(float(sun[2]), np.sin(np.deg2rad(1.0)))
        transmittance = float(self.clouds.transmittance_at(sun, air_mass=air_mass, time_s=t))
        clear = SimpleSky(sun_direction=tuple(sun), channels=self.channels)
        sky = SimpleSky(sun_direction=tuple(sun), channels=self.channels, layer=self.clouds, time_s=t)
        dirs, w = hemisphere_directions()
        ratio = float((sky(dirs)[:, 0] * w).sum() / (clear(dirs)[:, 0] * w).sum())
        sun_e = np.array([self.sun_irradiance * SUN_GAIN.get(ch, 1.0) * transmittance for ch in self.channels])
        sky_e = np.array([self.sky_irradiance * SKY_GAIN.get(ch, 1.0) * ratio for ch in self.channels])
        return {"t_s": t, "sun": sun, "sun_transmittance": transmittance, "sky": sky, "diffuse_ratio": ratio,
                "sun_irradiance": sun_e, "sky_irradiance": sky_e}

    def session_conditions(self, cells: np.ndarray, *, rng: np.random.Generator) -> dict:
        """Sun direction, its transmission and the skylight factor at each cell's capture (through windows).

        Parameters
        ----------
        cells : ndarray, shape (N, 2), int
            Grid cells ``(i, j)`` (captured ones).
        rng : numpy.random.Generator
            The recording session's cloud stream (without a layer the
            transmission along the capture order is drawn from it; with a
            layer it is not used).

        Returns
        -------
        dict
            ``fraction`` (N,) capture time fraction, ``sun_dir`` (N, 3) unit
            vectors towards the sun, ``transmission`` (N,) the clouds'
            transmission of the sun (without a layer mean 1 over the
            session's process), ``sky`` (N,) skylight factor ``(1 + T) / 2``
            (the sky beside the sun is brighter when the sun is out).
        """
        cells = np.asarray(cells, np.int64).reshape(-1, 2)
        f = self.capture_fraction(cells)
        if self.start_utc is None:
            sun = self._stated_sun(f)
        else:
            sun = np.stack([self.sun_direction(self.time_s(i, j)) for i, j in cells]).reshape(-1, 3)
        if self.clouds is not None:
            t = np.array([self.clouds.transmittance_at(s, air_mass=1.0 / max(float(s[2]), np.sin(np.deg2rad(1.0))),
                                                       time_s=self.time_s(i, j)) for s, (i, j) in zip(sun, cells)],
                         float)
        else:
            n_total = self.n_captures
            rho = float(np.exp(-1.0 / max(self.cloud_images, 1e-9)))
            z = np.empty(n_total)
            e = rng.standard_normal(n_total)
            z[0] = e[0]
            for k in range(1, n_total):
                z[k] = rho * z[k - 1] + np.sqrt(1.0 - rho * rho) * e[k]
            s = float(self.cloud_sigma)
            t_all = np.exp(s * z - 0.5 * s * s)
            t = t_all[np.rint(f * (n_total - 1)).astype(np.int64)]
        return {"fraction": f, "sun_dir": sun, "transmission": t, "sky": 0.5 * (1.0 + t)}
