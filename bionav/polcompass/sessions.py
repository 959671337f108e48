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
    """Everything one session needs for decoding and scoring, computed once.

    ``yaw`` is the logged yaw as it is; ``yaw + yaw_shift`` the stitched yaw
    (:func:`bionav.polcompass.references.stitch_shifts`). ``sun`` is the sun at the session's start (its
    condition, ``sessions.csv``); ``sun_azimuth`` / ``sun_elevation`` the sun at every sample
    (``recordings.sun``; :mod:`bionav.polcompass.timebase`), which decoding and the sky rings use.
    ``reference`` names ``recordings.reference``, the rule of the default-named errors.
    """

    session: Any
    array: Any
    counts: np.ndarray  # (N, K, P)
    yaw: np.ndarray  # (N,): the logged yaw, radians CCW
    rotation_index: np.ndarray
    valid: np.ndarray
    evectors: Any
    faults: list
    excluded: list
    sun: Any
    period: str
    pol_op_valid: np.ndarray | None = None  # (N, K, J): both photodiodes of the POL-OP usable, unit not dropped
    yaw_shift: np.ndarray | None = None  # (N,): radians added to the logged yaw to stitch its runs; None: zeros
    times: np.ndarray | None = None  # (N,): seconds since the session's start
    sun_azimuth: np.ndarray | None = None  # (N,): radians CCW from east, unwrapped; None: ``sun`` throughout
    sun_elevation: np.ndarray | None = None  # (N,): radians
    reference: str = "session"

    def __post_init__(self) -> None:
        n = np.shape(self.yaw)
        if self.yaw_shift is None:
            self.yaw_shift = np.zeros(n)
        if self.sun_azimuth is None:
            self.sun_azimuth = np.full(n, float(self.sun.azimuth))
        if self.sun_elevation is None:
            self.sun_elevation = np.full(n, float(self.sun.elevation))

    @property
    def stitched_yaw(self) -> np.ndarray:
        """The logged yaw with its runs turned into the first run's reference, radians, ``(N,)``."""
        return self.yaw + self.yaw_shift

    @property
    def sky_yaw(self) -> np.ndarray:
        """The stitched yaw against the sky of the first sample (:func:`~bionav.polcompass.references.sky_frame_yaw`):
        the yaw the self-calibration bins its rings by."""
        from bionav.polcompass.references import sky_frame_yaw

        return sky_frame_yaw(self.stitched_yaw, self.sun_azimuth)


def session_evectors(counts, array, pol_op_valid, excluded):
    """E-vectors of a session's counts with every unusable POL-OP masked (:func:`~bionav.polcompass.array.masked_pol_ops`)."""
    from bionav.polcompass.array import evectors_from_counts, masked_pol_ops

    with np.errstate(invalid="ignore", divide="ignore"):
        ev = evectors_from_counts(counts, array)
    return ev if pol_op_valid is None else masked_pol_ops(ev, pol_op_valid, faulty_units=excluded)


def prepare_session(session, rc) -> SessionData:
    """Counts, validity, e-vectors, the sun at every sample and the stitched yaw of one session."""
    from bionav.light import sun_position
    from bionav.polcompass.recordings import detect_faults, pol_op_validity, sample_validity
    from bionav.polcompass.references import stitch_shifts
    from bionav.polcompass.timebase import sample_times, session_sun

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
    times = sample_times(index, rc.rotation_period_s)
    azimuth, elevation = session_sun(when, times, latitude_deg=rc.latitude_deg, longitude_deg=rc.longitude_deg,
                                     per_sample=rc.sun == "sample")
    shift, _runs, lost = stitch_shifts(counts, yaw, valid, index, azimuth)
    if lost:
        log.warning("%s: yaw run(s) %s are not stitched (shift 0): no readable counts in common with the first run, or "
                    "turned more than 20 degrees against it", session.name, lost)
    return SessionData(session, array, counts, yaw, index, valid, ev, faults, excluded, sun,
                       session_period(session.condition, sun.elevation, rc.dusk_elevation_deg), pol_ok, shift, times,
                       azimuth, elevation, rc.reference)


def session_period(condition: str, sun_elevation: float, dusk_elevation_deg: float) -> str:
    """The group a session is reported in: ``canopy``, ``tod_daylight`` / ``tod_dusk`` (time-of-day sessions with
    the sun at least / below ``dusk_elevation_deg`` at the start) or ``unknown`` (a session whose condition the
    path does not tell, :func:`bionav.polcompass.recordings.path_condition`)."""
    if condition in ("canopy", "unknown"):
        return condition
    return "tod_daylight" if np.degrees(sun_elevation) >= dusk_elevation_deg else "tod_dusk"


def calibration_sessions(datas, rc) -> list:
    """Sessions the self-calibration learns from: time-of-day sessions with the sun at least ``dusk_elevation_deg`` high.

    Clear skies only: the gauge of the common polarizer offset is the sky's mirror symmetry about the
    solar meridian, which canopy breaks; a session whose condition the path does not tell (``unknown``)
    never calibrates.
    """
    return [d for d in datas if d.period == "tod_daylight" and d.session.condition == "tod"]


def self_calibrate(datas, rc, *, progress=None):
    """Per-session self-calibrations (:func:`bionav.polcompass.array_calibration.calibrate_session`).

    Each session's counts are binned by the yaw it has repaired itself, whatever reference the run scores
    against: the stitched yaw against the sky of its first sample (:attr:`SessionData.sky_yaw`), so neither
    an odometry restart nor the sun's motion turns one part of the session's ring against another.

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
            out[d.session.name] = (d.session.day, calibrate_session(d.counts, d.sky_yaw, d.valid, d.array))
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

    The heading is the sun's azimuth at each sample's time minus the decoded solar azimuth in the sensor
    frame (:func:`~bionav.polcompass.decoders.heading_from_sun`); a decoder that needs the sun's elevation
    gets each rotation's own (its mean over the rotation: it changes by at most about 0.2 degrees in one).
    ``mount_tilt`` (radians, ``(2,)``, :attr:`~bionav.polcompass.array_calibration.ArrayCalibration.mount_tilt`):
    its heading deviation ``tan(h) (a cos phi + b sin phi)`` is removed (:mod:`bionav.polcompass.deviation`).
    """
    from bionav.polcompass.decoders import heading_from_sun
    from bionav.polcompass.deviation import corrected_heading

    t0 = time.perf_counter()
    elevation = np.asarray(data.sun_elevation, float)
    if getattr(decoder, "needs_sun_elevation", False) and elevation.size and np.ptp(elevation) > 0:
        azimuth = np.full(elevation.shape, np.nan)
        resolved = np.zeros(elevation.shape, bool)
        for r in np.unique(data.rotation_index):
            sel = np.flatnonzero(data.rotation_index == r)
            est = decoder.decode(data.evectors.rows(sel), data.valid[sel], array=data.array,
                                 sun_elevation=float(np.mean(elevation[sel])))
            azimuth[sel], resolved[sel] = est.azimuth, est.resolved
    else:
        est = decoder.decode(data.evectors, data.valid, array=data.array,
                             sun_elevation=float(np.mean(elevation)) if elevation.size else float(data.sun.elevation))
        azimuth, resolved = est.azimuth, est.resolved
    heading = heading_from_sun(azimuth, data.sun_azimuth)
    if mount_tilt is not None:
        heading = corrected_heading(heading, azimuth, mount_tilt, scale=np.tan(elevation))
    return heading, np.asarray(resolved, bool), time.perf_counter() - t0


def mount_tilt(datas, rc, calibration, decoder, *, leave_out_day=None, days=None, parts=None):
    """The sensor's first-order mount tilt (radians, ``(2,)``, or None) from the daylight rotations of the other days.

    Each session (:func:`calibration_sessions`, not of ``leave_out_day``; only of ``days`` if given) is decoded
    through ``calibration`` (its ``parts``, default ``recordings.calibration_parts``) with ``decoder``; its errors
    against the stitched yaw (one offset per session: the yaw the calibration repaired itself, whatever
    ``recordings.reference`` scores against) are fitted with
    ``tan(h) (a cos phi + b sin phi)`` (:func:`bionav.polcompass.deviation.deviation_from_errors`, tilt form,
    ``h`` each sample's sun elevation), and the sessions are pooled by the median. No heading truth is used.
    """
    from bionav.polcompass.deviation import deviation_from_errors, pooled_deviation
    from bionav.polcompass.references import session_errors

    fits = []
    for d in calibration_sessions(datas, rc):
        if d.session.day == leave_out_day or (days is not None and d.session.day not in days):
            continue
        dc = calibrated(d, calibration, rc.calibration_parts if parts is None else parts, rc.calibration_solver)
        heading, _resolved, _seconds = decode_session(decoder, dc)
        err, _c = session_errors(heading, dc.stitched_yaw)
        fits.append(deviation_from_errors(wrap_angle(dc.sun_azimuth - heading), err, n_harmonics=1,
                                          scale=np.tan(dc.sun_elevation)))
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
    sessions get a cloud field of ``sim_canopy_cover``. The robot turns as the stitched yaw says (no
    restarts: the simulated session's logged and stitched yaw are one) under the sun of each rotation
    (:attr:`SessionData.sun_azimuth`, ``sun_elevation``: it moves as the real one did).
    """
    from bionav.light import SkyModel, SunPosition, random_cloud_map
    from bionav.polcompass.array import counts_from_stokes, stokes_from_sky
    from bionav.polcompass.recordings import photodiode_validity, pol_op_validity

    clouds = random_cloud_map(rng, cover=exp.sim_canopy_cover) if data.period == "canopy" and exp.sim_canopy_cover > 0 else None
    mount = float(rng.uniform(-np.pi, np.pi))
    offsets = np.deg2rad(exp.sim_angle_sigma_deg) * rng.standard_normal(data.array.polarizer_angles.shape)
    k = data.array.unit_tilts.shape
    device = replace(data.array, polarizer_angles=data.array.polarizer_angles + offsets,
                     unit_tilts=data.array.unit_tilts + np.deg2rad(exp.sim_tilt_sigma_deg) * rng.standard_normal(k),
                     unit_azimuths=data.array.unit_azimuths + np.deg2rad(exp.sim_azimuth_sigma_deg) * rng.standard_normal(k))
    heading = mount + data.stitched_yaw
    stokes = np.zeros((3,) + data.valid.shape)
    for r in np.unique(data.rotation_index):  # the sky of each rotation
        sel = data.rotation_index == r
        sun = SunPosition(float(np.mean(data.sun_azimuth[sel])), float(np.mean(data.sun_elevation[sel])))
        stokes[:, sel] = stokes_from_sky(SkyModel(sun, max_degree=exp.sim_max_degree, clouds=clouds), device, heading[sel])
    counts = counts_from_stokes(*stokes, device)
    lit = data.counts[data.counts > 0]
    scale = (np.median(lit) if lit.size else 1000.0) / max(float(np.median(counts)), 1e-12)
    k, n_pd = counts.shape[1:]
    common = rng.standard_normal((k, 1)) if exp.sim_gain_shared > 0 else 0.0
    z = np.sqrt(exp.sim_gain_shared) * common + np.sqrt(1.0 - exp.sim_gain_shared) * rng.standard_normal((k, n_pd))
    gains = np.exp(exp.sim_gain_sigma * z)
    counts = counts * scale * gains
    if exp.sim_view_sigma > 0:  # each photodiode's own smooth departure from the shared sky ring (world frame)
        counts = counts * np.exp(exp.sim_view_sigma * view_field(rng, heading, data.array.unit_azimuths,
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
    return replace(data, counts=counts, valid=valid, evectors=ev, pol_op_valid=pol_ok, yaw=data.stitched_yaw,
                   yaw_shift=np.zeros(data.yaw.shape))


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
    "decode_session",
    "excluded_units",
    "leave_one_day_out",
    "mount_tilt",
    "prepare_session",
    "prepared_sessions",
    "session_period",
    "self_calibrate",
    "session_evectors",
    "simulate_session",
    "view_field",
]
