"""The session pipeline of recorded POL-OP rotations (``experiment=pol_recordings``): the recorded array,
each session's counts prepared once (faults, excluded units, e-vectors, the sun), the heading
reference, the self-calibration left out by day, the mount tilt, decoding, and a session
simulated in bionav's sky model.

The settings are a :class:`~bionav.polcompass.recordings_config.RecordingsConfig` (``rc``,
the ``recordings.*`` node); the simulation's parameters (:func:`simulate_session`) any object
with the ``sim_*`` attributes of ``experiment=pol_recordings``. Conventions: angles in radians,
headings counter-clockwise from the logged yaw's zero, azimuths in the sensor's file frame.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from bionav.errors import UserError
from bionav.geometry import wrap_angle

log = logging.getLogger(__name__)


def circular_offset(decoded, yaw) -> float:
    """``c``: circular mean of ``decoded - yaw`` over finite samples (radians)."""
    d = np.asarray(decoded, float) - np.asarray(yaw, float)
    d = d[np.isfinite(d)]
    return float(np.angle(np.mean(np.exp(1j * d)))) if d.size else 0.0


def session_errors(decoded, yaw, *, runs=None, undecoded_error: float = np.pi / 2.0):
    """Errors ``wrap(decoded - yaw - c)`` with one ``c`` per reference run; undecoded samples get ``undecoded_error``.

    ``runs`` (int, shape ``(N,)``) numbers the runs over which the logged yaw
    keeps one reference (:attr:`SessionData.reference_run`, ``recordings.reference``);
    None: one ``c`` for the whole session. A sample a decoder cannot decode
    (NaN) counts as a 90 degree error, the mean absolute error of a guess;
    ``sessions.csv`` also gives the MAE over decoded samples only
    (``mae_decoded_deg``) and the decoded fraction.

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


def build_array(rc, file_azimuths):
    """The :class:`~bionav.polcompass.array.PolArray` of the recorded sensor."""
    from bionav.polcompass.array import PolArray

    return PolArray.fan(
        np.degrees(rc.azimuth_sign * np.asarray(file_azimuths, float)),
        tilt_deg=rc.tilt_deg,
        photodiode_angles_deg=rc.photodiode_angles_deg,
        pairs=rc.pairs,
    )


def excluded_units(rc, faults, k: int) -> list[int]:
    if rc.exclude_units == "auto":
        return [f.unit for f in faults if f.excluded]
    if rc.exclude_units == "none":
        return []
    bad = [u for u in rc.exclude_units if not 0 <= u < k]
    if bad:
        raise UserError(f"recordings.exclude_units lists unit(s) {bad}, but the recordings have units 0..{k - 1}.")
    return sorted(set(rc.exclude_units))


@dataclass
class SessionData:
    """Everything one session needs for decoding, computed once."""

    session: Any
    array: Any
    counts: np.ndarray  # (N, K, P)
    yaw: np.ndarray
    rotation_index: np.ndarray
    valid: np.ndarray
    evectors: Any
    faults: list
    excluded: list
    sun: Any
    period: str
    pol_op_valid: np.ndarray | None = None  # (N, K, J): both photodiodes of the POL-OP usable, unit not dropped
    reference_run: np.ndarray | None = None  # (N,): runs of one yaw reference (recordings.reference); None: the session
    yaw_shift: np.ndarray | None = None  # (N,): radians added to the logged yaw (recordings.reference=stitched)


def session_evectors(counts, array, pol_op_valid, excluded):
    """E-vectors of a session's counts with every unusable POL-OP masked (:func:`~bionav.polcompass.array.masked_pol_ops`)."""
    from bionav.polcompass.array import evectors_from_counts, masked_pol_ops

    with np.errstate(invalid="ignore", divide="ignore"):
        ev = evectors_from_counts(counts, array)
    return ev if pol_op_valid is None else masked_pol_ops(ev, pol_op_valid, faulty_units=excluded)


def prepare_session(session, rc) -> SessionData:
    """Counts, validity, e-vectors and the sun position of one session."""
    from bionav.light import sun_position
    from bionav.polcompass.recordings import detect_faults, pol_op_validity, sample_validity

    rots = session.rotations
    counts = np.concatenate([r.counts for r in rots])
    yaw = np.concatenate([r.yaw for r in rots])
    index = np.concatenate([np.full(r.yaw.size, i) for i, r in enumerate(rots)])
    array = build_array(rc, rots[0].file_azimuths)
    faults = detect_faults(counts, saturation_counts=rc.saturation_counts, dark_counts=rc.dark_counts,
                           imbalance_decades=rc.imbalance_decades, blind_fraction=rc.blind_fraction,
                           pairs=array.pairs)
    excluded = excluded_units(rc, faults, counts.shape[1])
    valid = sample_validity(counts, saturation_counts=rc.saturation_counts, dark_counts=rc.dark_counts,
                            imbalance_decades=rc.imbalance_decades)
    valid[:, excluded] = False
    pol_ok = pol_op_validity(counts, array.pairs, saturation_counts=rc.saturation_counts, dark_counts=rc.dark_counts)
    pol_ok[:, excluded] = False
    ev = session_evectors(counts, array, pol_ok, excluded)
    valid &= np.isfinite(ev.angle)
    when = session.time_utc(rc.utc_offset_hours)
    if when is None:
        raise UserError(
            f"The session folder {session.name} does not say when it was recorded; name it HH-MM__<Day>_dd-mm-yy "
            "(local time, e.g. 13-00__Thursday_12-05-22) so the sun position can be computed."
        )
    sun = sun_position(when, latitude_deg=rc.latitude_deg, longitude_deg=rc.longitude_deg)
    if session.condition == "canopy":
        period = "canopy"
    else:
        period = "tod_daylight" if np.degrees(sun.elevation) >= rc.dusk_elevation_deg else "tod_dusk"
    data = SessionData(session, array, counts, yaw, index, valid, ev, faults, excluded, sun, period, pol_ok)
    return with_reference(data, rc.reference)


def yaw_runs(data: SessionData) -> np.ndarray:
    """Per sample, the run of the logged yaw between its restarts (int, ``(N,)``, from 0;
    :func:`bionav.polcompass.recordings.yaw_restarts`)."""
    from bionav.polcompass.recordings import yaw_restarts

    index = np.asarray(data.rotation_index, int)
    logged = data.yaw if data.yaw_shift is None else data.yaw - data.yaw_shift
    starts = [logged[index == r] for r in range(int(index.max()) + 1 if index.size else 0)]
    return (np.cumsum(yaw_restarts(starts)) - 1)[index]


def with_reference(data: SessionData, reference: str) -> SessionData:
    """The session scored under ``recordings.reference``.

    ``session``: as logged, one offset. ``yaw_run``: one offset per run between the yaw's restarts
    (:attr:`SessionData.reference_run`). ``stitched``: each run turned by its shift against the first
    run, found from the counts alone (:func:`bionav.polcompass.array_calibration.yaw_run_shifts`), then
    one offset (:attr:`SessionData.yaw` is the stitched yaw, :attr:`SessionData.yaw_shift` what was
    added). ``rotation``: one offset per rotation file.
    """
    if reference == "session":
        return data
    if reference == "rotation":
        return replace(data, reference_run=np.asarray(data.rotation_index, int))
    runs = yaw_runs(data)
    if reference == "yaw_run":
        return replace(data, reference_run=runs)
    from bionav.polcompass.array_calibration import yaw_run_shifts

    shifts = yaw_run_shifts(data.counts, data.yaw, data.valid, runs)
    readable = np.array([data.valid[runs == r].any() for r in range(shifts.size)])
    lost = np.flatnonzero(~np.isfinite(shifts) & readable)  # a run with nothing readable decodes nothing anyway
    if lost.size:
        log.warning("%s: yaw run(s) %s are not stitched (shift 0): no readable counts in common with the first run, or "
                    "turned more than 20 degrees against it", data.session.name, lost.tolist())
    shift = np.nan_to_num(shifts)[runs]
    return replace(data, yaw=data.yaw + shift, yaw_shift=shift)


def calibration_sessions(datas, rc) -> list:
    """Sessions the self-calibration learns from: time-of-day sessions with the sun at least ``dusk_elevation_deg`` high.

    Clear skies only: the gauge of the common polarizer offset is the sky's mirror symmetry about the
    solar meridian, which canopy breaks.
    """
    return [d for d in datas if d.period == "tod_daylight"]


def self_calibrate(datas, rc, *, progress=None):
    """Per-session self-calibrations (:func:`bionav.polcompass.array_calibration.calibrate_session`).

    Returns
    -------
    dict
        Session name -> ``(day, SessionCalibration)``; sessions where it fails are left out (logged).
    """
    from bionav.polcompass.array_calibration import calibrate_session

    out = {}
    chosen = calibration_sessions(datas, rc)
    for d in (progress(chosen, desc="self-calibration", total=len(chosen)) if progress else chosen):
        try:
            out[d.session.name] = (d.session.day, calibrate_session(d.counts, d.yaw, d.valid, d.array))
        except UserError as exc:
            log.warning("self-calibration skips %s: %s", d.session.name, exc)
    return out


def leave_one_day_out(estimates, day):
    """The calibration of all other days' sessions (all sessions when ``day`` is the only one), and a label."""
    from bionav.polcompass.array_calibration import combine_sessions

    others = {n: e for n, (dd, e) in estimates.items() if dd != day}
    if others:
        return combine_sessions(list(others.values()), sorted(others)), "auto (other days)"
    if estimates:
        log.warning("only one day of daylight sessions: day %s is decoded with its own self-calibration", day)
        return combine_sessions([e for _d, e in estimates.values()], sorted(estimates)), "auto (same day)"
    return None, "none (no daylight session to calibrate from)"


def calibrated(data: SessionData, calibration, parts, solver: str = "pol_op") -> SessionData:
    """The session decoded through a calibrated array (same counts and validity; ``solver``: see
    :meth:`~bionav.polcompass.array_calibration.ArrayCalibration.apply`)."""
    if calibration is None:
        return data
    array = calibration.apply(data.array, gains="gains" in parts, angles="angles" in parts, azimuths=False,
                              solver=solver)
    ev = session_evectors(data.counts, array, data.pol_op_valid, data.excluded)
    valid = data.valid & np.isfinite(ev.angle)
    return replace(data, array=array, valid=valid, evectors=ev)


def decode_session(decoder, data: SessionData, mount_tilt=None):
    """Decode every sample of a session; returns ``(heading, resolved, seconds)``.

    ``mount_tilt`` (radians, ``(2,)``, :attr:`~bionav.polcompass.array_calibration.ArrayCalibration.mount_tilt`):
    its heading deviation ``tan(h) (a cos phi + b sin phi)`` is removed (:mod:`bionav.polcompass.deviation`).
    """
    from bionav.polcompass.decoders import heading_from_sun
    from bionav.polcompass.deviation import corrected_heading

    t0 = time.perf_counter()
    est = decoder.decode(data.evectors, data.valid, array=data.array, sun_elevation=float(data.sun.elevation))
    heading = heading_from_sun(est.azimuth, data.sun.azimuth)
    if mount_tilt is not None:
        heading = corrected_heading(heading, est.azimuth, mount_tilt, scale=float(np.tan(data.sun.elevation)))
    return heading, np.asarray(est.resolved, bool), time.perf_counter() - t0


def mount_tilt(datas, rc, calibration, decoder, *, leave_out_day=None):
    """The sensor's first-order mount tilt (radians, ``(2,)``, or None) from the daylight rotations of the other days.

    Each session (:func:`calibration_sessions`, not of ``leave_out_day``) is decoded through ``calibration``
    with ``decoder``; its errors against the logged yaw are fitted with ``tan(h) (a cos phi + b sin phi)``
    (:func:`bionav.polcompass.deviation.deviation_from_errors`, tilt form), and the sessions are pooled by
    the median. Only the logged yaw is used, no heading truth.
    """
    from bionav.polcompass.deviation import deviation_from_errors, pooled_deviation

    fits = []
    for d in calibration_sessions(datas, rc):
        if d.session.day == leave_out_day:
            continue
        dc = calibrated(d, calibration, rc.calibration_parts, rc.calibration_solver)
        heading, _resolved, _seconds = decode_session(decoder, dc)
        err, _c = session_errors(heading, dc.yaw, runs=dc.reference_run)
        fits.append(deviation_from_errors(wrap_angle(dc.sun.azimuth - heading), err, n_harmonics=1,
                                          scale=float(np.tan(dc.sun.elevation))))
    return pooled_deviation(fits)


def view_field(rng, heading, unit_azimuths, n_photodiodes: int, *, n_harmonics: int = 12, shared: float = 0.0):
    """A random smooth field of unit variance per photodiode over the world azimuth it looks at, shape ``(N, K, P)``.

    ``g_kp(theta) = sum_{h=1..H} a_kph cos(h theta) + b_kph sin(h theta)`` with ``a, b ~ N(0, 1/H)``, evaluated
    at ``theta = heading + unit_azimuth_k`` (radians). The simulation multiplies counts by
    ``exp(sim_view_sigma g)``: what makes the real units depart from one shared sky ring (about 11 % rms on
    the recordings, ``SessionCalibration.residual_rms``) -- e.g. each unit's own field of view, reflections,
    the horizon -- which gains, polarizer offsets and pointing do not (docs/polcompass.md).

    ``shared`` (0..1) is the fraction of the variance that a unit's photodiodes share: ``g_kp = sqrt(shared)
    u_k + sqrt(1 - shared) g'_kp`` with ``u_k`` one such field per unit. What a unit's photodiodes see alike
    (its aperture, a reflection) cancels in a POL-OP's log ratio; what differs between them (each polarizer's
    own angular acceptance) turns the e-vector. ``shared = 0`` draws exactly the per-photodiode field above.
    """
    if not 0.0 <= shared <= 1.0:
        raise ValueError(f"shared must be in [0, 1], got {shared}")
    k = np.size(unit_azimuths)
    theta = np.asarray(heading, float)[:, None] + np.asarray(unit_azimuths, float)[None, :]  # (N, K)
    h = np.arange(1, n_harmonics + 1)
    ang = theta[:, :, None] * h  # (N, K, H)

    def field(n: int):
        a, b = rng.standard_normal((2, k, n, n_harmonics)) / np.sqrt(n_harmonics)
        return np.einsum("nkh,kph->nkp", np.cos(ang), a) + np.einsum("nkh,kph->nkp", np.sin(ang), b)

    own = field(n_photodiodes)
    if shared == 0.0:
        return own
    return np.sqrt(shared) * field(1) + np.sqrt(1.0 - shared) * own


def simulate_session(data: SessionData, exp, rng) -> SessionData:
    """The same sensor, samples and exclusions under bionav's sky model at the session's time and place.

    Photodiode counts from :func:`bionav.polcompass.array.stokes_from_sky`
    (point optics) scaled to the session's median count, through a device
    drawn with a log-normal photodiode gain spread ``sim_gain_sigma`` (a share ``sim_gain_shared`` of its
    variance common to a unit's photodiodes) and
    polarizer angle offsets ``sim_angle_sigma_deg`` (the decoder assumes the
    nominal device), with proportional noise and the same saturation; canopy
    sessions get a cloud field of ``sim_canopy_cover``.
    """
    from bionav.light import SkyModel, random_cloud_map
    from bionav.polcompass.array import counts_from_stokes, stokes_from_sky
    from bionav.polcompass.recordings import photodiode_validity, pol_op_validity

    clouds = random_cloud_map(rng, cover=exp.sim_canopy_cover) if data.period == "canopy" and exp.sim_canopy_cover > 0 else None
    model = SkyModel(data.sun, max_degree=exp.sim_max_degree, clouds=clouds)
    mount = float(rng.uniform(-np.pi, np.pi))
    offsets = np.deg2rad(exp.sim_angle_sigma_deg) * rng.standard_normal(data.array.polarizer_angles.shape)
    k = data.array.unit_tilts.shape
    device = replace(data.array, polarizer_angles=data.array.polarizer_angles + offsets,
                     unit_tilts=data.array.unit_tilts + np.deg2rad(exp.sim_tilt_sigma_deg) * rng.standard_normal(k),
                     unit_azimuths=data.array.unit_azimuths + np.deg2rad(exp.sim_azimuth_sigma_deg) * rng.standard_normal(k))
    intensity, q, u = stokes_from_sky(model, device, mount + data.yaw)
    counts = counts_from_stokes(intensity, q, u, device)
    lit = data.counts[data.counts > 0]
    scale = (np.median(lit) if lit.size else 1000.0) / max(float(np.median(counts)), 1e-12)
    k, n_pd = counts.shape[1:]
    common = rng.standard_normal((k, 1)) if exp.sim_gain_shared > 0 else 0.0
    z = np.sqrt(exp.sim_gain_shared) * common + np.sqrt(1.0 - exp.sim_gain_shared) * rng.standard_normal((k, n_pd))
    gains = np.exp(exp.sim_gain_sigma * z)
    counts = counts * scale * gains
    if exp.sim_view_sigma > 0:  # each photodiode's own smooth departure from the shared sky ring (world frame)
        counts = counts * np.exp(exp.sim_view_sigma * view_field(rng, mount + data.yaw, data.array.unit_azimuths,
                                                                   counts.shape[-1], shared=exp.sim_view_shared))
    counts = counts * (1.0 + exp.sim_noise * rng.standard_normal(counts.shape))
    counts = np.clip(np.round(counts), 0, None)
    saturation = float(np.max(data.counts)) if data.counts.size else np.inf
    valid = np.all(photodiode_validity(counts, saturation_counts=saturation, dark_counts=1.0), axis=-1)  # counts are whole
    valid[:, data.excluded] = False
    pol_ok = pol_op_validity(counts, data.array.pairs, saturation_counts=saturation, dark_counts=1.0)
    pol_ok[:, data.excluded] = False
    ev = session_evectors(counts, data.array, pol_ok, data.excluded)
    valid &= np.isfinite(ev.angle)
    return replace(data, counts=counts, valid=valid, evectors=ev, pol_op_valid=pol_ok)


def prepared_sessions(rc, progress=None) -> tuple[list, list]:
    """Every session of ``recordings.path`` prepared for decoding, and ``(path, message)`` of the unusable ones.

    ``progress(iterable, desc=..., total=...)`` (e.g. ``ctx.progress``) shows the preparation of the sessions.
    """
    from bionav.polcompass.recordings import load_sessions

    log.info("reading the POL-OP recordings in %s ...", rc.path)
    sessions, bad_files = load_sessions(rc.path)
    for _path, message in bad_files:
        log.warning("%s", message)
    if not sessions:
        raise UserError(" ".join(m for _p, m in bad_files) or f"No usable recordings in {rc.path}.")
    prepared = []
    for session in (progress or (lambda it, **_: it))(sessions, desc="preparing sessions", total=len(sessions)):
        try:
            prepared.append(prepare_session(session, rc))
        except UserError as exc:  # e.g. a folder name without the recording time: skip that session, keep the rest
            bad_files.append((Path(session.name), str(exc)))
            log.warning("%s", exc)
    return prepared, bad_files


__all__ = [
    "SessionData",
    "build_array",
    "calibrated",
    "calibration_sessions",
    "circular_offset",
    "decode_session",
    "excluded_units",
    "leave_one_day_out",
    "mount_tilt",
    "prepare_session",
    "prepared_sessions",
    "self_calibrate",
    "session_errors",
    "session_evectors",
    "simulate_session",
    "view_field",
    "with_reference",
    "yaw_runs",
]
