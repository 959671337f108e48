"""From POL-OP unit voltages to the e-vector angle and a heading.

Thesis chapter 4 after Lambrinos et al. (2000), Robotics and Autonomous
Systems 30:39-64, doi:10.1016/S0921-8890(99)00064-0.

Conventions
-----------
The compass measures the *e-vector angle* ``a`` of the skylight in its own
sensor plane (see :mod:`bionav.polcompass.optics`): radians from the sensor's
``x_s`` axis towards ``y_s``, axial, returned in ``[-pi/2, pi/2)``. Unit ``i``
with polarizer angle ``alpha_i`` outputs ``p_i = log10((1 + d cos(2a -
2alpha_i)) / (1 - d cos(2a - 2alpha_i)))`` (eq. 4.2, in decades) and the
sigmoid of eq. 4.3 turns it into ``x_i = 1 - 2 / (1 + 10^p_i) = d cos(2a -
2alpha_i)``. For a compass looking at the zenith, whose e-vector is
perpendicular to the solar meridian (world e-vector azimuth ``chi_w =
sun_azimuth + pi/2``), the sensor heading is ``h = chi_w - a`` modulo ``pi``:
the pair ``(h, h + pi)`` of eq. 4.6.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.geometry import wrap_angle, wrap_axial


def volts_to_decades(volts, *, center_v=2.5, volts_per_decade=0.5):
    """Invert the log-ratio amplifier: ``p = (V - V_c) / G`` in decades.

    Parameters
    ----------
    volts : ndarray, shape ``(..., K)``
    center_v, volts_per_decade : float or ndarray, shape ``(K,)``
        Nominal or calibrated (per unit) centre and gain.
    """
    return (np.asarray(volts, float) - center_v) / volts_per_decade


def delogarithmise(p):
    """Sigmoid delogarithmisation of eq. 4.3.

    Parameters
    ----------
    p : ndarray
        Unit outputs in decades, ``p = log10((1 + x) / (1 - x))``.

    Returns
    -------
    ndarray
        ``x = 1 - 2 p~`` with ``p~ = 1 / (1 + 10^p)``, i.e. ``d cos(2a - 2alpha)``.
    """
    p_tilde = 1.0 / (1.0 + np.power(10.0, np.asarray(p, float)))
    return 1.0 - 2.0 * p_tilde


def two_unit_evector(x_i, x_j, alpha_i: float, alpha_j: float):
    """E-vector angle and degree from two POL-OP units (eqs. 4.4-4.5).

    Eq. 4.4 gives ``tan 2a = (f cos 2alpha_j - cos 2alpha_i) / (sin 2alpha_i - f
    sin 2alpha_j)`` with ``f = x_i / x_j``. Its principal value (eq. 4.5,
    ``arctan``) only fixes ``a`` modulo ``pi/2``; the quadrant follows from
    ``d > 0``. Solving the two equations ``x = d cos(2a - 2alpha)`` for
    ``(d cos 2a, d sin 2a)`` and taking ``atan2`` does both at once and avoids
    the division by ``x_j`` (the same ratio as eq. 4.4, multiplied through).

    Parameters
    ----------
    x_i, x_j : ndarray
        Delogarithmised outputs (eq. 4.3) of units ``i`` and ``j``.
    alpha_i, alpha_j : float
        Polarizer angles of the units, radians (must differ modulo ``pi/2``).

    Returns
    -------
    angle : ndarray
        E-vector angle in the sensor frame, ``[-pi/2, pi/2)``.
    degree : ndarray
        ``d`` (times the polarizer efficiency), ``>= 0``.
    """
    det = np.sin(2.0 * alpha_j - 2.0 * alpha_i)
    if abs(det) < 1e-9:
        raise ValueError("two POL-OP units with parallel (or perpendicular) polarizers cannot give an angle")
    x_i = np.asarray(x_i, float)
    x_j = np.asarray(x_j, float)
    c = (x_i * np.sin(2.0 * alpha_j) - x_j * np.sin(2.0 * alpha_i)) / det
    s = (x_j * np.cos(2.0 * alpha_i) - x_i * np.cos(2.0 * alpha_j)) / det
    return wrap_axial(0.5 * np.arctan2(s, c)), np.hypot(c, s)


def least_squares_evector(x, unit_angles):
    """E-vector angle and degree from ``J >= 2`` POL-OP outputs by linear least squares: bionav's one e-vector solver.

    Fits ``x_j = c cos 2alpha_j + s sin 2alpha_j`` with ``c = d cos 2a``,
    ``s = d sin 2a``. For three units at 0/60/120 degrees this is
    ``(c, s) = 2/3 sum_j x_j (cos 2alpha_j, sin 2alpha_j)``; two POL-OPs give
    eqs. 4.4-4.5 exactly (the quadrant from ``d > 0``). Used by the thesis
    compass (:func:`evector_from_compass_counts`, one e-vector from its units)
    and by every unit of a sensor array
    (:func:`bionav.polcompass.array.evectors_from_counts`, one per unit).

    Parameters
    ----------
    x : ndarray, shape ``(..., J)``
        Delogarithmised POL-OP outputs (eq. 4.3).
    unit_angles : array_like, shape ``(J,)`` or ``(..., J)``
        First polarizer angle of each POL-OP, radians; leading axes broadcast
        against those of ``x`` (e.g. ``(K, J)`` for ``K`` units of ``J`` POL-OPs each).

    Returns
    -------
    angle : ndarray, shape ``(...)``
        ``[-pi/2, pi/2)``, in the frame of the polarizer angles.
    degree : ndarray, shape ``(...)``
    """
    alpha = np.asarray(unit_angles, float)
    design = np.stack([np.cos(2.0 * alpha), np.sin(2.0 * alpha)], axis=-1)  # (..., J, 2)
    pinv = np.linalg.pinv(design)  # (..., 2, J)
    cs = np.einsum("...ij,...j->...i", pinv, np.asarray(x, float))
    return wrap_axial(0.5 * np.arctan2(cs[..., 1], cs[..., 0])), np.hypot(cs[..., 0], cs[..., 1])


def candidate_pair(angle):
    """The two candidate orientations of eq. 4.6.

    Parameters
    ----------
    angle : ndarray
        An orientation from eq. 4.5 in ``[-pi/2, pi/2]`` (or any angle).

    Returns
    -------
    first, second : ndarray
        ``(angle, angle - pi)`` where ``angle >= 0``, ``(angle, angle + pi)``
        otherwise: both in ``[-pi, pi]``, a half turn apart.
    """
    angle = np.asarray(angle, float)
    return angle, np.where(angle >= 0.0, angle - np.pi, angle + np.pi)


def zenith_heading(evector_angle, *, sun_azimuth: float = np.pi / 2.0):
    """Sensor heading from the zenith e-vector (one of the two candidates).

    Parameters
    ----------
    evector_angle : ndarray
        E-vector angle ``a`` in the sensor frame (radians).
    sun_azimuth : float, optional
        Sun azimuth, radians CCW from east. The default ``pi/2`` makes the
        world e-vector azimuth 0, i.e. returns ``-a``: a heading relative to an
        unknown constant, enough when only heading *changes* matter.

    Returns
    -------
    ndarray
        Heading ``sun_azimuth + pi/2 - a`` wrapped to ``[-pi, pi)``; the other
        candidate is this plus ``pi``.
    """
    return wrap_angle(sun_azimuth + np.pi / 2.0 - np.asarray(evector_angle))


def choose_candidate(first, second, error_first, error_second, *, margin: float = 0.0):
    """Pick the candidate with the lower error (thesis 4, after eq. 4.6).

    Parameters
    ----------
    first, second : ndarray
        Candidate orientations.
    error_first, error_second : ndarray
        Error function values (computed vs expected result) of each.
    margin : float, optional
        The choice counts as *resolved* only where the errors differ by more
        than this.

    Returns
    -------
    chosen : ndarray
    resolved : ndarray of bool
        False where the geometry cannot tell the candidates apart (e.g. a
        compass looking straight at the zenith).
    """
    error_first = np.asarray(error_first, float)
    error_second = np.asarray(error_second, float)
    chosen = np.where(error_second < error_first, second, first)
    return chosen, np.abs(error_first - error_second) > margin


@dataclass(frozen=True)
class HeadingErrors:
    """Heading errors after removing a constant offset.

    Attributes
    ----------
    errors : ndarray
        Per-sample errors, radians (``[-pi/2, pi/2)`` when axial).
    offset : float
        The removed constant offset (circular mean), radians.
    axial : bool
        Whether errors were taken modulo ``pi``.
    """

    errors: np.ndarray
    offset: float
    axial: bool

    @property
    def rmse_deg(self) -> float:
        """Root-mean-square error in degrees."""
        return float(np.degrees(np.sqrt(np.mean(self.errors**2))))

    @property
    def mae_deg(self) -> float:
        """Mean absolute error in degrees."""
        return float(np.degrees(np.mean(np.abs(self.errors))))


def heading_errors(estimated, reference, *, axial: bool, remove_offset: bool = True) -> HeadingErrors:
    """Errors of estimated headings against reference headings.

    Parameters
    ----------
    estimated, reference : ndarray, shape ``(N,)``
        Radians, same rotation sense.
    axial : bool
        Compare modulo ``pi`` (the compass' unresolved ambiguity).
    remove_offset : bool, optional
        Subtract the circular mean of the differences (the constant mounting
        offset the thesis removes); axial means use doubled angles.

    Returns
    -------
    HeadingErrors
    """
    diff = np.asarray(estimated, float) - np.asarray(reference, float)
    k = 2.0 if axial else 1.0
    offset = float(np.angle(np.mean(np.exp(1j * k * diff))) / k) if remove_offset and diff.size else 0.0
    errors = wrap_axial(diff - offset) if axial else wrap_angle(diff - offset)
    return HeadingErrors(np.asarray(errors, float), offset, axial)


def evector_from_compass_counts(counts, calibration, *, solver: str = "least_squares"):
    """E-vector angle, degree and delogarithmised unit outputs from ADC counts (thesis 4.1).

    Parameters
    ----------
    counts : ndarray, shape ``(N, K)``
        10-bit counts (``V = count * 5 / 1023``).
    calibration : UnitCalibration
    solver : {'least_squares', 'two_unit'}
        Three-unit least squares, or eqs. 4.4-4.5 on the first two units
        (another value: ``ValueError``).

    Returns
    -------
    angle : ndarray, shape ``(N,)``
        E-vector angle in the sensor frame, radians ``[-pi/2, pi/2)``.
    degree : ndarray, shape ``(N,)``
    x : ndarray, shape ``(N, K)``
    """
    from bionav.polcompass.electronics import counts_to_volts

    volts = counts_to_volts(counts)
    x = delogarithmise(volts_to_decades(volts, center_v=calibration.center_v, volts_per_decade=calibration.volts_per_decade))
    if solver == "least_squares":
        angle, degree = least_squares_evector(x, calibration.unit_angles)
    elif solver == "two_unit":
        angle, degree = two_unit_evector(x[:, 0], x[:, 1], calibration.unit_angles[0], calibration.unit_angles[1])
    else:  # a Python caller's argument (experiment.solver is checked against its declared choices on the way in)
        raise ValueError(f"solver must be 'least_squares' or 'two_unit', got {solver!r}")
    return angle, degree, x
