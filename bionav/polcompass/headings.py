"""Headings from e-vector measurements by comparing them with a sky model.

The zenith e-vector only fixes a heading modulo ``pi`` (the candidate pair of
eq. 4.6). The thesis chooses between the candidates with an *error function*
that compares the computed with the expected result. Here the expected result
is the sensor response predicted by the sky model (:mod:`bionav.light`) through
the compass optics (:mod:`bionav.polcompass.optics`) for a candidate heading,
with the sun position known from time and place. Looking at the zenith both
candidates predict the same response, so the pair stays unresolved there;
tilted views and scans over several sky points break the symmetry.

Headings are radians CCW from east; a *sensor heading* is mount heading plus
pan (see :mod:`bionav.polcompass.optics`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from bionav.geometry import wrap_angle, wrap_axial
from bionav.polcompass.compass import choose_candidate, zenith_heading
from bionav.polcompass.optics import CompassOptics


@dataclass
class EvectorPredictor:
    """Expected e-vector angle, degree and unit signals for any compass pose.

    Parameters
    ----------
    source : SkyModel or PolarizerLamp
        The model sky (normally clear, without clouds: what the compass
        expects to see).
    optics : CompassOptics
        Compass optics (nominal or calibrated polarizer angles).
    n_grid : int
        Sensor-heading grid size for the tabulated predictions.
    """

    source: object
    optics: CompassOptics = field(default_factory=CompassOptics)
    n_grid: int = 720
    _tables: dict = field(default_factory=dict, repr=False)

    def at(self, sensor_heading, tilt):
        """Predicted ``(angle, degree)`` at poses (broadcast), by direct integration.

        ``degree`` includes the polarizer efficiency, like a measured degree.
        """
        _, q, u = self.optics.stokes(self.source, sensor_heading, tilt)
        return wrap_axial(0.5 * np.arctan2(u, q)), self.optics.polarizer_efficiency * np.hypot(q, u)

    def unit_signals(self, sensor_heading, tilt, unit_angles):
        """Predicted delogarithmised unit outputs, shape ``S + (K,)``."""
        _, q, u = self.optics.stokes(self.source, sensor_heading, tilt)
        return self.optics.unit_signals(q, u, unit_angles=unit_angles)

    def table(self, tilt: float):
        """Predictions on the sensor-heading grid ``2 pi j / n_grid`` for one tilt (cached).

        Returns
        -------
        headings : ndarray, shape ``(n_grid,)``
        c2, s2 : ndarray, shape ``(n_grid,)``
            ``d cos 2a`` and ``d sin 2a`` (smooth, safe to interpolate).
        """
        key = round(float(tilt), 12)
        if key not in self._tables:
            h = 2.0 * np.pi * np.arange(self.n_grid) / self.n_grid
            angle, degree = self.at(h, float(tilt))
            self._tables[key] = (h, degree * np.cos(2 * angle), degree * np.sin(2 * angle))
        return self._tables[key]

    def interpolate(self, sensor_heading, tilt: float):
        """Tabulated ``(angle, degree)`` at arbitrary sensor headings for one tilt (periodic linear)."""
        h, c2, s2 = self.table(tilt)
        x = np.mod(np.asarray(sensor_heading, float), 2.0 * np.pi)
        hp = np.append(h, 2.0 * np.pi)
        c = np.interp(x, hp, np.append(c2, c2[0]))
        s = np.interp(x, hp, np.append(s2, s2[0]))
        return wrap_axial(0.5 * np.arctan2(s, c)), np.hypot(c, s)


def _roots_for_angle(predictor: EvectorPredictor, angle: float, tilt: float, *, n_polish: int = 6):
    """Sensor headings where the predicted e-vector angle equals ``angle`` (mod pi)."""
    h, c2, s2 = predictor.table(tilt)
    pred = 0.5 * np.arctan2(s2, c2)
    r = wrap_axial(pred - angle)
    r_next = np.roll(r, -1)
    h_next = np.append(h[1:], 2.0 * np.pi)
    crossing = (np.sign(r) != np.sign(r_next)) & (np.abs(r - r_next) < np.pi / 2.0)
    roots = []
    for j in np.flatnonzero(crossing):
        # Secant iterations on the exact model, starting from the bracketing grid points.
        xa, fa, xb, fb = h[j], r[j], h_next[j], r_next[j]
        x = xa - fa * (xb - xa) / (fb - fa)
        for _ in range(n_polish):
            fx = float(wrap_axial(predictor.at(x, tilt)[0] - angle))
            if abs(fx) < 1e-14:
                break
            xa, fa, xb, fb = xb, fb, x, fx
            if fb == fa:
                break
            x = xb - fb * (xb - xa) / (fb - fa)
        roots.append(float(wrap_angle(x)))
    return roots


@dataclass(frozen=True)
class PoseSolution:
    """Heading of one reading, chosen from its candidates by the error function.

    Attributes
    ----------
    heading : float
        Chosen sensor heading, radians CCW from east.
    alternative : float
        Best candidate about a half turn away (the eq. 4.6 partner).
    error, alternative_error : float
        Error function values (sum of squared unit-signal differences).
    resolved : bool
        Whether the error function tells the two apart by more than the margin.
    """

    heading: float
    alternative: float
    error: float
    alternative_error: float
    resolved: bool


def solve_pose(
    x,
    angle: float,
    tilt: float,
    *,
    predictor: EvectorPredictor,
    unit_angles,
    margin: float,
) -> PoseSolution:
    """Sensor heading of one reading at a known tilt.

    Finds every sensor heading whose predicted e-vector angle equals the
    measured one, scores each candidate by the error function ``E = sum_i
    (x_i - x^_i)^2`` (measured minus predicted delogarithmised unit outputs)
    and keeps the best; its partner is the best candidate more than a quarter
    turn away.

    Parameters
    ----------
    x : ndarray, shape ``(K,)``
        Measured delogarithmised unit outputs.
    angle : float
        Measured e-vector angle (sensor frame), radians.
    tilt : float
        Tilt of the compass, radians.
    predictor : EvectorPredictor
    unit_angles : array_like, shape ``(K,)``
    margin : float
        Minimum error difference for a resolved choice.

    Returns
    -------
    PoseSolution
    """
    roots = _roots_for_angle(predictor, angle, tilt)
    if not roots:
        return PoseSolution(np.nan, np.nan, np.nan, np.nan, False)
    roots = np.asarray(roots)
    predicted = predictor.unit_signals(roots, tilt, unit_angles)
    errors = np.sum((predicted - np.asarray(x)[None, :]) ** 2, axis=-1)
    best = int(np.argmin(errors))
    far = np.abs(wrap_angle(roots - roots[best])) > np.pi / 2.0
    if not np.any(far):
        return PoseSolution(float(roots[best]), np.nan, float(errors[best]), np.nan, True)
    alt = int(np.flatnonzero(far)[np.argmin(errors[far])])
    # The candidate pair (best root, its partner about a half turn away), chosen by the error function.
    chosen, resolved = choose_candidate(roots[best], roots[alt], errors[best], errors[alt], margin=margin)
    return PoseSolution(float(chosen), float(roots[alt]), float(errors[best]), float(errors[alt]), bool(resolved))


@dataclass(frozen=True)
class ScanFit:
    """Mount heading fitted to the e-vectors of a scan.

    Attributes
    ----------
    heading : float
        Best mount heading, radians CCW from east.
    alternative : float
        Best heading in the opposite half turn.
    error, alternative_error : float
        Weighted error function at both (normalised by the total weight).
    resolved : bool
    n_used : int
        Readings that entered the fit (degree at or above ``min_degree``).
    """

    heading: float
    alternative: float
    error: float
    alternative_error: float
    resolved: bool
    n_used: int


def fit_scan_heading(
    angles,
    degrees,
    pans,
    tilts,
    *,
    predictor: EvectorPredictor,
    min_degree: float = 0.05,
    margin: float = 1e-3,
) -> ScanFit:
    """Fit the mount heading to e-vector angles measured at many pan/tilt poses.

    Error function ``E(H) = sum_k w_k (1 - cos 2(a_k - a^(H + pan_k, tilt_k)))
    / sum_k w_k`` with weights ``w_k`` = measured degree (cloud-covered
    points, whose degree is low, count little; those below ``min_degree`` are
    dropped). Grid search on the tabulated predictions, then a bounded
    refinement on the exact model.

    Parameters
    ----------
    angles, degrees : ndarray, shape ``(N,)``
        Measured e-vector angles (sensor frame) and degrees.
    pans, tilts : ndarray, shape ``(N,)``
        Poses of the readings, radians.
    predictor : EvectorPredictor
    min_degree : float, optional
    margin : float, optional
        Minimum difference of the normalised errors for a resolved result.

    Returns
    -------
    ScanFit
    """
    from scipy.optimize import minimize_scalar

    angles = np.asarray(angles, float)
    degrees = np.asarray(degrees, float)
    pans = np.asarray(pans, float)
    tilts = np.asarray(tilts, float)
    use = np.isfinite(angles) & (degrees >= min_degree)
    if not np.any(use):
        return ScanFit(np.nan, np.nan, np.nan, np.nan, False, 0)
    a, w, p, t = angles[use], degrees[use], pans[use], tilts[use]
    grid = 2.0 * np.pi * np.arange(predictor.n_grid) / predictor.n_grid
    energy = np.zeros_like(grid)
    for tilt in np.unique(t):
        sel = t == tilt
        pred, _ = predictor.interpolate(grid[:, None] + p[sel][None, :], float(tilt))
        energy += np.sum(w[sel] * (1.0 - np.cos(2.0 * (a[sel] - pred))), axis=1)
    energy /= np.sum(w)

    def exact(h):
        pred, _ = predictor.at(h + p, t)
        return float(np.sum(w * (1.0 - np.cos(2.0 * (a - pred)))) / np.sum(w))

    def refine(j):
        step = grid[1] - grid[0]
        res = minimize_scalar(exact, bounds=(grid[j] - step, grid[j] + step), method="bounded", options={"xatol": 1e-10})
        return float(wrap_angle(res.x)), float(res.fun)

    best_j = int(np.argmin(energy))
    far = np.abs(wrap_angle(grid - grid[best_j])) > np.pi / 2.0
    alt_j = int(np.flatnonzero(far)[np.argmin(energy[far])])
    h_best, e_best = refine(best_j)
    h_alt, e_alt = refine(alt_j)
    if e_alt < e_best:
        h_best, e_best, h_alt, e_alt = h_alt, e_alt, h_best, e_best
    return ScanFit(h_best, h_alt, e_best, e_alt, bool(e_alt - e_best > margin), int(use.sum()))


def pose_headings(angle, x, tilts, *, sun, predictor, unit_angles, margin):
    """Sensor heading of every reading; tilted readings resolved by the error function (thesis 4.2.3).

    Parameters
    ----------
    angle : ndarray, shape ``(N,)``
        E-vector angles in the sensor frame (radians).
    x : ndarray, shape ``(N, K)``
        Delogarithmised unit outputs.
    tilts : ndarray, shape ``(N,)``
        Sensor tilt of every reading (radians; 0 at the zenith).
    sun : SunPosition
    predictor : EvectorPredictor
    unit_angles : ndarray, shape ``(K,)``
    margin : float
        See :func:`solve_pose`.

    Returns
    -------
    heading : ndarray, shape ``(N,)``
        Radians CCW from east (for zenith readings: the candidate in
        ``[-pi, pi)`` of eq. 4.6's pair).
    resolved : ndarray of bool, shape ``(N,)``
    """
    heading = np.asarray(zenith_heading(angle, sun_azimuth=sun.azimuth), float)
    resolved = np.zeros(heading.shape, dtype=bool)
    for i in np.flatnonzero(np.abs(tilts) > 1e-12):
        sol = solve_pose(x[i], float(angle[i]), float(tilts[i]), predictor=predictor, unit_angles=unit_angles, margin=margin)
        heading[i], resolved[i] = sol.heading, sol.resolved
    return heading, resolved
