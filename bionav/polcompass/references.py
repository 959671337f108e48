"""The heading references a recorded session is scored against (``recordings.reference``), and the scoring rules.

The robot's logged yaw (Gkanias et al. 2023, doi:10.1038/s44172-023-00132-w) is an integrated IMU
angle with an arbitrary zero that restarts between some rotation files
(:func:`bionav.polcompass.recordings.yaw_restarts`). Every error is ``wrap(heading - yaw - c)`` with
``c`` fitted (circular mean) per session or per run:

``session`` -- the *published rule* (logged yaw, one offset per session)
    The authors align the logged yaw once per session (a sky photograph) and score against it;
    bionav fits that one constant per session and decoder. Named ``logged`` in the outputs.
``stitched`` -- the logged yaw repaired at its restarts, one offset per session
    Each run of the yaw between restarts is turned into the first run's reference by the shift
    that makes its ring of counts match the first run's (:func:`stitch_shifts`, no decoder, no
    heading truth), with the sun's own motion between the runs removed first (its ephemeris at each
    sample's time, :mod:`bionav.polcompass.timebase`): otherwise the repair also turns the yaw with
    the sun and hides the error of decoding against a fixed sun. Named ``stitched`` in the outputs.
``yaw_run`` / ``rotation``
    One offset per run of the logged yaw, or per rotation file (diagnostics: a lower bound).

Conventions: radians; headings and yaw counter-clockwise (the logged yaw's sense).
"""

from __future__ import annotations

import numpy as np

from bionav.geometry import wrap_angle

#: the two rules every run reports, named in ``metrics.json``, ``sessions.csv`` and ``summary.md``:
#: ``logged`` is the published one (``recordings.reference=session``), ``stitched`` the repaired yaw
RULES = {"logged": "session", "stitched": "stitched"}


def circular_offset(decoded, yaw) -> float:
    """``c``: circular mean of ``decoded - yaw`` over finite samples (radians)."""
    d = np.asarray(decoded, float) - np.asarray(yaw, float)
    d = d[np.isfinite(d)]
    return float(np.angle(np.mean(np.exp(1j * d)))) if d.size else 0.0


def session_errors(decoded, yaw, *, runs=None, undecoded_error: float = np.pi / 2.0):
    """Errors ``wrap(decoded - yaw - c)`` with one ``c`` per reference run; undecoded samples get ``undecoded_error``.

    ``runs`` (int, shape ``(N,)``) numbers the runs over which the yaw keeps one reference
    (``recordings.reference=yaw_run|rotation``); None: one ``c`` for the whole session. A sample a
    decoder cannot decode (NaN) counts as a 90 degree error, the mean absolute error of a guess;
    ``sessions.csv`` also gives the MAE over decoded samples only (``mae_decoded_deg``) and the
    decoded fraction.

    Returns
    -------
    errors : ndarray, radians in ``[-pi, pi)``
    c : float
        The offset of the first run (radians).
    """
    decoded = np.asarray(decoded, float)
    yaw = np.asarray(yaw, float)
    runs = np.zeros(decoded.shape, int) if runs is None else np.asarray(runs)
    offsets = np.zeros(decoded.shape)
    first = None
    for r in np.unique(runs):
        sel = runs == r
        offsets[sel] = circular_offset(decoded[sel], yaw[sel])
        first = offsets[sel][0] if first is None else first
    err = wrap_angle(decoded - yaw - offsets)
    return np.where(np.isfinite(err), err, undecoded_error), float(first or 0.0)


def yaw_runs(yaw, rotation_index) -> np.ndarray:
    """Per sample, the run of the logged ``yaw`` between its restarts (int, ``(N,)``, from 0;
    :func:`bionav.polcompass.recordings.yaw_restarts`)."""
    from bionav.polcompass.recordings import yaw_restarts

    index = np.asarray(rotation_index, int)
    yaw = np.asarray(yaw, float)
    starts = [yaw[index == r] for r in range(int(index.max()) + 1 if index.size else 0)]
    return (np.cumsum(yaw_restarts(starts)) - 1)[index]


def sky_frame_yaw(yaw, sun_azimuth) -> np.ndarray:
    """The yaw against the sky as it stood at the first sample: ``yaw - (S(t) - S(t_0))``, shape ``(N,)``.

    Under a sky that turns with the sun (azimuth ``S(t)``, radians CCW, unwrapped) a unit reads the
    same sky point wherever ``yaw + A_k - S(t)`` is the same, so rings of counts binned by this yaw
    are one ring over a whole session (:func:`stitch_shifts`, the self-calibration's rings).
    """
    s = np.asarray(sun_azimuth, float)
    return np.asarray(yaw, float) - (s - s[0] if s.size else 0.0)


def stitch_shifts(counts, yaw, valid, rotation_index, sun_azimuth):
    """The stitched reference: per sample the shift (radians) that turns its yaw run into the first run's.

    Runs from :func:`yaw_runs`; each run's shift from the counts alone
    (:func:`bionav.polcompass.array_calibration.yaw_run_shifts`, 1 degree bins or as many as the shortest run
    has samples) on the yaw against the sky
    (:func:`sky_frame_yaw`). A run that cannot be matched (nothing readable in common with the first,
    or turned further than the search) keeps shift 0.

    Returns
    -------
    shift : ndarray, shape ``(N,)``
        ``yaw + shift`` is the stitched yaw.
    runs : ndarray of int, shape ``(N,)``
    lost : list of int
        Runs with readable counts that could not be stitched.
    """
    from bionav.polcompass.array_calibration import yaw_run_shifts

    valid = np.asarray(valid, bool)
    runs = yaw_runs(yaw, rotation_index)
    # rings no finer than the shortest run fills (1 degree for the recorded ~412 samples per turn): a ring with gaps
    # between its bins matches the first run's only at the whole-bin shifts that happen to interleave
    n_bins = int(max(36, min([360, *np.bincount(runs)[np.unique(runs)].tolist()])))
    shifts = yaw_run_shifts(counts, sky_frame_yaw(yaw, sun_azimuth), valid, runs, n_bins=n_bins)
    readable = np.array([valid[runs == r].any() for r in range(shifts.size)])
    lost = np.flatnonzero(~np.isfinite(shifts) & readable).tolist()  # nothing readable: nothing decoded either
    return np.nan_to_num(shifts)[runs], runs, lost


def reference_errors(heading, data, reference: str):
    """Errors of ``heading`` (radians, ``(N,)``) against session ``data`` under ``reference``, and ``c``.

    ``data`` is a :class:`~bionav.polcompass.sessions.SessionData` (its logged ``yaw``, ``yaw_shift``
    and ``rotation_index``); ``reference`` one of ``session``, ``stitched``, ``yaw_run``, ``rotation``
    (module docstring).
    """
    if reference == "session":
        return session_errors(heading, data.yaw)
    if reference == "stitched":
        return session_errors(heading, data.yaw + data.yaw_shift)
    if reference == "yaw_run":
        return session_errors(heading, data.yaw, runs=yaw_runs(data.yaw, data.rotation_index))
    if reference == "rotation":
        return session_errors(heading, data.yaw, runs=data.rotation_index)
    raise ValueError(f"unknown reference {reference!r}")


__all__ = [
    "RULES",
    "circular_offset",
    "reference_errors",
    "session_errors",
    "sky_frame_yaw",
    "stitch_shifts",
    "yaw_runs",
]
