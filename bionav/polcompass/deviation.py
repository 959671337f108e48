"""Heading deviation curves of a POL-OP compass ("compass swinging"), learned from rotations.

A compass swung through a full turn shows its deviation: the heading error as a function of the
heading. For a sky compass the systematic error of the device (gains, polarizer and pointing
tolerances the calibration leaves, each unit's view) depends on where the sun stands in the
*device frame*, ``phi`` (the solar azimuth in the sensor frame, radians CCW from the sensor front,
what a decoder returns as :attr:`bionav.polcompass.decoders.SunEstimate.azimuth`). The deviation
curve is a low-order Fourier series

    D(phi) = sum_{h=1..H} a_h cos(h phi) + b_h sin(h phi)     (radians)

or its *tilt form* ``D(phi) = tan(h) sum_h (...)`` with ``h`` the sun's elevation: a compass whose
up-axis is tilted by a small angle ``beta`` (a mount not level) reads the sun's azimuth wrong by
``beta tan(h) sin(phi - phi_beta)`` to first order (the trunnion error of a theodolite), so one harmonic
of the tilt form is a mount tilt of ``hypot(a_1, b_1)``. Either is
fitted to the errors ``wrap(heading - yaw - c)`` of rotation sessions (the logged yaw only, ``c``
one constant per session, so no constant term: it is indistinguishable from ``c``), and removed
from a heading as ``heading - D(phi)``. Per-session fits are pooled by their median (a session
with another sky does not move it). Measured on the recordings (leave one day out, docs/polcompass.md):
learned on clear-sky days, the plain curve lowers the held-out daylight MAE a little and raises canopy
and dusk; the tilt form lowers daylight by half a degree without array calibration and by 0.1 on top of
the polarizer offsets, without changing canopy or dusk there: it is the ``tilt`` part of
``experiment=pol_recordings``'s calibration (:func:`bionav.polcompass.sessions.mount_tilt`), the plain
form is not used. ``python -m bionav.bench.decoders.deviation`` repeats the study.
"""

from __future__ import annotations

import numpy as np

from bionav.geometry import wrap_angle


def fourier_basis(phi, n_harmonics: int):
    """``[cos phi, sin phi, cos 2 phi, sin 2 phi, ...]`` up to ``n_harmonics``, shape ``(N, 2 H)`` (``phi`` radians)."""
    phi = np.asarray(phi, float)
    h = np.arange(1, int(n_harmonics) + 1)
    ang = phi[:, None] * h[None, :]
    return np.stack([np.cos(ang), np.sin(ang)], axis=-1).reshape(phi.size, -1)


def deviation_from_errors(sun_sensor_azimuth, errors, *, n_harmonics: int = 2, scale: float = 1.0,
                          max_error: float = np.deg2rad(30.0), min_samples: int = 20):
    """Fourier coefficients of one rotation session's heading errors against the solar azimuth in the device frame.

    Parameters
    ----------
    sun_sensor_azimuth : ndarray, shape ``(N,)``
        ``phi`` per sample, radians (NaN: not decoded).
    errors : ndarray, shape ``(N,)``
        ``wrap(heading - yaw - c)``, radians.
    n_harmonics : int
        ``H``.
    scale : float
        The curve is ``scale`` times the series: 1 (plain form) or ``tan(h)`` of the session's sun
        elevation ``h`` (tilt form; the coefficients are then radians of tilt).
    max_error : float
        Samples with ``|error|`` above it (a wrong member of the eq. 4.6 pair, a glitch) are left out, radians.
    min_samples : int
        Fewest usable samples; fewer gives None.

    Returns
    -------
    ndarray, shape ``(2 H,)``, or None
        ``[a_1, b_1, a_2, b_2, ...]``, radians.
    """
    phi = np.asarray(sun_sensor_azimuth, float)
    e = np.asarray(errors, float)
    ok = np.isfinite(phi) & np.isfinite(e) & (np.abs(e) <= max_error)
    if ok.sum() < max(int(min_samples), 2 * int(n_harmonics)):
        return None
    coef, *_ = np.linalg.lstsq(float(scale) * fourier_basis(phi[ok], n_harmonics), e[ok], rcond=None)
    return coef


def pooled_deviation(per_session):
    """Median of per-session coefficients (None entries skipped), shape ``(2 H,)``; None if there are none."""
    got = [c for c in per_session if c is not None]
    return np.median(np.stack(got), axis=0) if got else None


def corrected_heading(heading, sun_sensor_azimuth, coefficients, *, scale: float = 1.0):
    """``wrap(heading - scale D(phi))`` (radians; NaN headings stay NaN; ``coefficients`` None: unchanged;
    ``scale``: see :func:`deviation_from_errors`)."""
    heading = np.asarray(heading, float)
    if coefficients is None:
        return heading
    coefficients = np.asarray(coefficients, float)
    phi = np.nan_to_num(np.asarray(sun_sensor_azimuth, float))
    d = float(scale) * (fourier_basis(phi, coefficients.size // 2) @ coefficients)
    return np.where(np.isfinite(heading), wrap_angle(heading - d), np.nan)
