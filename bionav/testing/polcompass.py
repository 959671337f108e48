"""Recorded POL-OP sessions with a known answer: rotation files written under bionav's model sky.

:func:`write_model_session` writes what the recorded sensor (Gkanias et al. 2023,
doi:10.1038/s44172-023-00132-w; :mod:`bionav.polcompass.recordings`) would have written while turning
under the single-scattering sky at a known mount angle, with the sun where the ephemeris puts it at each
sample's time (:mod:`bionav.polcompass.timebase`) and, if asked, odometry restarts that turn the logged
yaw's zero by known angles. A decoder plugin, a scoring rule or a calibration can then be checked against
the known heading through ``python -m bionav experiment=pol_recordings recordings.path=...``.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

#: the recorded fan's unit azimuths as the files store them (radians, clockwise from the front)
FILE_AZIMUTHS = np.deg2rad([0.0, 90.0, 180.0, 270.0, 45.0, 135.0, 225.0, 315.0])


def model_counts(local_time, times_s, headings, *, utc_offset_hours: float = 2.0, latitude_deg: float = 39.2,
                 longitude_deg: float = 9.1, max_degree: float = 0.5, scale: float = 3000.0, array=None):
    """Photodiode counts of the fan-8 (``PolArray.fan8``) under the model sky, shape ``(N, 8, 4)``.

    Parameters
    ----------
    local_time : datetime
        The session's start, naive local time (``utc_offset_hours`` ahead of UTC).
    times_s : ndarray, shape ``(N,)``
        Seconds after the start of each sample; the sun is taken at each one's own time.
    headings : ndarray, shape ``(N,)``
        The sensor's heading, radians CCW from east.
    """
    import datetime as dt

    from bionav.light import SkyModel, SunPosition, sun_track
    from bionav.polcompass.array import PolArray, counts_from_stokes, stokes_from_sky

    arr = PolArray.fan8() if array is None else array
    start = local_time.replace(tzinfo=dt.timezone(dt.timedelta(hours=utc_offset_hours)))
    azimuth, elevation = sun_track(start, times_s, latitude_deg=latitude_deg, longitude_deg=longitude_deg)
    headings = np.asarray(headings, float)
    stokes = np.zeros((3, headings.size, arr.n_units))
    for i in range(headings.size):
        sky = SkyModel(SunPosition(float(azimuth[i]), float(elevation[i])), max_degree=max_degree)
        stokes[:, i] = np.asarray(stokes_from_sky(sky, arr, headings[i:i + 1]))[:, 0]
    return counts_from_stokes(scale * stokes[0], stokes[1], stokes[2], arr)


def write_model_session(folder, *, rotations: int = 2, samples: int = 90, mount_deg: float = 30.0,
                        restarts=None, rotation_period_s: float = 72.0, blind_unit: int | None = 7,
                        noise: float = 0.0, seed: int = 0, **sky) -> Path:
    """Write ``rotations`` rotation files ``1.json`` ... into ``folder`` (named ``HH-MM__<Day>_dd-mm-yy``).

    Each rotation turns once from its start yaw; the logged yaw of a rotation starts 0.5 degrees off zero
    (the robot back at its yaw zero: same reference) or, for a rotation ``r`` in ``restarts`` (a mapping
    ``r -> degrees``), at rest at exactly zero with the robot turned by that many degrees further against
    the logged zero (an odometry restart, :func:`bionav.polcompass.recordings.yaw_restarts`). The sensor's
    true heading is ``mount_deg + (turns so far) + logged yaw``; samples are timed as
    :func:`bionav.polcompass.timebase.sample_times` with ``rotation_period_s``. ``blind_unit``: a unit whose
    orthogonal photodiodes read alike (as unit 7 of the recorded sensor; None: none). ``noise``: relative count
    noise (drawn with ``seed``); counts are rounded. ``sky``: keywords of :func:`model_counts`.

    Returns
    -------
    Path
        ``folder``.
    """
    from bionav.polcompass.recordings import parse_session_time
    from bionav.polcompass.timebase import sample_times

    folder = Path(folder)
    local_time = parse_session_time(folder.name)
    if local_time is None:
        raise ValueError(f"{folder.name} is not a session folder name HH-MM__<Day>_dd-mm-yy")
    restarts = dict(restarts or {})
    index = np.repeat(np.arange(rotations), samples)
    times = sample_times(index, rotation_period_s)
    rest = 6
    yaw, turned = [], []
    for r in range(rotations):
        start = 0.0 if r in restarts else np.deg2rad(0.5)
        turn = start + np.linspace(0.0, 2.0 * np.pi, samples - rest, endpoint=False)
        yaw.append(np.concatenate([np.full(rest, start), turn]))
        turned.append(np.full(samples, np.deg2rad(sum(v for k, v in restarts.items() if k <= r))))
    yaw, turned = np.concatenate(yaw), np.concatenate(turned)
    counts = model_counts(local_time, times, np.deg2rad(mount_deg) + turned + yaw, **sky)
    if noise > 0:
        counts = counts * (1.0 + noise * np.random.default_rng(seed).standard_normal(counts.shape))
    counts = np.clip(np.round(counts), 0.0, None)
    if blind_unit is not None:
        counts[:, blind_unit, 1], counts[:, blind_unit, 3] = counts[:, blind_unit, 0], counts[:, blind_unit, 2]
    folder.mkdir(parents=True, exist_ok=True)
    for r in range(rotations):
        sel = index == r
        data = {f"pol_op_{k}": counts[sel, k, :].tolist() for k in range(counts.shape[1])}
        data["azimuths"] = FILE_AZIMUTHS.tolist()
        data["yaw"] = yaw[sel].tolist()
        (folder / f"{r + 1}.json").write_text(json.dumps(data))
    return folder


__all__ = ["FILE_AZIMUTHS", "model_counts", "write_model_session"]
