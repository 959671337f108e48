"""Sun position from time and place (PyEphem; no run-time downloads)."""

from __future__ import annotations

import datetime as _dt

import numpy as np

#: Bielefeld, Germany, where the thesis' samples and scans were taken (degrees).
BIELEFELD_LAT_DEG = 52.02
BIELEFELD_LON_DEG = 8.53


def _as_utc(time) -> _dt.datetime:
    if isinstance(time, np.datetime64):
        time = time.astype("datetime64[us]").item()
    if isinstance(time, str):
        time = _dt.datetime.fromisoformat(time)
    if not isinstance(time, _dt.datetime):
        raise TypeError(f"time must be a datetime, numpy datetime64 or ISO string, got {type(time)}")
    if time.tzinfo is None:
        raise ValueError("time must carry a time zone (e.g. '2009-06-17T11:27:04+02:00')")
    return time.astimezone(_dt.timezone.utc).replace(tzinfo=None)


def sun_position(time, *, latitude_deg: float = BIELEFELD_LAT_DEG, longitude_deg: float = BIELEFELD_LON_DEG):
    """Apparent position of the sun's centre seen from a place on Earth.

    Parameters
    ----------
    time : datetime.datetime (time-zone aware) or ISO 8601 string with offset
        Moment of observation.
    latitude_deg, longitude_deg : float
        Observer's geodetic latitude (north positive) and longitude (east
        positive) in degrees.

    Returns
    -------
    elevation : float
        Radians above the horizon (with standard refraction).
    azimuth : float
        Radians, geographic convention: from north, clockwise (east = pi/2).

    Notes
    -----
    Uses PyEphem (VSOP87 ephemeris, accuracy far below 0.01 degree).
    """
    import ephem

    obs = ephem.Observer()
    obs.lat = str(latitude_deg)
    obs.lon = str(longitude_deg)
    obs.elevation = 0.0
    obs.date = ephem.Date(_as_utc(time))
    sun = ephem.Sun(obs)
    return float(sun.alt), float(sun.az)
