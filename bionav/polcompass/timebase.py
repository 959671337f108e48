"""When each recorded sample was taken, and where the sun was then (``recordings.sun``, ``recordings.rotation_period_s``).

The time base of the recordings of Gkanias et al. (2023, doi:10.1038/s44172-023-00132-w)
----------------------------------------------------------------------------------------
The rotation files hold no time stamps: the authors' conversion from ROS bags to JSON keeps each
topic's messages in order and drops their times. What a session gives is

* its start, to the minute, in the folder name ``HH-MM__<Day>_dd-mm-yy`` (local time, CEST on
  these recordings: ``recordings.utc_offset_hours``);
* the order of its rotation files (``1.json``, ``2.json``, ...) and of the samples in each;
* no sample rate. One file is one turn of about 412 samples.

So a sample's time is modelled as ``t = t_session + (r + i / n_r) T``: rotation ``r`` (file order,
from 0) starts ``r T`` after the folder's time and its ``n_r`` samples are spread evenly over
its period ``T`` (``recordings.rotation_period_s``, which includes the robot's turn back between
files). ``T`` is measured from the counts, not from any heading error: the sky's brightness
falls (evening) or rises (morning) through every low-sun session, and its trend within a session
(per rotation) against its trend between sessions half an hour or an hour apart (per minute,
folder times) gives minutes per rotation. On the 15 low-sun sessions of 12-14 May a smooth curve
through all rotations is closest for ``T`` = 1.06-1.30 minutes (cubic or quartic in time; 1.1-1.3
on each day alone), hence the default of 72 s (docs/polcompass.md, "The sun at each sample's
time"). A start offset (the folder's minute against the first sample) turns every heading of a
session alike and is absorbed by the session's offset under every scoring rule; only ``T`` matters.
"""

from __future__ import annotations

import numpy as np


def sample_times(rotation_index, rotation_period_s: float) -> np.ndarray:
    """Seconds since the session's start of every sample, shape ``(N,)``.

    Parameters
    ----------
    rotation_index : array_like of int, shape ``(N,)``
        The rotation (file order, from 0) of each sample, samples of one rotation contiguous and in
        recording order.
    rotation_period_s : float
        Seconds from the start of one rotation to the start of the next (0: every sample at the
        session's start).

    Returns
    -------
    ndarray, shape ``(N,)``
        ``(r + i / n_r) T`` for sample ``i`` of the ``n_r`` samples of rotation ``r``.
    """
    index = np.asarray(rotation_index, int)
    out = np.zeros(index.shape, float)
    for r in np.unique(index):
        sel = np.flatnonzero(index == r)
        out[sel] = (r + np.arange(sel.size) / sel.size) * float(rotation_period_s)
    return out


def session_sun(start_utc, times_s, *, latitude_deg: float, longitude_deg: float, per_sample: bool = True):
    """The sun's azimuth and elevation at every sample, each ``(N,)``, radians (azimuth CCW from east, unwrapped).

    ``per_sample=False``: the sun at the session's start for every sample (one ephemeris per session,
    the published analysis' choice; ``recordings.sun=session``).
    """
    from bionav.light import sun_track

    t = np.asarray(times_s, float)
    if not per_sample:
        t = np.zeros_like(t)
    return sun_track(start_utc, t, latitude_deg=latitude_deg, longitude_deg=longitude_deg)


__all__ = ["sample_times", "session_sun"]
