"""Solar azimuth from the e-vectors of a POL-OP array, one sample at a time.

Every decoder takes what the units of an array (:mod:`bionav.polcompass.array`)
read at one moment, :class:`~bionav.polcompass.array.UnitEvectors` and a
``valid`` mask (units dropped as faulty or saturated at that sample), and
returns a :class:`SunEstimate`: the solar azimuth in the *sensor frame*
(radians, counter-clockwise from the sensor front, ``[-pi, pi)``), the other
member of the eq. 4.6 candidate pair, and whether the pair was resolved. No
decoder looks at other samples. A heading follows as ``sun_world_azimuth -
sun_sensor_azimuth`` (:func:`heading_from_sun`).

Decoders
--------
``sky_fit`` (bionav's default)
    Least squares over all units against the sky model's e-vector pattern
    for tilted units: the solar azimuth ``phi`` minimising
    ``E(phi) = sum_k w_k (1 - cos 2(a_k - a^_k(phi)))`` with the sun elevation
    known from time and place, ``w_k = d_k^2`` (measured degree); a grid,
    then a parabolic refinement. The candidate pair is the best ``phi`` and
    the best one within 45 degrees of its antipode (eq. 4.6 generalised to tilted
    units); the lower error wins, and where the errors differ by less than
    the margin the brighter side of the sky (first harmonic of the units'
    intensities) decides. Samples where a unit reads only one of its POL-OPs
    (a saturated pair, a photodiode read fault), or where fewer than
    ``min_units`` units read both, are decoded from every usable POL-OP
    instead (:func:`sun_from_pol_op_fit`), so partly saturated units vote.
``two_unit``, ``eigenvector``, ``mean_vector``, ``sol``, ``four_zeros``
    The thesis' two-unit solution and the published per-sample decoders
    ``sky_fit`` is compared with: :mod:`bionav.polcompass.published_decoders`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.geometry import parabolic_peak_offset, wrap_angle
from bionav.polcompass.array import PolArray, UnitEvectors, stokes_from_sky


@dataclass(frozen=True)
class SunEstimate:
    """Solar azimuth of every sample in the sensor frame.

    Attributes
    ----------
    azimuth : ndarray, shape ``(N,)``
        Radians CCW from the sensor front, ``[-pi, pi)``; NaN where the units
        read at that sample cannot give one.
    alternative : ndarray, shape ``(N,)``
        The other member of the candidate pair (about a half turn away).
    resolved : ndarray of bool, shape ``(N,)``
        Whether the choice between the two was clear (margin exceeded).
    """

    azimuth: np.ndarray
    alternative: np.ndarray
    resolved: np.ndarray

    @property
    def valid(self) -> np.ndarray:
        """Per sample: the units gave an azimuth (enough light above the noise floor, enough units), shape ``(N,)``."""
        return np.isfinite(self.azimuth)


def heading_from_sun(sun_sensor_azimuth, sun_world_azimuth):
    """Sensor heading (radians CCW from east) from the solar azimuth in the sensor frame."""
    return wrap_angle(np.asarray(sun_world_azimuth, float) - np.asarray(sun_sensor_azimuth, float))


def _weights(ev: UnitEvectors, valid, power: float):
    ok = np.asarray(valid, bool) & np.isfinite(ev.angle) & np.isfinite(ev.degree)
    return np.where(ok, np.nan_to_num(ev.degree) ** power, 0.0)


def angle_noise(ev: UnitEvectors, noise_counts: float, *, min_degree: float = 0.05):
    """Standard deviation of each unit's e-vector angle caused by count noise, radians, shape ``(N, K)``.

    A POL-OP reads ``x = (s_a - s_b) / (s_a + s_b)`` (eq. 4.3 after delogarithmising); a count noise of
    ``sigma_c`` counts per photodiode gives ``sigma_x = sqrt(2) sigma_c / S`` with ``S = s_a + s_b`` (to
    first order), and ``J`` POL-OPs at evenly spread orientations give the angle to
    ``sigma_a = sigma_x / (2 d sqrt(J / 2))`` (``d``: the unit's measured degree, at least ``min_degree``).
    ``S`` is twice the unit's mean photodiode reading (:attr:`UnitEvectors.intensity`, counts). In daylight
    ``sigma_a`` is far below a degree; in twilight, with a few counts per photodiode, it reaches tens of
    degrees: the noise floor.

    Parameters
    ----------
    ev : UnitEvectors
    noise_counts : float
        ``sigma_c``: dark noise and quantisation of one photodiode count (counts).
    min_degree : float
        Lower bound of the degree used (a noisy degree near 0 would make every angle worthless).

    Returns
    -------
    ndarray, shape ``(N, K)``
        Radians; ``inf`` where the unit reads no light.
    """
    s = 2.0 * np.nan_to_num(np.asarray(ev.intensity, float))
    j = ev.x.shape[-1] if np.ndim(ev.x) == 3 else 1
    d = np.maximum(np.nan_to_num(np.asarray(ev.degree, float)), float(min_degree))
    with np.errstate(divide="ignore"):
        sigma_x = np.where(s > 0, np.sqrt(2.0) * float(noise_counts) / np.where(s > 0, s, 1.0), np.inf)
    return sigma_x / (2.0 * d * np.sqrt(max(j, 1) / 2.0))


def brightness_azimuth(ev: UnitEvectors, valid, array: PolArray):
    """Azimuth of the first harmonic of the units' intensities (towards the bright sky), shape ``(N,)``.

    Intensities are normalised by their mean over the valid units of each sample.
    """
    ok = np.asarray(valid, bool) & np.isfinite(ev.intensity)
    i = np.where(ok, np.nan_to_num(ev.intensity), 0.0)
    n = np.maximum(ok.sum(axis=-1), 1)
    mean = i.sum(axis=-1) / n
    rel = np.where(ok, i / np.maximum(mean, 1e-12)[:, None] - 1.0, 0.0)
    z = np.sum(rel * np.sin(array.unit_tilts) * np.exp(1j * array.unit_azimuths), axis=-1)
    return np.where(np.abs(z) > 0, np.angle(z), np.nan)


def _choose_by_brightness(first, second, bright):
    """Pick the candidate nearer the bright side."""
    d1 = np.abs(wrap_angle(first - bright))
    d2 = np.abs(wrap_angle(second - bright))
    return np.where(np.isfinite(bright) & (d2 < d1), second, first), np.where(np.isfinite(bright) & (d2 < d1), first, second)


@dataclass(frozen=True)
class SkyTable:
    """Expected e-vectors of every unit for a grid of solar azimuths (one sun elevation).

    Attributes
    ----------
    azimuths : ndarray, shape ``(G,)``
        Solar azimuths in the sensor frame, ``2 pi g / G``.
    cos2, sin2 : ndarray, shape ``(G, K)``
        ``cos 2a^``, ``sin 2a^`` of the predicted e-vector angle in each unit frame.
    degree : ndarray, shape ``(G, K)``
        Predicted degree.
    """

    azimuths: np.ndarray
    cos2: np.ndarray
    sin2: np.ndarray
    degree: np.ndarray


def sky_table(array: PolArray, sun_elevation: float, *, n_grid: int = 720, max_degree: float = 0.76,
              neutral_point_separation: float = 0.0) -> SkyTable:
    """Tabulate the sky model's e-vector pattern seen by the array (:class:`bionav.light.SkyModel`).

    Parameters
    ----------
    array : PolArray
    sun_elevation : float
        Radians.
    n_grid : int
        Number of solar azimuths.
    max_degree, neutral_point_separation : float
        Sky model parameters (Rayleigh for separation 0, else Berry et al. 2004).
    """
    from bionav.light import SkyModel, SunPosition

    phis = 2.0 * np.pi * np.arange(n_grid) / n_grid
    model = SkyModel(SunPosition(0.0, float(sun_elevation)), max_degree=max_degree,
                     neutral_point_separation=neutral_point_separation)
    # the sun at sensor azimuth phi = a sensor heading of -phi under a sun at world azimuth 0
    _, q, u = stokes_from_sky(model, array, -phis)
    degree = np.hypot(q, u)
    a2 = np.arctan2(u, q)
    return SkyTable(phis, np.cos(a2), np.sin(a2), degree)


def sun_directions(azimuths, elevation):
    """Unit sun vectors in the sensor frame for solar azimuths (sensor frame) at one elevation, shape ``(G, 3)``."""
    az = np.asarray(azimuths, float)
    ce = np.cos(elevation)
    return np.stack([ce * np.cos(az), ce * np.sin(az), np.full(az.shape, np.sin(elevation))], axis=-1)


def _pick_pair(score, azimuths, total, margin):
    """Best grid column, best column more than a quarter turn away, both refined; normalised gap."""
    n, g = score.shape
    rows = np.arange(n)
    best = np.argmax(score, axis=1)
    # the eq. 4.6 partner: the best candidate within 45 degrees of the antipode
    far = (best[:, None] + g // 2 - g // 8 + np.arange(2 * (g // 8) + 1)[None, :]) % g
    alt = far[rows, np.argmax(np.take_along_axis(score, far, axis=1), axis=1)]
    step = 2.0 * np.pi / g

    def refine(j):
        shift = parabolic_peak_offset(score[rows, (j - 1) % g], score[rows, j], score[rows, (j + 1) % g])
        return wrap_angle(azimuths[j] + shift * step)

    gap = (score[rows, best] - score[rows, alt]) / np.maximum(total, 1e-12)
    return best, refine(best), refine(alt), gap


def _robust_weights(w0, r, scale, reject, *, last: bool):
    """Cauchy weights ``w0 / (1 + (r / scale)^2)``; on the ``last`` round with ``reject``: ``w0`` of the units with
    ``|r| <= reject`` where at least two such units remain (shapes ``(N, K)``, radians)."""
    w = w0 / (1.0 + (r / scale) ** 2)
    if not last or reject is None:
        return w
    keep = np.abs(r) <= reject
    enough = np.sum(keep & (w0 > 0), axis=-1) >= 2
    return np.where(enough[:, None], np.where(keep, w0, 0.0), w)


def sun_from_sky_fit(ev: UnitEvectors, valid, *, table: SkyTable, array: PolArray, sun_elevation: float | None = None,
                     residual: str = "perpendicular", weight_power: float = 1.0, robust_iterations: int = 2,
                     robust_scale: float = np.deg2rad(20.0), reject: float | None = np.deg2rad(30.0),
                     model_error: float = np.deg2rad(10.0), margin: float = 0.01, noise_counts: float = 0.0,
                     min_units: int = 1, pol_op_fallback: bool = False) -> SunEstimate:
    """bionav's least-squares fit of the sky model's pattern (see the module docstring).

    Parameters
    ----------
    ev : UnitEvectors
    valid : ndarray of bool, shape ``(N, K)``
    table : SkyTable
        From :func:`sky_table` for the session's sun elevation.
    array : PolArray
    sun_elevation : float, optional
        Radians; needed for ``residual="perpendicular"``.
    residual : {'perpendicular', 'angle'}
        ``perpendicular``: the single-scattering pattern's condition that
        every e-vector is perpendicular to the sun, ``E = sum_k w_k (e_k .
        s(phi))^2`` with ``s(phi)`` at the known elevation; ``angle``:
        ``E = sum_k w_k (1 - cos 2(a_k - a^_k(phi)))`` against the tabulated
        model angles (any sky model, e.g. with neutral points).
    weight_power : float
        Unit weight ``d_k ** weight_power``.
    robust_iterations : int
        Re-weighting rounds with Cauchy weights ``1 / (1 + (r_k / robust_scale)^2)``
        of each unit's angle residual ``r_k`` at the current solution: units
        contradicting the others at that sample (glare, leaves under canopy)
        count less. ``r_k`` is the angle, in the unit's own image plane, between
        the measured e-vector and the model's (radians): for ``perpendicular``
        ``r_k = arcsin(e_k . s / |s_perp,k|)`` with ``s_perp,k`` the sun vector's
        component across unit ``k``'s view, so units that look near the sun or
        the antisun (where the pattern's angle is ill-defined) are judged in
        the same units as the others.
    robust_scale : float
        Cauchy scale of the re-weighting, radians.
    reject : float or None
        After the Cauchy rounds, units whose angle residual exceeds ``reject``
        (radians) are dropped and the last solve weights the others by ``w_k``
        alone: one unit seeing leaves instead of sky then leaves the heading
        of the clean units exactly (where at least two units remain; else the
        Cauchy weights stay). ``None``: no rejection.
    model_error : float
        Model-error scale ``s`` of the noise weighting below, radians.
    margin : float
        Minimum difference of the normalised errors of the pair for a
        resolved choice; below it the brighter side decides.
    noise_counts : float
        Count noise per photodiode (counts; 0: none). Each unit's angle noise ``sigma_a``
        (:func:`angle_noise`) lowers its weight to ``d^p s^2 / (s^2 + sigma_a^2)`` with the model-error
        scale ``s = model_error`` (inverse-variance weighting of model error plus noise), and a unit
        whose ``sigma_a`` exceeds ``s`` takes no part: at dusk, units read by light above the noise
        floor count, dark ones not.
    min_units : int
        Fewest units taking part for a sample to be decoded (two e-vectors fix the sun); fewer: NaN,
        ``SunEstimate.valid`` False (below the noise floor nothing is claimed).
    pol_op_fallback : bool
        Samples with fewer than ``min_units`` units taking part, and samples where a unit reads one POL-OP
        only (:attr:`UnitEvectors.pol_op_valid`: one saturated pair, one faulty photodiode), are decoded from
        every usable POL-OP (:func:`sun_from_pol_op_fit`), so such units still vote; where that has too few
        readings the whole units' fit stays (NaN if there is none).

    Returns
    -------
    SunEstimate
    """
    w0 = _fit_weights(ev, valid, weight_power=weight_power, noise_counts=noise_counts, model_error=model_error,
                      min_units=min_units)
    robust = {"iterations": robust_iterations, "scale": robust_scale, "reject": reject}
    if residual == "perpendicular":
        if sun_elevation is None:
            raise ValueError("residual='perpendicular' needs the sun elevation")
        score, w = _perpendicular_scores(ev, w0, table=table, array=array, sun_elevation=float(sun_elevation), **robust)
    elif residual == "angle":
        score, w = _angle_scores(ev, w0, table=table, **robust)
    else:
        raise ValueError(f"residual must be 'perpendicular' or 'angle', got {residual!r}")
    usable = w0.sum(axis=-1) > 0
    total = np.maximum(w.sum(axis=-1), 1e-12)
    bright = brightness_azimuth(ev, valid, array)
    fallback = _pol_op_rows(ev, usable) if pol_op_fallback else np.zeros_like(usable)
    if fallback.any():
        rows = np.flatnonzero(fallback)
        sub = ev.rows(rows)
        f_score, f_total, f_ok = _pol_op_scores(sub, np.asarray(valid, bool)[rows], table=table, array=array,
                                                noise_counts=noise_counts, model_error=model_error, min_units=min_units)
        rows, f_score, f_total = rows[f_ok], f_score[f_ok], f_total[f_ok]  # too few POL-OPs: the whole units' fit stays
        score[rows], total[rows] = f_score, f_total
        bright[rows] = brightness_azimuth(ev.rows(rows), np.isfinite(ev.intensity[rows]), array)
        usable = usable.copy()
        usable[rows] = True
    _, first, second, gap = _pick_pair(score, table.azimuths, total, margin)
    resolved = gap > margin
    by_light, other = _choose_by_brightness(first, second, bright)
    azimuth = np.where(usable, np.where(resolved, first, by_light), np.nan)
    return SunEstimate(azimuth, np.where(usable, np.where(resolved, second, other), np.nan), resolved & usable)


def _pol_op_rows(ev: UnitEvectors, usable):
    """Samples ``sky_fit`` decodes from every usable POL-OP: too few whole units (not ``usable``), or a unit that
    reads one POL-OP only (it votes there; needs :attr:`UnitEvectors.pol_op_valid`), shape ``(N,)``."""
    if ev.pol_op_valid is None:
        return ~usable
    return ~usable | np.any(np.sum(ev.pol_op_valid, axis=-1) == 1, axis=-1)


def pol_op_table(table: SkyTable, array: PolArray):
    """Model POL-OP outputs ``b_kj(phi) = d^_k cos(2 a^_k - 2 alpha_kj)`` for the table's solar azimuths, shape ``(G, K, J)``.

    ``d^``, ``a^``: the table's degree and e-vector angle in each unit frame; ``alpha_kj``: the first polarizer
    angle of POL-OP ``j`` (:attr:`PolArray.pair_angles`), radians.
    """
    a2 = 2.0 * array.pair_angles  # (K, J)
    return table.degree[:, :, None] * (table.cos2[:, :, None] * np.cos(a2) + table.sin2[:, :, None] * np.sin(a2))


def _pol_op_scores(ev: UnitEvectors, valid, *, table: SkyTable, array: PolArray, noise_counts: float,
                   model_error: float, min_units: int, min_degree: float = 0.05):
    """Scores of :func:`sun_from_pol_op_fit` on the table's azimuths ``(N, G)``, the normalising totals ``(N,)`` and
    whether each sample has enough readings ``(N,)``."""
    x = np.asarray(ev.x, float)
    xs = np.nan_to_num(x)
    checked = np.asarray(valid, bool)[..., None] if ev.pol_op_valid is None else np.asarray(ev.pol_op_valid, bool)
    readable = np.isfinite(x) & checked
    if noise_counts > 0 and ev.pair_total is not None:
        s = np.nan_to_num(np.asarray(ev.pair_total, float))
        with np.errstate(divide="ignore"):
            sigma_x = np.where(s > 0, np.sqrt(2.0) * float(noise_counts) / np.where(s > 0, s, 1.0), np.inf)
        readable &= sigma_x / (2.0 * np.maximum(np.abs(xs), min_degree)) <= model_error
    n = x.shape[0]
    w = readable.reshape(n, -1).astype(float)
    b = pol_op_table(table, array).reshape(table.azimuths.size, -1)  # (G, K J)
    sxb = (w * xs.reshape(n, -1)) @ b.T
    sbb = w @ (b**2).T
    score = np.maximum(sxb, 0.0) ** 2 / np.maximum(sbb, 1e-12)
    enough = (readable.any(axis=-1).sum(axis=-1) >= max(int(min_units), 2)) & (readable.reshape(n, -1).sum(axis=-1) >= 3)
    return score, np.maximum(np.sum(w * xs.reshape(n, -1) ** 2, axis=-1), 1e-12), enough


def sun_from_pol_op_fit(ev: UnitEvectors, valid, *, table: SkyTable, array: PolArray, noise_counts: float = 0.0,
                        model_error: float = np.deg2rad(10.0), margin: float = 0.01, min_units: int = 2) -> SunEstimate:
    """The solar azimuth from every usable POL-OP, not every usable unit.

    A POL-OP ``j`` of unit ``k`` reads ``x_kj = d_k cos(2 a_k - 2 alpha_kj)`` (eq. 4.3), one equation
    even where the unit's other POL-OP is saturated. Against the sky model's pattern (the table's
    degree ``d^_k(phi)`` and angle ``a^_k(phi)`` at the known sun elevation, heading unknown) the fit
    minimises ``sum_kj (x_kj - lambda b_kj(phi))^2`` over the solar azimuth ``phi`` and a common degree
    scale ``lambda > 0`` (the sky's maximum degree times the polarizer efficiency, unknown at each
    sample), with ``b_kj = d^_k cos(2 a^_k - 2 alpha_kj)`` (:func:`pol_op_table`): in closed form
    ``lambda = sum x b / sum b^2`` and the score ``(sum x b)_+^2 / sum b^2`` is maximised on the grid, then
    refined by a parabola; the eq. 4.6 pair as in :func:`sun_from_sky_fit` (the degree pattern is not
    mirror-symmetric for tilted units), else the brighter side (units with a finite intensity, saturated
    ones included: only faulty units' intensities are NaN). ``sky_fit`` uses it for samples where a unit reads one POL-OP
    only or too few units read both.

    Parameters
    ----------
    ev : UnitEvectors
        With :attr:`~bionav.polcompass.array.UnitEvectors.pol_op_valid` (:func:`bionav.polcompass.array.masked_pol_ops`)
        every usable POL-OP takes part; without it only those of the units in ``valid``.
    valid : ndarray of bool, shape ``(N, K)``
        Units reading both POL-OPs (the per-unit mask of the other decoders).
    table : SkyTable
    array : PolArray
    noise_counts : float
        Count noise per photodiode; a POL-OP whose angle noise ``sqrt(2) sigma_c / (2 S |x|)``
        (``S``: :attr:`UnitEvectors.pair_total`, ``|x|`` at least 0.05) exceeds ``model_error`` is left out.
    model_error : float
        Radians.
    margin : float
        Minimum normalised score gap of the pair for a resolved choice.
    min_units : int
        Fewest units with a usable POL-OP (at least 2, and at least 3 POL-OPs: ``phi`` and ``lambda``).

    Returns
    -------
    SunEstimate
        NaN where the sample has too few usable POL-OPs.
    """
    score, total, ok = _pol_op_scores(ev, valid, table=table, array=array, noise_counts=noise_counts, model_error=model_error,
                                      min_units=min_units)
    _, first, second, gap = _pick_pair(score, table.azimuths, total, margin)
    resolved = gap > margin
    by_light, other = _choose_by_brightness(first, second, brightness_azimuth(ev, np.isfinite(ev.intensity), array))
    azimuth = np.where(ok, np.where(resolved, first, by_light), np.nan)
    return SunEstimate(azimuth, np.where(ok, np.where(resolved, second, other), np.nan), resolved & ok)


def _fit_weights(ev: UnitEvectors, valid, *, weight_power, noise_counts, model_error, min_units):
    """``sky_fit``'s unit weights before re-weighting, shape ``(N, K)`` (see :func:`sun_from_sky_fit`)."""
    w0 = _weights(ev, valid, weight_power)
    if noise_counts > 0:
        sigma = angle_noise(ev, noise_counts)
        readable = sigma <= model_error
        w0 = np.where(readable, w0 * model_error**2 / (model_error**2 + np.where(readable, sigma, 0.0) ** 2), 0.0)
    enough = np.sum(w0 > 0, axis=-1) >= max(int(min_units), 1)
    return np.where(enough[:, None], w0, 0.0)


def _perpendicular_scores(ev: UnitEvectors, w0, *, table: SkyTable, array: PolArray, sun_elevation: float,
                          iterations: int, scale: float, reject):
    """Scores ``-sum_k w_k (e_k . s(phi))^2`` on the table's azimuths, shape ``(N, G)``, and the last weights ``(N, K)``.

    Re-weighting on each unit's angle residual ``arcsin(e_k . s / |s_perp,k|)`` (:func:`sun_from_sky_fit`).
    """
    e = np.nan_to_num(ev.evector)
    v = sun_directions(table.azimuths, sun_elevation)  # (G, 3)
    views = array.unit_frames()[:, :, 2]  # (K, 3) view directions in the sensor frame
    iu, ju = np.triu_indices(3)
    mono = v[:, iu] * v[:, ju] * np.where(iu == ju, 1.0, 2.0)  # (G, 6): quadratic form as a matmul
    w = w0
    for it in range(iterations + 1):
        m6 = np.einsum("nk,nki,nki->ni", w, e[..., iu], e[..., ju])  # upper triangle of sum_k w e e^T
        score = -(m6 @ mono.T)
        if it < iterations:
            s = v[np.argmax(score, axis=1)]  # (N, 3)
            across = np.sqrt(np.maximum(1.0 - (s @ views.T) ** 2, 1e-6))  # |s_perp| per unit, (N, K)
            r = np.arcsin(np.clip(np.einsum("nki,ni->nk", e, s) / across, -1.0, 1.0))
            w = _robust_weights(w0, r, scale, reject, last=it == iterations - 1)
    return score, w


def _angle_scores(ev: UnitEvectors, w0, *, table: SkyTable, iterations: int, scale: float, reject):
    """Scores ``sum_k w_k cos 2(a_k - a^_k(phi))`` on the table's azimuths, shape ``(N, G)``, and the last weights."""
    a2 = 2.0 * np.nan_to_num(ev.angle)
    ca, sa = np.cos(a2), np.sin(a2)
    w = w0
    for it in range(iterations + 1):
        score = (w * ca) @ table.cos2.T + (w * sa) @ table.sin2.T  # (N, G)
        if it < iterations:
            best = np.argmax(score, axis=1)
            r = 0.5 * np.arccos(np.clip(ca * table.cos2[best] + sa * table.sin2[best], -1.0, 1.0))
            w = _robust_weights(w0, r, scale, reject, last=it == iterations - 1)
    return score, w
