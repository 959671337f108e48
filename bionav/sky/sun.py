"""Sun position from time and place (PyEphem), in bionav's sky frame.

Sky frame
---------
A local east-north-up frame: ``x`` east, ``y`` north, ``z`` up (zenith).
*Azimuth* is measured counter-clockwise from east seen from above (the
mathematical convention of :mod:`bionav.geometry`, **not** the compass
convention clockwise from north); *elevation* is positive above the horizon.
Angles are radians.
"""

from __future__ import annotations

import datetime as _dt
from dataclasses import dataclass

import numpy as np

from bionav.errors import UserError


@dataclass(frozen=True)
class SunPosition:
    """Sun direction in the sky frame.

    Attributes
    ----------
    azimuth : float
        Radians, counter-clockwise from east.
    elevation : float
        Radians above the horizon (apparent, with standard refraction).
    """

    azimuth: float
    elevation: float

    @property
    def direction(self) -> np.ndarray:
        """Unit vector towards the sun, shape ``(3,)``, sky frame (ENU)."""
        return direction_from_angles(self.azimuth, self.elevation)


def direction_from_angles(azimuth, elevation):
    """Unit vectors from azimuth and elevation.

    Parameters
    ----------
    azimuth, elevation : float or ndarray
        Radians; azimuth counter-clockwise from east, elevation above the
        horizon. Broadcast against each other.

    Returns
    -------
    ndarray, shape ``(..., 3)``
        ``(cos e cos a, cos e sin a, sin e)`` in the sky frame (ENU).
    """
    azimuth, elevation = np.broadcast_arrays(np.asarray(azimuth, float), np.asarray(elevation, float))
    ce = np.cos(elevation)
    return np.stack([ce * np.cos(azimuth), ce * np.sin(azimuth), np.sin(elevation)], axis=-1)


def angles_from_direction(direction):
    """Azimuth (CCW from east) and elevation of direction vectors, shape ``(..., 3)``."""
    d = np.asarray(direction, float)
    azimuth = np.arctan2(d[..., 1], d[..., 0])
    elevation = np.arctan2(d[..., 2], np.hypot(d[..., 0], d[..., 1]))
    return azimuth, elevation


def compass_to_azimuth(bearing):
    """Convert a compass bearing (clockwise from north) to an azimuth CCW from east (radians)."""
    return np.pi / 2.0 - np.asarray(bearing)


def azimuth_to_compass(azimuth):
    """Convert an azimuth CCW from east to a compass bearing clockwise from north, in ``[0, 2 pi)``."""
    return np.mod(np.pi / 2.0 - np.asarray(azimuth), 2.0 * np.pi)


def parse_time(when) -> _dt.datetime:
    """A timezone-aware UTC datetime from a datetime or an ISO-8601 string.

    Naive datetimes and strings without an offset are taken as UTC.
    """
    if isinstance(when, _dt.datetime):
        t = when
    else:
        try:
            t = _dt.datetime.fromisoformat(str(when))
        except ValueError:
            raise UserError(
                f"The time {when!r} is not an ISO-8601 date and time; write it like "
                "'2009-08-04T12:30:00+02:00' (a time without offset is taken as UTC)."
            ) from None
    if t.tzinfo is None:
        t = t.replace(tzinfo=_dt.timezone.utc)
    return t.astimezone(_dt.timezone.utc)


def sun_position(when, *, latitude_deg: float, longitude_deg: float, elevation_m: float = 0.0) -> SunPosition:
    """Apparent position of the sun for an observer on Earth.

    Uses PyEphem (VSOP87 planetary theory, no downloads), accurate to well
    under 0.01 degrees, which is far below the polarized-light compass'
    resolution.

    Parameters
    ----------
    when : datetime or str
        Time of observation; naive values are UTC.
    latitude_deg, longitude_deg : float
        Geodetic latitude (north positive) and longitude (east positive) in
        degrees.
    elevation_m : float, optional
        Observer height above sea level in metres.

    Returns
    -------
    SunPosition
        Azimuth counter-clockwise from east and elevation, radians.
    """
    import ephem

    if not -90.0 <= latitude_deg <= 90.0:
        raise UserError(f"Latitude {latitude_deg} deg is outside [-90, 90]; give the observer's latitude in degrees north.")
    t = parse_time(when)
    observer = ephem.Observer()
    observer.lat = np.deg2rad(latitude_deg)
    observer.lon = np.deg2rad(longitude_deg)
    observer.elevation = float(elevation_m)
    observer.date = ephem.Date(t.replace(tzinfo=None))
    sun = ephem.Sun(observer)
    return SunPosition(azimuth=float(compass_to_azimuth(float(sun.az))), elevation=float(sun.alt))
