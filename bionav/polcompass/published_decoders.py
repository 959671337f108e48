"""The thesis' two-unit solution and the published per-sample decoders of a POL-OP array.

Conventions as in :mod:`bionav.polcompass.decoders` (bionav's own ``sky_fit``):
each function takes one sample's :class:`~bionav.polcompass.array.UnitEvectors`
and ``valid`` mask and returns a :class:`~bionav.polcompass.decoders.SunEstimate`,
the solar azimuth in the sensor frame (radians, counter-clockwise from the sensor
front, ``[-pi, pi)``).

Decoders
--------
``two_unit`` (the thesis' solution)
    Eqs. 4.4-4.5 give each unit's e-vector; for single scattering the sun is
    perpendicular to every e-vector, so two units give ``s = +-(e_i x e_j)``
    (Lambrinos et al. 2000 use the zenith case of this). The pair with the
    largest ``d_i d_j |e_i x e_j|`` is used; the eq. 4.6 pair ``(s, -s)`` is
    resolved by the error function ``|elevation - expected elevation|``.
``eigenvector``
    The sun vector is the eigenvector of the smallest eigenvalue of
    ``M = sum_k w_k e_k e_k^T`` (the e-vectors are all perpendicular to it;
    e.g. Lu et al. 2015, Opt. Express 23:7248, doi:10.1364/OE.23.007248),
    with ``w_k = d_k``; sign: the sun is above the horizon.
``mean_vector``
    The weighted mean of the pairwise sun vectors ``e_i x e_j`` each turned
    to the upper hemisphere (weights ``d_i d_j |e_i x e_j|``).
``sol``
    The sinusoidal population decoder of Gkanias et al. (2019), PLoS Comput.
    Biol. 15:e1007123, doi:10.1371/journal.pcbi.1007123, with the responses of
    Gkanias et al. (2023), doi:10.1038/s44172-023-00132-w: each unit gives a
    POL response ``p_k`` (normalised POL-OP difference), an intensity
    response ``i_k`` and their difference ``c_k = i_k - p_k``; ``n_sol`` SOL
    neurons with preferred directions ``theta_z`` respond
    ``r_z = (n_sol / n_units) sum_k sin(theta_k - theta_z + pi/2) r_k``, and
    the solar azimuth is the phase of their first Fourier harmonic,
    ``arg sum_z r_z exp(i theta_z)``. No ambiguity to resolve (a vector, not
    an axis), reported as resolved where the population vector is non-zero.
``four_zeros``
    Smith & Stewart (2014), doi:10.5220/0004792100210026: around a ring of
    sky points, the angle ``chi`` between e-vector and local meridian passes
    through +-45 degrees at four azimuths placed symmetrically about the
    solar meridian; the meridian is the axis of their first harmonic, found
    here by linear interpolation of ``cos 2 chi`` between neighbouring units
    (the axis about which the zero set is most nearly mirror-symmetric);
    the brighter side picks the sun's end (eq. 4.6 pair).
"""

from __future__ import annotations

import numpy as np

from bionav.geometry import wrap_angle
from bionav.polcompass.array import PolArray, UnitEvectors
from bionav.polcompass.decoders import SunEstimate, _choose_by_brightness, _weights, brightness_azimuth


def _sun_candidates(s, expected_elevation, margin):
    """Eq. 4.6 pair for sun vectors ``+-s``: choose by the elevation error function."""
    s = np.asarray(s, float)
    norm = np.linalg.norm(s, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        s = s / norm[..., None]
    el = np.arcsin(np.clip(s[..., 2], -1.0, 1.0))
    az = np.arctan2(s[..., 1], s[..., 0])
    err_plus = np.abs(el - expected_elevation)
    err_minus = np.abs(-el - expected_elevation)
    flip = err_minus < err_plus
    first = np.where(flip, wrap_angle(az + np.pi), az)
    second = wrap_angle(first + np.pi)
    resolved = np.abs(err_plus - err_minus) > margin
    bad = ~np.isfinite(az) | (norm < 1e-12)
    return SunEstimate(np.where(bad, np.nan, first), np.where(bad, np.nan, second), resolved & ~bad)


def _pair_index(k):
    i, j = np.triu_indices(k, 1)
    return i, j


def sun_from_two_units(ev: UnitEvectors, valid, *, sun_elevation, margin: float = np.deg2rad(2.0)) -> SunEstimate:
    """The thesis' two-unit solution generalised to tilted units (see the module docstring).

    Parameters
    ----------
    sun_elevation : float or ndarray, shape ``(N,)``
        Expected sun elevation (radians), the error function's reference.
    margin : float
        Minimum difference of the elevation errors for a resolved choice, radians.
    """
    w = _weights(ev, valid, 1.0)
    e = np.nan_to_num(ev.evector)
    i, j = _pair_index(e.shape[1])
    cross = np.cross(e[:, i], e[:, j])  # (N, pairs, 3)
    score = w[:, i] * w[:, j] * np.linalg.norm(cross, axis=-1)
    best = np.argmax(score, axis=1)
    s = cross[np.arange(len(best)), best]
    s = np.where((score[np.arange(len(best)), best] > 0)[:, None], s, np.nan)
    return _sun_candidates(s, np.asarray(sun_elevation, float), margin)


def sun_from_eigenvector(ev: UnitEvectors, valid, *, margin: float = np.deg2rad(2.0)) -> SunEstimate:
    """Eigenvector method: the direction most perpendicular to all weighted e-vectors."""
    w = _weights(ev, valid, 1.0)
    e = np.nan_to_num(ev.evector)
    m = np.einsum("nk,nki,nkj->nij", w, e, e)
    _, vecs = np.linalg.eigh(m)
    s = vecs[..., 0]
    s = np.where((np.sum(w > 0, axis=1) >= 2)[:, None], s, np.nan)
    return _up(s, margin)


def _up(s, margin):
    """Resolve ``+-s`` by "the sun is above the horizon"; resolved where ``|s_z| > sin(margin)``."""
    s = np.asarray(s, float)
    norm = np.linalg.norm(s, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        s = s / norm[..., None]
    s = np.where((s[..., 2] < 0)[..., None], -s, s)
    az = np.arctan2(s[..., 1], s[..., 0])
    bad = ~np.isfinite(az) | ~(norm > 1e-12)
    resolved = np.abs(s[..., 2]) > np.sin(margin)
    return SunEstimate(np.where(bad, np.nan, az), np.where(bad, np.nan, wrap_angle(az + np.pi)), resolved & ~bad)


def sun_from_mean_vector(ev: UnitEvectors, valid, *, margin: float = np.deg2rad(2.0)) -> SunEstimate:
    """Mean-vector method: weighted mean of pairwise sun vectors turned upwards."""
    w = _weights(ev, valid, 1.0)
    e = np.nan_to_num(ev.evector)
    i, j = _pair_index(e.shape[1])
    cross = np.cross(e[:, i], e[:, j])
    cross = np.where((cross[..., 2] < 0)[..., None], -cross, cross)  # |e_i x e_j| already weights by angle
    s = np.einsum("np,npi->ni", w[:, i] * w[:, j], cross)
    return _up(s, margin)


def sol_responses(ev: UnitEvectors, valid, *, response: str = "c", analyser: float = np.pi / 2.0):
    """Per-unit responses of Gkanias et al. (2023): ``p`` (POL), ``i`` (intensity) or ``c = i - p``.

    ``p_k = d_k cos(2 (a_k - analyser))`` is the normalised POL-OP response
    ``(s_par - s_perp) / (s_par + s_perp)`` of an analyser at ``analyser`` in
    the unit frame (``pi/2``: horizontal, perpendicular to the unit's
    meridian, i.e. largest for units on the solar meridian); ``i_k`` is the
    unit's intensity divided by the mean over the valid units, minus one.
    """
    ok = np.asarray(valid, bool) & np.isfinite(ev.intensity) & np.isfinite(ev.angle)
    p = np.where(ok, np.nan_to_num(ev.degree) * np.cos(2.0 * (np.nan_to_num(ev.angle) - analyser)), 0.0)
    n = np.maximum(ok.sum(axis=-1), 1)
    inten = np.where(ok, np.nan_to_num(ev.intensity), 0.0)
    mean = inten.sum(axis=-1) / n
    i = np.where(ok, inten / np.maximum(mean, 1e-12)[:, None] - 1.0, 0.0)
    if response == "p":
        return p, ok
    if response == "i":
        return i, ok
    if response == "c":
        return i - p, ok
    raise ValueError(f"response must be p, i or c, got {response!r}")


def sun_from_sol(ev: UnitEvectors, valid, *, array: PolArray, n_sol: int = 8, response: str = "c",
                 analyser: float = np.pi / 2.0) -> SunEstimate:
    """Sinusoidal population (SOL) decoder (see the module docstring)."""
    r, ok = sol_responses(ev, valid, response=response, analyser=analyser)
    theta_z = 2.0 * np.pi * np.arange(n_sol) / n_sol
    theta_k = array.unit_azimuths
    n_units = np.maximum(ok.sum(axis=-1), 1)
    weights = np.sin(theta_k[None, :] - theta_z[:, None] + np.pi / 2.0)  # (n_sol, K)
    r_sol = (n_sol / n_units)[:, None] * (r @ weights.T)  # (N, n_sol)
    z = r_sol @ np.exp(1j * theta_z)
    if response == "p":  # the POL population points away from the sun (Gkanias et al. 2023, fig. 2c)
        z = -z
    az = np.angle(z)
    good = np.abs(z) > 1e-12
    return SunEstimate(np.where(good, az, np.nan), np.where(good, wrap_angle(az + np.pi), np.nan), good)


def _ring_fit(values, valid, azimuths, grid, n_harmonics):
    """Weighted least-squares trigonometric interpolation of per-unit values around the ring, on ``grid``."""
    def basis(t):
        cols = [np.ones_like(t)]
        for m in range(1, n_harmonics + 1):
            cols += [np.cos(m * t), np.sin(m * t)]
        return np.stack(cols, axis=-1)

    b = basis(np.asarray(azimuths, float))  # (K, P)
    w = np.asarray(valid, float)
    a = np.einsum("nk,kp,kq->npq", w, b, b) + 1e-9 * np.eye(b.shape[1])
    rhs = np.einsum("nk,kp,nk->np", w, b, np.nan_to_num(values))
    coef = np.linalg.solve(a, rhs[..., None])[..., 0]
    return coef @ basis(grid).T  # (N, G)


def sun_from_four_zeros(ev: UnitEvectors, valid, *, array: PolArray, n_harmonics: int = 3, n_grid: int = 360) -> SunEstimate:
    """Four-zeros method (see the module docstring).

    ``cos 2 chi`` (``chi`` = e-vector angle from the unit's meridian, the unit
    frame's ``x_u``) is interpolated around the ring by a trigonometric
    least-squares fit with up to ``n_harmonics`` harmonics (fewer when fewer
    units are valid) and cut at ``chi = +-45`` degrees, else (Smith & Stewart's
    other options) at ``+-(45 + 60)`` or ``+-(45 - 60)`` degrees; samples whose
    curve crosses none of these levels exactly four times are not decoded. The four zeros form two pairs placed
    symmetrically about the solar meridian; of the two ways to pair
    neighbouring zeros (mirror pairs are nested) the one whose pair bisectors
    lie most nearly on one line gives the meridian; the brighter side picks the sun's end.
    """
    n, k = ev.angle.shape
    ok = np.asarray(valid, bool) & np.isfinite(ev.angle)
    count = ok.sum(axis=1)
    grid = 2.0 * np.pi * np.arange(n_grid) / n_grid
    f = np.cos(2.0 * np.nan_to_num(ev.angle))
    curve = np.full((n, n_grid), np.nan)
    for h in range(1, n_harmonics + 1):
        rows = (count >= 2 * h + 1) & ((h == n_harmonics) | (count < 2 * h + 3))
        if rows.any():
            curve[rows] = _ring_fit(f[rows], ok[rows], array.unit_azimuths, grid, h)
    nxt = np.roll(np.arange(n_grid), -1)
    azimuth = np.full(n, np.nan)
    alternative = np.full(n, np.nan)
    resolved = np.zeros(n, bool)
    bright_all = brightness_azimuth(ev, valid, array)
    # Smith & Stewart's three options: chi = +-45, +-(45 + 60), +-(45 - 60) degrees
    for level in (0.0, -np.cos(np.pi / 6.0), np.cos(np.pi / 6.0)):
        g = curve - level
        crossing = (np.sign(g) != np.sign(g[:, nxt])) & np.isfinite(g) & np.isfinite(g[:, nxt])
        four = (crossing.sum(axis=1) == 4) & np.isnan(azimuth)
        if not four.any():
            continue
        rows, cols = np.nonzero(crossing[four])
        c0, c1 = g[four][rows, cols], g[four][rows, nxt[cols]]
        step = 2.0 * np.pi / n_grid
        z = (grid[cols] + c0 / (c0 - c1) * step).reshape(-1, 4)  # sorted around the ring

        def mid(a, b):
            return np.angle(np.exp(1j * a) + np.exp(1j * b))

        best_axis, best_err = None, None
        for pairing in (((0, 1), (2, 3)), ((1, 2), (3, 0))):
            m1 = mid(z[:, pairing[0][0]], z[:, pairing[0][1]])
            m2 = mid(z[:, pairing[1][0]], z[:, pairing[1][1]])
            err = np.abs(wrap_angle(2.0 * (m1 - m2)))  # both bisectors lie on the meridian (a line)
            axis = 0.5 * np.angle(np.exp(2j * m1) + np.exp(2j * m2))
            if best_axis is None:
                best_axis, best_err = axis, err
            else:
                better = err < best_err
                best_axis = np.where(better, axis, best_axis)
                best_err = np.where(better, err, best_err)
        bright = bright_all[four]
        first, second = _choose_by_brightness(best_axis, wrap_angle(best_axis + np.pi), bright)
        azimuth[four], alternative[four], resolved[four] = first, second, np.isfinite(bright)
    return SunEstimate(azimuth, alternative, resolved)
