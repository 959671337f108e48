"""Labelled sky/object sample sets of the five-channel sensor (thesis 6.2.1, 6.3.1).

A :class:`SampleSet` holds one data point per row: the five channel counts (the
mean of ``n_average`` subsequent readings, as in the thesis), whether it is sky,
the kind of sky or object, and when it was taken. Simulated sets mirror the
thesis' collections:

* :func:`sim_natural`: 239 natural objects (grass, shrubs, trees, tar, dead leaves
  and wood, rock, gravel, sand, soil; 5-30 m away) and 233 sky readings, taken
  9 May - 20 June 2006 near Bielefeld at random times of day and weather from
  clear to drizzle, in sun and shade.
* :func:`sim_artificial`: 124 artificial objects (paint, plastic, lacquered and
  bare metal; 0.5-2 m away), 14 Jan - 10 May 2007 and 10-15 May 2008, with the
  *same* 233 sky readings as :func:`sim_natural` for the same seed (the thesis
  reuses its sky readings).

Each sample draws a time, a weather regime of that day, a cloud field, the
viewing direction and, for objects, a material reflectance spectrum
(:data:`bionav.light.materials.MATERIALS`: measured leaf and petal spectra for
vegetation and flowers, five-band tables elsewhere), a surface orientation, sun
or shadow and a distance. The object radiance per channel is
``int S_b(lambda) rho(lambda) E(lambda) dlambda / pi`` with the spectral
irradiance ``E`` of :mod:`bionav.light.daylight`; counts come from the
logarithmic :class:`~bionav.spectral.sensor_model.LogSensorModel`, so a
contrast (difference of two channels' counts) is a log ratio of band radiances.
"""

from __future__ import annotations

import datetime as _dt
from dataclasses import dataclass

import numpy as np

from bionav.geometry import direction_from_angles
from bionav.light.bands import CHANNELS, PEAK_NM, band_integrate
from bionav.light.clouds import CloudLayer
from bionav.light.daylight import (
    SkyState,
    aerosol_optical_depth,
    band_sky_radiance,
    illumination,
    rayleigh_optical_depth,
)
from bionav.light.materials import (
    ARTIFICIAL_GROUND_MIX,
    ARTIFICIAL_MIX,
    MATERIALS,
    NATURAL_GROUND_MIX,
    NATURAL_MIX,
)
from bionav.light.sun import BIELEFELD_LAT_DEG, BIELEFELD_LON_DEG, sun_position
from bionav.spectral.sensor_model import LogSensorModel


@dataclass(frozen=True)
class SampleSet:
    """Sky and object readings of the five-channel sensor.

    Attributes
    ----------
    counts : ndarray, shape (N, 5), float
        Channel counts UV, B, G, R, IR (12-bit ADC units of the log signal; the
        mean of several readings, hence float).
    is_sky : ndarray of bool, shape (N,)
        True for sky (background), False for objects (foreground).
    kind : ndarray of str, shape (N,)
        Sky type or object material ("" when unknown).
    time : ndarray of str, shape (N,)
        ISO 8601 time of the reading ("" when unknown).
    name : str
        Where the set came from (``sim_natural``, a CSV path ...).
    """

    counts: np.ndarray
    is_sky: np.ndarray
    kind: np.ndarray
    time: np.ndarray
    name: str = ""

    def __len__(self) -> int:
        return len(self.is_sky)

    @property
    def n_sky(self) -> int:
        """Number of sky samples."""
        return int(np.count_nonzero(self.is_sky))

    @property
    def n_objects(self) -> int:
        """Number of object samples."""
        return int(np.count_nonzero(~self.is_sky))

    def concat(self, other: "SampleSet", *, name: str | None = None) -> "SampleSet":
        """Rows of ``self`` followed by rows of ``other``."""
        return SampleSet(
            np.vstack([self.counts, other.counts]),
            np.r_[self.is_sky, other.is_sky],
            np.r_[self.kind, other.kind],
            np.r_[self.time, other.time],
            name or self.name,
        )


_REGIMES = {
    # name: (probability, cover range, optical depth range, cloud kind)
    "clear": (0.22, (0.0, 0.0), (0.0, 0.0), "blue_sky"),
    "cirrus": (0.12, (0.3, 0.8), (0.5, 3.0), "cirrus"),
    "fair": (0.24, (0.15, 0.45), (10.0, 30.0), "cumulus"),
    "cloudy": (0.2, (0.5, 0.85), (15.0, 45.0), "cumulus"),
    "overcast": (0.16, (1.0, 1.0), (20.0, 60.0), "stratus"),
    "drizzle": (0.06, (1.0, 1.0), (60.0, 120.0), "nimbostratus"),
}


def _berlin(date: _dt.datetime) -> _dt.datetime:
    try:
        from zoneinfo import ZoneInfo

        return date.replace(tzinfo=ZoneInfo("Europe/Berlin"))
    except Exception:  # no tz database: central European summer/winter time by month
        off = 2 if 4 <= date.month <= 10 else 1
        return date.replace(tzinfo=_dt.timezone(_dt.timedelta(hours=off)))


def _draw_time(rng, ranges, min_elevation):
    lengths = np.array([(b - a).days + 1 for a, b in ranges], dtype=float)
    while True:
        k = rng.choice(len(ranges), p=lengths / lengths.sum())
        day = ranges[k][0] + _dt.timedelta(days=int(rng.integers(0, lengths[k])))
        minutes = int(rng.integers(8 * 60, 19 * 60 + 30))
        t = _berlin(_dt.datetime(day.year, day.month, day.day, minutes // 60, minutes % 60, int(rng.integers(0, 60))))
        sun = sun_position(t, latitude_deg=BIELEFELD_LAT_DEG, longitude_deg=BIELEFELD_LON_DEG)
        if sun.elevation >= min_elevation:
            return t, sun.elevation, sun.azimuth


class _Weather:
    """Weather regime per day (drawn once per date)."""

    def __init__(self, rng):
        self.rng = rng
        self.days = {}

    def state(self, t, el, az):
        key = t.date()
        if key not in self.days:
            names = list(_REGIMES)
            p = np.array([_REGIMES[n][0] for n in names])
            self.days[key] = (names[self.rng.choice(len(names), p=p / p.sum())], float(self.rng.uniform(0.05, 0.2)))
        regime, beta = self.days[key]
        _, cover, tau, kind = _REGIMES[regime]
        clouds = CloudLayer(
            cover=float(self.rng.uniform(*cover)),
            optical_depth=float(self.rng.uniform(*tau)) if tau[1] > 0 else 0.0,
            seed=int(self.rng.integers(0, 2**31)),
        )
        state = SkyState(sun_elevation=el, sun_azimuth=az, turbidity=beta, clouds=clouds)
        return state, kind


def _extinction_per_m(turbidity):
    """Band extinction coefficients (1/m) at ground level: Rayleigh (8 km scale height) + aerosol (1.2 km)."""
    wl = np.asarray(PEAK_NM)
    return rayleigh_optical_depth(wl) / 8000.0 + aerosol_optical_depth(wl, beta=turbidity) / 1200.0


def _sky_samples(rng, n, ranges, sensor, n_average):
    weather = _Weather(rng)
    counts, kinds, times = [], [], []
    for _ in range(n):
        t, el, az = _draw_time(rng, ranges, np.deg2rad(5.0))
        state, cloud_kind = weather.state(t, el, az)
        while True:
            v_el = np.arcsin(rng.uniform(np.sin(np.deg2rad(10)), np.sin(np.deg2rad(88))))
            v = direction_from_angles(rng.uniform(0, 2 * np.pi), v_el)
            if v @ state.sun_direction < np.cos(np.deg2rad(20.0)):
                break
        rad = band_sky_radiance(state, v)
        tau = float(state.clouds.optical_depth_at(v))
        kinds.append(cloud_kind if tau > 0.3 else "blue_sky")
        counts.append(sensor.read(rad, rng=rng, n_readings=n_average)[..., :5].mean(axis=0))
        times.append(t.isoformat())
    return np.array(counts), np.array(kinds), np.array(times)


def _object_samples(rng, n, ranges, mix, distance_m, sensor, n_average, ground_mix):
    weather = _Weather(rng)
    names = list(mix)
    p = np.array([mix[k] for k in names])
    # the ground round each object, drawn from its own stream (the object draws stay as they were)
    ground_rng = np.random.default_rng(rng.bit_generator.seed_seq.spawn(1)[0])
    ground_names = list(ground_mix)
    ground_p = np.array([ground_mix[k] for k in ground_names])
    counts, kinds, times = [], [], []
    for _ in range(n):
        t, el, az = _draw_time(rng, ranges, np.deg2rad(5.0))
        state, _ = weather.state(t, el, az)
        mat = MATERIALS[names[rng.choice(len(names), p=p / p.sum())]]
        rho = mat.sample(rng)[0]
        # viewing direction (sensor -> object), roughly horizontal
        view_el = np.deg2rad(rng.uniform(-35.0, 5.0))  # draws: elevation, then azimuth
        view = direction_from_angles(rng.uniform(0, 2 * np.pi), view_el)
        normal_el = np.deg2rad(rng.uniform(0.0, 90.0))
        normal = direction_from_angles(rng.uniform(0, 2 * np.pi), normal_el)
        if normal @ view > 0:  # make the surface face the sensor
            normal = normal * np.array([-1.0, -1.0, 1.0])
        in_shadow = rng.random() < 0.3
        ill = illumination(state)
        ground = MATERIALS[ground_names[ground_rng.choice(len(ground_names), p=ground_p / ground_p.sum())]]
        ground_albedo = ground.sample(ground_rng)[0]
        # spectral shading: integrate reflectance x irradiance over each channel (not band means multiplied)
        rad = band_integrate(rho * ill.on_surface(normal, sunlit=0.0 if in_shadow else 1.0,
                                                         ground_albedo=ground_albedo)) / np.pi
        gloss = rng.uniform(*mat.gloss) if mat.gloss[1] > 0 else 0.0
        if gloss > 0:
            mirror = view - 2 * (view @ normal) * normal
            if mirror[2] > 0.02:
                rad = rad + gloss * band_sky_radiance(state, mirror)
            else:
                rad = rad + gloss * 0.15 * band_integrate(ill.global_horizontal) / np.pi
        d = rng.uniform(*distance_m)
        trans = np.exp(-_extinction_per_m(state.turbidity) * d)
        horizon = band_sky_radiance(state, direction_from_angles(np.arctan2(-view[1], -view[0]) + np.pi, np.deg2rad(1.0)))
        rad = rad * trans + horizon * (1 - trans)
        counts.append(sensor.read(rad, rng=rng, n_readings=n_average)[..., :5].mean(axis=0))
        kinds.append(mat.name)
        times.append(t.isoformat())
    return np.array(counts), np.array(kinds), np.array(times)


_NATURAL_DATES = [(_dt.date(2006, 5, 9), _dt.date(2006, 6, 20))]
_SKY_DATES = _NATURAL_DATES
_ARTIFICIAL_DATES = [(_dt.date(2007, 1, 14), _dt.date(2007, 5, 10)), (_dt.date(2008, 5, 10), _dt.date(2008, 5, 15))]


def sim_sky(*, seed: int, n_sky: int = 233, sensor: LogSensorModel | None = None, n_average: int = 10) -> SampleSet:
    """Simulated sky readings (blue sky and clouds of every kind), 9 May - 20 June 2006.

    Parameters
    ----------
    seed : int
        The set is a pure function of the seed (sky readings use the child
        stream ``[seed, 0]``, so every sample set of one seed shares them).
    n_sky : int
        Number of sky readings (thesis: 233).
    sensor : LogSensorModel, optional
        Signal chain; default parameters if omitted.
    n_average : int
        Subsequent readings averaged into one data point (thesis: 10).
    """
    sensor = sensor or LogSensorModel()
    rng = np.random.default_rng([seed, 0])
    c, k, t = _sky_samples(rng, n_sky, _SKY_DATES, sensor, n_average)
    return SampleSet(c, np.ones(n_sky, bool), k, t, "sim_sky")


def sim_natural(*, seed: int, n_objects: int = 239, n_sky: int = 233,
                sensor: LogSensorModel | None = None, n_average: int = 10) -> SampleSet:
    """Simulated natural-object and sky readings sized like thesis 6.2.1 (239 + 233).

    Parameters
    ----------
    seed : int
        Objects use the child stream ``[seed, 1]``, sky ``[seed, 0]``.
    n_objects, n_sky : int
        Numbers of readings.
    sensor : LogSensorModel, optional
    n_average : int
        Readings averaged per data point.

    Returns
    -------
    SampleSet
        Objects first, then sky.
    """
    sensor = sensor or LogSensorModel()
    rng = np.random.default_rng([seed, 1])
    c, k, t = _object_samples(rng, n_objects, _NATURAL_DATES, NATURAL_MIX, (5.0, 30.0), sensor, n_average,
                             NATURAL_GROUND_MIX)
    objects = SampleSet(c, np.zeros(n_objects, bool), k, t)
    return objects.concat(sim_sky(seed=seed, n_sky=n_sky, sensor=sensor, n_average=n_average), name="sim_natural")


def sim_artificial(*, seed: int, n_objects: int = 124, n_sky: int = 233,
                   sensor: LogSensorModel | None = None, n_average: int = 10) -> SampleSet:
    """Simulated artificial-object and sky readings sized like thesis 6.3.1 (124 + 233).

    The sky readings are those of :func:`sim_natural` with the same seed.
    Objects use the child stream ``[seed, 2]``.
    """
    sensor = sensor or LogSensorModel()
    rng = np.random.default_rng([seed, 2])
    c, k, t = _object_samples(rng, n_objects, _ARTIFICIAL_DATES, ARTIFICIAL_MIX, (0.5, 2.0), sensor, n_average,
                             ARTIFICIAL_GROUND_MIX)
    objects = SampleSet(c, np.zeros(n_objects, bool), k, t)
    return objects.concat(sim_sky(seed=seed, n_sky=n_sky, sensor=sensor, n_average=n_average), name="sim_artificial")


#: Channel names of :attr:`SampleSet.counts` columns.
COLUMNS = CHANNELS
