"""Sun position from time and place (PyEphem), in bionav's sky frame; the one time parser.

Sky frame
---------
The ENU frame of :mod:`bionav.geometry`: ``x`` east, ``y`` north, ``z`` up
(zenith). *Azimuth* is measured counter-clockwise from east seen from above
(**not** the compass convention clockwise from north); *elevation* is
positive above the horizon. Angles are radians.
"""

from __future__ import annotations

import datetime as _dt
from dataclasses import dataclass

import numpy as np

from bionav.errors import UserError
from bionav.geometry import compass_to_azimuth, direction_from_angles

#: Bielefeld, Germany, where the thesis' spectral samples and scans were taken (degrees).
BIELEFELD_LAT_DEG = 52.02
BIELEFELD_LON_DEG = 8.53


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


def parse_time(when, *, what: str = "The time", naive_utc: bool = True) -> _dt.datetime:
    """A timezone-aware datetime from a datetime, a ``numpy.datetime64`` or an ISO-8601 string.

    Parameters
    ----------
    when : datetime, numpy.datetime64 or str
        The time. ``numpy.datetime64`` values carry no zone and count as UTC.
    what : str, optional
        How error messages name the value (e.g. ``"experiment.times[2]"``).
    naive_utc : bool, optional
        Take a time without offset as UTC (default); if false, such a time is
        an error asking for the offset.

    Returns
    -------
    datetime
        Aware, in the offset it was given in (UTC when it had none).

    Raises
    ------
    UserError
        Unparseable text, or a naive time when ``naive_utc`` is false.
    """
    if isinstance(when, np.datetime64):
        t = when.astype("datetime64[us]").item().replace(tzinfo=_dt.timezone.utc)
    elif isinstance(when, _dt.datetime):
        t = when
    else:
        try:
            t = _dt.datetime.fromisoformat(str(when))
        except ValueError:
            raise UserError(
                f"{what} {when!r} is not an ISO-8601 date and time; write it like "
                "'2009-08-04T12:30:00+02:00'" + (" (a time without offset is taken as UTC)." if naive_utc else ".")
            ) from None
    if t.tzinfo is None:
        if not naive_utc:
            raise UserError(f"{what} {when!r} has no time zone; append its offset, e.g. +02:00.")
        t = t.replace(tzinfo=_dt.timezone.utc)
    return t


def sun_position(when, *, latitude_deg: float, longitude_deg: float, elevation_m: float = 0.0) -> SunPosition:
    """Apparent position of the sun for an observer on Earth.

    Uses PyEphem (VSOP87 planetary theory, no downloads), accurate to well
    under 0.01 degrees, which is far below the polarized-light compass'
    resolution.

    Parameters
    ----------
    when : datetime, numpy.datetime64 or str
        Time of observation (see :func:`parse_time`); naive values are UTC.
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
    t = parse_time(when).astimezone(_dt.timezone.utc)
    observer = ephem.Observer()
    observer.lat = np.deg2rad(latitude_deg)
    observer.lon = np.deg2rad(longitude_deg)
    observer.elevation = float(elevation_m)
    observer.date = ephem.Date(t.replace(tzinfo=None))
    sun = ephem.Sun(observer)
    return SunPosition(azimuth=float(compass_to_azimuth(float(sun.az))), elevation=float(sun.alt))


def sun_track(start, offsets_s, *, latitude_deg: float, longitude_deg: float, step_s: float = 30.0):
    """The sun's apparent azimuth and elevation at many times after ``start`` (one ephemeris per ``step_s``).

    :func:`sun_position` is evaluated at ``start`` plus every ``step_s`` seconds over the span of
    ``offsets_s`` and interpolated linearly (azimuth unwrapped): the sun's azimuth changes by less than
    1.5 degrees a minute outside the tropics' noon, so the interpolation error of 30 s steps is below
    0.001 degrees (:func:`sun_position` itself: 0.01).

    Parameters
    ----------
    start : datetime, numpy.datetime64 or str
        Reference time (see :func:`parse_time`; naive values are UTC).
    offsets_s : array_like, shape ``(N,)``
        Seconds after ``start`` (any order, may be negative).
    latitude_deg, longitude_deg : float
        The observer, degrees (north and east positive).
    step_s : float
        Seconds between ephemeris evaluations.

    Returns
    -------
    azimuth, elevation : ndarray, shape ``(N,)``
        Radians, azimuth counter-clockwise from east (continuous over the span, not wrapped),
        elevation above the horizon.
    """
    t = np.asarray(offsets_s, float)
    if t.size == 0:
        return np.zeros(0), np.zeros(0)
    t0 = parse_time(start)
    lo, hi = float(np.min(t)), float(np.max(t))
    nodes = lo + float(step_s) * np.arange(int(np.ceil((hi - lo) / float(step_s))) + 1)
    at = [sun_position(t0 + _dt.timedelta(seconds=float(s)), latitude_deg=latitude_deg, longitude_deg=longitude_deg)
          for s in nodes]
    az = np.unwrap([p.azimuth for p in at])
    el = np.array([p.elevation for p in at])
    if nodes.size == 1:
        return np.full(t.shape, az[0]), np.full(t.shape, el[0])
    return np.interp(t, nodes, az), np.interp(t, nodes, el)
