"""Self-calibration of a POL-OP array from its own rotations (no heading truth beyond the yaw).

A robot turning in place under a steady sky shows every unit of a fan (units
at one tilt, different azimuths) the same ring of sky points, each at
another yaw. Unit ``k``'s photodiode ``p`` reads (eq. 4.1 of the thesis,
Lambrinos et al. 2000, doi:10.1016/S0921-8890(99)00064-0, with per-channel
tolerances)::

    c_kp(t) = g_kp I(theta) (1 + q(theta) cos 2 alpha_kp + u(theta) sin 2 alpha_kp) / 2,
    theta = yaw(t) + A_k,     alpha_kp = alpha0_kp + delta_kp,

where ``I, q, u`` (radiance and normalised Stokes parameters in the unit
frame, see :mod:`bionav.polcompass.array`) are one smooth function of the
viewing azimuth ``theta`` around the ring, shared by all units (a Fourier
series of ``n_harmonics``), ``A_k`` the nominal unit azimuth, and the unknowns
per channel are the photodiode gain ``g_kp`` and the polarizer angle offset
``delta_kp`` (unit pointing offsets are not fitted: the file format keeps a
per-unit ``azimuth_offset`` at 0 for them). :func:`calibrate_session` fits
them to the counts binned by yaw by alternating linear least squares (the
ring given the channels, each channel given the ring). The ring fixes
everything but these gauges:

* the overall gain scale (absorbed into ``I``): gains are reported relative
  to their geometric mean over the fitted channels;
* a gain pattern common to all units that varies with the polarizer angle
  as ``cos 2 alpha`` or ``sin 2 alpha`` (absorbed into a constant added to
  ``q`` or ``u``): fixed by making the channels as a whole most nearly nominal,
  so what the units share of such a pattern is not recovered (at a degree of
  polarization ``d`` a common 2 % gain pattern turns e-vectors by about
  ``0.01 / d`` radians);
* a polarizer offset common to all units (absorbed into a rotation of
  ``q, u``). It is fixed by the mirror symmetry of a clear sky about the
  solar meridian: ``I`` and ``I q`` are even and ``I u`` odd about some axis
  ``phi`` (:func:`mirror_gauge`), which holds for single and multiple
  scattering alike; only clear (``symmetric=True``) sessions should be used.

:func:`combine_sessions` pools the per-session estimates (medians, one gain
gauge per session) into an :class:`ArrayCalibration` with standard errors
from the spread across sessions; :meth:`ArrayCalibration.apply` returns
the calibrated :class:`~bionav.polcompass.array.PolArray` (per-channel gains,
angles and unit azimuths), read through the POL-OP chain with each pair at
its mean calibrated orientation (default) or, ``solver="stokes"``, from all
photodiodes by linear least squares at their own angles.

Angles in radians internally; the JSON file (:meth:`ArrayCalibration.save`)
stores degrees under keys ending ``_deg`` (schema in docs/polcompass.md).
"""

from __future__ import annotations

import json
import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from bionav.errors import UserError
from bionav.geometry import parabolic_peak_offset, wrap_axial
from bionav.validation import Range

SCHEMA = "bionav.pol_array_calibration/1"
#: what each field of a calibration file may hold (JSON null: "not calibrated", where a fill is defined)
FIELD_RANGES = {
    "units": Range(ge=1, le=64), "photodiodes": Range(ge=1, le=16), "gain": Range(ge=1e-3, le=1e3),
    "gain_log_sigma": Range(ge=0.0, le=10.0), "angle_offset_deg": Range(ge=-180.0, le=180.0),
    "angle_sigma_deg": Range(ge=0.0, le=360.0), "azimuth_offset_deg": Range(ge=-180.0, le=180.0),
    "azimuth_sigma_deg": Range(ge=0.0, le=360.0), "n_sessions": Range(ge=0, le=1_000_000),
    "mount_tilt_deg": Range(ge=-45.0, le=45.0),
}


@dataclass(frozen=True)
class SessionCalibration:
    """Calibration estimated from one session.

    Attributes
    ----------
    log_gain : ndarray, shape ``(K, P)``
        Natural log of each photodiode's gain, geometric mean over ``fitted`` = 0; NaN where not fitted.
    angle_offset : ndarray, shape ``(K, P)``
        Polarizer angle offsets ``delta_kp``, radians (same sense as the polarizer angles); NaN where not fitted.
    azimuth_offset : ndarray, shape ``(K,)``
        Unit pointing offsets ``eps_k``, radians CCW, mean 0 over fitted units; NaN where not fitted.
    fitted : ndarray of bool, shape ``(K,)``
        Units that took part.
    common_offset : float
        The all-unit polarizer offset found by the mirror symmetry, radians (already in ``angle_offset``).
    symmetry : float
        Mean resultant length of the mirror condition (1: perfectly symmetric sky), ``[0, 1]``.
    residual_rms : float
        RMS of the fit's log-count residuals (natural log units).
    """

    log_gain: np.ndarray
    angle_offset: np.ndarray
    azimuth_offset: np.ndarray
    fitted: np.ndarray
    common_offset: float
    symmetry: float
    residual_rms: float


def _basis(theta, n_harmonics):
    cols = [np.ones_like(theta)]
    for m in range(1, n_harmonics + 1):
        cols += [np.cos(m * theta), np.sin(m * theta)]
    return np.stack(cols, axis=-1)


def bin_by_yaw(counts, yaw, valid, *, n_bins: int = 120, min_samples: int = 2):
    """Median log counts per yaw bin, unit and photodiode.

    Parameters
    ----------
    counts : ndarray, shape ``(N, K, P)``
    yaw : ndarray, shape ``(N,)``
        Radians CCW (any zero).
    valid : ndarray of bool, shape ``(N, K)``
    n_bins : int
        Bins over the full turn.
    min_samples : int
        Bins with fewer valid samples are NaN.

    Returns
    -------
    centres : ndarray, shape ``(B,)``
        Bin centres, radians.
    log_counts : ndarray, shape ``(B, K, P)``
        NaN where empty.
    """
    c = np.asarray(counts, float)
    n, k, p = c.shape
    b = np.floor(np.mod(np.asarray(yaw, float), 2.0 * np.pi) / (2.0 * np.pi) * n_bins).astype(int) % n_bins
    ok = np.asarray(valid, bool) & np.all(c > 0, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        logc = np.where(ok[..., None], np.log(np.where(c > 0, c, 1.0)), np.nan)
    out = np.full((n_bins, k, p), np.nan)
    order = np.argsort(b, kind="stable")
    edges = np.searchsorted(b[order], np.arange(n_bins + 1))
    for i in range(n_bins):  # one median per bin (vectorised over units and photodiodes)
        rows = order[edges[i]:edges[i + 1]]
        if rows.size:
            block = logc[rows]
            enough = np.sum(np.isfinite(block), axis=0) >= min_samples
            block = np.where(enough[None], block, 0.0)  # all-NaN columns are masked below
            med = np.nanmedian(block, axis=0)
            out[i] = np.where(enough, med, np.nan)
    centres = (np.arange(n_bins) + 0.5) * 2.0 * np.pi / n_bins
    return centres, out


def yaw_run_shifts(counts, yaw, valid, runs, *, n_bins: int = 360, max_shift_deg: float = 20.0) -> np.ndarray:
    """How far each run of the logged yaw is turned against the first, from the counts alone (radians, ``(R,)``).

    Under a steady sky every run of a rotation session sees the same ring of log
    counts per unit and photodiode; a run whose yaw restarted
    (:func:`bionav.polcompass.recordings.yaw_restarts`) sees it turned by the
    unlogged angle ``s``: ``f_r(theta) = f_0(theta + s)``. Each run's ring is
    binned by yaw (:func:`bin_by_yaw`, each channel's mean removed), and ``s``
    minimises the mean squared difference between the first run's ring and
    run ``r``'s ring read at ``theta - s`` (whole bins within ``max_shift_deg``,
    then a parabola through the three best; interpolating between bins would
    favour half-bin shifts, where it averages the noise):
    ``yaw + shift[run]`` puts every run in the first run's reference. No heading
    truth and no decoder is used. A run sharing no ring bin with the first, or
    whose best match lies at the search limit, gets NaN.

    Parameters
    ----------
    counts : ndarray, shape ``(N, K, P)``
    yaw : ndarray, shape ``(N,)``
        Radians CCW.
    valid : ndarray of bool, shape ``(N, K)``
    runs : ndarray of int, shape ``(N,)``
        Run of each sample, ``0 .. R-1``.
    n_bins : int
        Ring bins over the full turn (a run should fill them: about 400 samples per turn fill 360).
    max_shift_deg : float
        Largest shift searched, degrees.

    Returns
    -------
    ndarray, shape ``(R,)``
        Radians CCW; ``shift[0] = 0``.
    """
    runs = np.asarray(runs, int)
    counts, yaw, valid = np.asarray(counts), np.asarray(yaw, float), np.asarray(valid, bool)

    def ring(sel):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # empty bins and dark channels: NaN
            _c, y = bin_by_yaw(counts[sel], yaw[sel], valid[sel], n_bins=n_bins, min_samples=1)
            return y - np.nanmean(y, axis=0, keepdims=True)

    steps = np.arange(-int(np.ceil(max_shift_deg / 360.0 * n_bins)), int(np.ceil(max_shift_deg / 360.0 * n_bins)) + 1)
    index = (np.arange(n_bins)[None] - steps[:, None]) % n_bins  # (S, B): ring r read at theta_b - s, whole bins
    base = ring(runs == 0)
    out = np.zeros(int(runs.max()) + 1 if runs.size else 1)
    for r in range(1, out.size):
        diff = ring(runs == r)[index] - base[None]  # (S, B, K, P)
        n = np.sum(np.isfinite(diff), axis=(1, 2, 3))
        if not n.any():
            out[r] = np.nan
            continue
        cost = np.where(n > 0, np.nansum(diff**2, axis=(1, 2, 3)) / np.maximum(n, 1), np.inf)
        j = int(np.argmin(cost))
        if j in (0, cost.size - 1):  # best at the search limit: turned further than max_shift_deg, not placed
            out[r] = np.nan
            continue
        near = -cost[j - 1:j + 2]  # a minimum of the cost is a peak of its negative
        dj = float(parabolic_peak_offset(*near)) if np.all(np.isfinite(near)) else 0.0
        out[r] = (steps[j] + dj) * 2.0 * np.pi / n_bins
    return out


def mirror_gauge(stokes, theta):
    """Split a ring's Stokes components into the parts even and odd about the best mirror axis.

    In a sky symmetric about the solar meridian ``I`` and ``I q`` are even and ``I u`` odd about it
    (unit frames mirror with the sky), so some combination of the fitted components must be odd.

    Parameters
    ----------
    stokes : ndarray, shape ``(G, 3)``
        The fitted ring in any gauge on a regular grid ``theta`` over the turn.
    theta : ndarray, shape ``(G,)``

    Returns
    -------
    a : ndarray, shape ``(3, 3)``
        Rows: two combinations spanning the even part, then the odd one (unit vectors).
    phi : float
        Mirror axis, radians.
    asymmetry : float
        Relative size of what no combination explains (``0``: perfectly symmetric).
    """
    g = theta.size
    idx = np.arange(g)
    scale = np.linalg.norm(stokes)
    best = (None, 0.0, np.inf)
    for sh in range(g):
        for half in (0, 1):
            plus = stokes[(sh + idx) % g]
            minus = stokes[(sh + half - idx) % g]
            even = 0.5 * (plus + minus)
            odd = 0.5 * (plus - minus)
            _, se, vte = np.linalg.svd(even, full_matrices=False)
            _, so, vto = np.linalg.svd(odd, full_matrices=False)
            bad = (se[-1] ** 2 + so[-2] ** 2 + so[-1] ** 2) ** 0.5 / scale
            if bad < best[2]:
                # odd combination: annihilates the even part; even pair: annihilates the odd part
                best = (np.stack([vto[-2], vto[-1], vte[-1]]), float(theta[sh] + half * np.pi / g), float(bad))
    return best


def _channel_fit(stokes, c, w):
    """Weighted least squares of each channel's counts on the ring Stokes vectors: ``c_kp(b) = m_kp . S(theta_bk)``."""
    # stokes (B, K, 3), c (B, K, P), w (B, K, P) -> m (K, P, 3)
    a = np.einsum("bkp,bki,bkj->kpij", w, stokes, stokes) + 1e-12 * np.eye(3)
    rhs = np.einsum("bkp,bki,bkp->kpi", w, stokes, c)
    return np.linalg.solve(a, rhs[..., None])[..., 0]


def _ring_fit(m, c, w, f):
    """Weighted least squares of the ring's Fourier coefficients ``C`` (3, nb): ``c_kp(b) = m_kp . C f(theta_bk)``."""
    # design row of (b, k, p): kron(m_kp, f_bk) -> (3 * nb)
    design = (m[None, :, :, :, None] * f[:, :, None, None, :]).reshape(c.shape + (-1,))  # (B, K, P, 3 nb)
    d = design.reshape(-1, design.shape[-1])
    wf = w.ravel()
    normal = (d * wf[:, None]).T @ d
    rhs = (d * wf[:, None]).T @ c.ravel()
    coef = np.linalg.solve(normal + 1e-12 * np.trace(normal) / normal.shape[0] * np.eye(normal.shape[0]), rhs)
    return coef.reshape(3, -1)


def _nominal_gauge(m, alpha0, free=None):
    """The gauge ``B`` (3 x 3) that makes the channel vectors ``B m_kp`` most nearly nominal, ``g [1, cos 2a0, sin 2a0]``.

    ``free`` : boolean (3, 3) mask of the entries of ``B`` allowed to be non-zero (default all).
    """
    t = np.stack([np.ones_like(alpha0), np.cos(2 * alpha0), np.sin(2 * alpha0)], axis=-1)
    t = t / np.linalg.norm(t, axis=-1, keepdims=True)
    proj = np.eye(3) - t[..., :, None] * t[..., None, :]  # (K, P, 3, 3)
    mn = m / np.linalg.norm(m, axis=-1, keepdims=True)
    # B m = (m^T kron I3) vec(B) with vec column-major: element i = sum_j B_ij m_j
    kron = np.einsum("...j,ik->...ijk", mn, np.eye(3)).reshape(mn.shape[:-1] + (3, 9))  # [..., i, (j,k)] -> B_kj
    rows = np.einsum("...ab,...bc->...ac", proj, kron).reshape(-1, 9)
    keep = np.ones(9, bool) if free is None else np.asarray(free, bool).T.ravel()
    _, _, vt = np.linalg.svd(rows[:, keep], full_matrices=False)
    vec = np.zeros(9)
    vec[keep] = vt[-1]
    b = vec.reshape(3, 3).T  # rows (j, k) ordered as vec index 3 j + k = B_kj
    if np.mean((m @ b.T)[..., 0]) < 0:
        b = -b
    return b


def _fix_gauge(m, c, w, f, alpha0, *, n_harmonics: int, symmetric: bool):
    """Channel vectors ``m`` (K, P, 3) in the fixed gauge (:func:`calibrate_session`), their polarizer angles before
    :func:`_nominal_gauge` (radians, (K, P)) and the mirror symmetry's strength (NaN without ``symmetric``)."""
    strength = float("nan")
    free = None
    if symmetric:
        # the mirror symmetry: rotate the ring's components into (even, even, odd) first
        grid = 2.0 * np.pi * np.arange(180) / 180
        ring = _ring_fit(m, c, w, f)
        a, _phi, asym = mirror_gauge(_basis(grid, n_harmonics) @ ring.T, grid)
        m = m @ np.linalg.inv(a)  # S -> A S, m -> A^-T m
        strength = 1.0 - asym
        free = np.array([[1, 1, 0], [1, 1, 0], [0, 0, 1]], bool)  # only gauges that keep the symmetry
    before = 0.5 * np.arctan2(m[..., 2], m[..., 1])
    return m @ _nominal_gauge(m, alpha0, free).T, before, strength


def calibrate_session(counts, yaw, valid, array, *, n_bins: int = 120, n_harmonics: int = 12,
                      iterations: int = 40, symmetric: bool = True) -> SessionCalibration:
    """Fit photodiode gains and polarizer offsets to one session (see the module docstring).

    Alternating least squares on the yaw-binned counts: the ring ``S(theta) = (I, I q, I u)`` given
    the channel vectors ``m_kp = (g/2) (1, eta cos 2 alpha, eta sin 2 alpha)``, then each channel's
    ``m_kp`` given the ring (both linear, weights ``1 / c^2``: relative errors). The fixed point is
    defined up to a 3 x 3 gauge ``S -> A S, m -> A^-T m``; it is fixed by making the channels as
    nominal as possible as a whole (:func:`_nominal_gauge`: mean gain, mean angle, mean efficiency
    and any gain pattern common to all units take their nominal values), then the common angle by
    the mirror symmetry (``symmetric=True``).

    Parameters
    ----------
    counts : ndarray, shape ``(N, K, P)``
        Photodiode counts of one session (the sky steady throughout).
    yaw : ndarray, shape ``(N,)``
        Rotation of the sensor, radians CCW (any zero); should cover the full turn.
    valid : ndarray of bool, shape ``(N, K)``
        Usable readings (faulty units all False).
    array : PolArray
        Nominal geometry (unit azimuths ``A_k``, polarizer angles ``alpha0_kp``).
    n_bins, n_harmonics : int
        Yaw bins and harmonics of the sky ring.
    iterations : int
        Alternating rounds.
    symmetric : bool
        Fix the common polarizer offset by the clear sky's mirror symmetry; False: mean offset 0.

    Returns
    -------
    SessionCalibration

    Raises
    ------
    UserError
        Fewer than two usable units.
    """
    c_all = np.asarray(counts, float)
    n, k, p = c_all.shape
    centres, y = bin_by_yaw(c_all, yaw, valid, n_bins=n_bins)
    filled = np.isfinite(y).all(axis=-1)  # (B, K)
    fitted = filled.mean(axis=0) >= 0.5
    if fitted.sum() < 2:
        raise UserError(
            f"Self-calibration needs at least two units usable over half the turn; this session has {int(fitted.sum())}. "
            "Calibrate from daylight rotations covering a full turn."
        )
    units = np.flatnonzero(fitted)
    alpha0 = array.polarizer_angles[units]  # (ku, P)
    c = np.exp(y[:, units])  # (B, ku, P), NaN where empty
    w = np.where(np.isfinite(c), 1.0 / np.where(np.isfinite(c), c, 1.0) ** 2, 0.0)
    c = np.nan_to_num(c)
    theta = centres[:, None] + array.unit_azimuths[units][None, :]
    f = _basis(theta, n_harmonics)  # (B, ku, nb)
    scale = np.sum(w * c, axis=0) / np.maximum(np.sum(w, axis=0), 1e-300)  # (ku, P)
    m = 0.5 * scale[..., None] * np.stack([np.ones_like(alpha0), np.cos(2 * alpha0), np.sin(2 * alpha0)], axis=-1)
    for _ in range(iterations):
        ring = _ring_fit(m, c, w, f)  # (3, nb)
        stokes = f @ ring.T  # (B, ku, 3)
        m = _channel_fit(stokes, c, w)
    stokes = f @ _ring_fit(m, c, w, f).T
    pred = np.einsum("kpi,bki->bkp", m, stokes)
    ok = w > 0
    rms = float(np.sqrt(np.mean((np.log(np.clip(pred[ok], 1e-300, None)) - np.log(c[ok])) ** 2)))
    m, before, strength = _fix_gauge(m, c, w, f, alpha0, n_harmonics=n_harmonics, symmetric=symmetric)
    gain = 2.0 * m[..., 0]
    angle = 0.5 * np.arctan2(m[..., 2], m[..., 1])
    lam = np.log(np.clip(np.abs(gain), 1e-300, None))
    lam = lam - lam.mean()
    log_gain = np.full((k, p), np.nan)
    offset = np.full((k, p), np.nan)
    log_gain[units] = lam
    offset[units] = wrap_axial(angle - alpha0)
    common = float(np.angle(np.mean(np.exp(2j * (angle - before)))) / 2.0)
    return SessionCalibration(log_gain, offset, np.where(fitted, 0.0, np.nan), fitted, common, strength, rms)


@dataclass(frozen=True)
class ArrayCalibration:
    """Per-channel constants of a POL-OP array, pooled over sessions.

    Attributes
    ----------
    gain : ndarray, shape ``(K, P)``
        Relative photodiode gains (counts are divided by them; geometric mean 1 over the calibrated
        channels); 1 where not calibrated.
    gain_log_sigma : ndarray, shape ``(K, P)``
        Standard error of ``log(gain)`` (natural log); NaN where not calibrated or from one session.
    angle_offset : ndarray, shape ``(K, P)``
        Polarizer angle offsets added to the nominal angles, radians (unit frame, same sense); 0 where
        not calibrated.
    angle_sigma : ndarray, shape ``(K, P)``
        Standard errors, radians.
    azimuth_offset : ndarray, shape ``(K,)``
        Unit pointing offsets added to the nominal unit azimuths, radians CCW (sensor frame).
    azimuth_sigma : ndarray, shape ``(K,)``
    calibrated : ndarray of bool, shape ``(K,)``
        Units with an estimate.
    n_sessions : ndarray of int, shape ``(K,)``
        Sessions each unit's estimate pools.
    sessions : list of str
        The sessions used.
    mount_tilt : ndarray, shape ``(2,)``, or None
        First-order tilt of the whole sensor (radians): the coefficients ``(a, b)`` of the heading
        deviation ``tan(h) (a cos phi + b sin phi)`` (``h`` the sun's elevation, ``phi`` its azimuth in
        the device frame, :mod:`bionav.polcompass.deviation`); the tilt is ``hypot(a, b)``. None: not
        estimated (``recordings.calibration_parts`` without ``tilt``).
    """

    gain: np.ndarray
    gain_log_sigma: np.ndarray
    angle_offset: np.ndarray
    angle_sigma: np.ndarray
    azimuth_offset: np.ndarray
    azimuth_sigma: np.ndarray
    calibrated: np.ndarray
    n_sessions: np.ndarray
    sessions: list = field(default_factory=list)
    mount_tilt: np.ndarray | None = None

    @property
    def shape(self) -> tuple:
        return tuple(self.gain.shape)

    def apply(self, array, *, gains: bool = True, angles: bool = True, azimuths: bool = True, solver: str = "pol_op"):
        """The calibrated array: nominal geometry plus the chosen parts of the calibration.

        Parameters
        ----------
        array : PolArray
            Nominal array with the same ``(K, P)``.
        gains, angles, azimuths : bool
            Which parts to apply.
        solver : {'pol_op', 'stokes'}
            ``pol_op`` keeps the POL-OP chain (eqs. 4.2-4.5: only each pair's gain ratio matters, and
            each POL-OP takes the mean orientation of its two polarizers, ``(alpha_a + alpha_b - 90 deg) / 2``);
            ``stokes`` reads every photodiode at its own calibrated angle by linear least squares.

        Returns
        -------
        PolArray
        """
        if array.polarizer_angles.shape != self.shape:
            raise UserError(
                f"The POL-OP calibration is for {self.shape[0]} units x {self.shape[1]} photodiodes but the recordings "
                f"have {array.n_units} x {array.n_photodiodes}; use a calibration made from this sensor."
            )
        g = array.gains * (self.gain if gains else 1.0)
        pol = array.polarizer_angles + (self.angle_offset if angles else 0.0)
        az = array.unit_azimuths + (self.azimuth_offset if azimuths else 0.0)
        if solver == "pol_op":
            pol = pol.copy()
            for a, b in array.pairs:
                mean = 0.5 * np.angle(np.exp(2j * pol[:, a]) + np.exp(2j * (pol[:, b] - np.pi / 2.0)))
                pol[:, a] = array.polarizer_angles[:, a] + wrap_axial(mean - array.polarizer_angles[:, a])
                pol[:, b] = pol[:, a] + np.pi / 2.0
        return replace(array, unit_azimuths=az, polarizer_angles=pol, gains=g, solver=solver)

    def to_dict(self) -> dict:
        """JSON-ready form (schema ``bionav.pol_array_calibration/1``, degrees; see docs/polcompass.md)."""

        def num(a, scale=1.0):
            a = np.asarray(a, float) * scale
            return [num(r, 1.0) for r in a] if a.ndim > 1 else [None if not np.isfinite(v) else float(v) for v in a]

        out = {
            "schema": SCHEMA,
            "units": int(self.shape[0]),
            "photodiodes": int(self.shape[1]),
            "conventions": "gain: relative photodiode sensitivity (counts are divided by it); angle_offset_deg: added "
                           "to the nominal polarizer angle in the unit frame; azimuth_offset_deg: added to the unit "
                           "azimuth (CCW, sensor frame); *_sigma: standard errors (gain_log_sigma in natural log).",
            "gain": num(self.gain),
            "gain_log_sigma": num(self.gain_log_sigma),
            "angle_offset_deg": num(self.angle_offset, 180.0 / np.pi),
            "angle_sigma_deg": num(self.angle_sigma, 180.0 / np.pi),
            "azimuth_offset_deg": num(self.azimuth_offset, 180.0 / np.pi),
            "azimuth_sigma_deg": num(self.azimuth_sigma, 180.0 / np.pi),
            "calibrated_units": [int(u) for u in np.flatnonzero(self.calibrated)],
            "n_sessions": [int(v) for v in self.n_sessions],
            "sessions": list(self.sessions),
        }
        if self.mount_tilt is not None:  # only when estimated: files without it stay as they were
            out["mount_tilt_deg"] = num(self.mount_tilt, 180.0 / np.pi)
            out["mount_tilt_conventions"] = ("heading deviation tan(sun elevation) (a cos phi + b sin phi), phi the "
                                             "sun's azimuth in the device frame; [a, b] in degrees, subtracted from "
                                             "the decoded heading; the sensor's tilt is hypot(a, b) to first order.")
        return out

    @classmethod
    def from_dict(cls, data: dict, *, source: str = "The calibration",
                  fix: str = "Recalibrate with recordings.calibration=auto.") -> "ArrayCalibration":
        """Inverse of :meth:`to_dict`; every field checked (:data:`FIELD_RANGES`, shapes, unit indices), a
        :class:`UserError` naming ``source``, the field and its allowed values otherwise."""
        from bionav.datafile import FileFields

        if not isinstance(data, dict) or data.get("schema") != SCHEMA:
            raise UserError(
                f"{source} is not a POL-OP array calibration (it needs \"schema\": \"{SCHEMA}\"); write one with "
                "experiment=pol_recordings recordings.calibration=auto (calibration.json in the run folder)."
            )
        f = FileFields(data, source=source, fix=fix)
        k = f.number("units", valid=FIELD_RANGES["units"], integer=True)
        p = f.number("photodiodes", valid=FIELD_RANGES["photodiodes"], integer=True)
        rad = np.pi / 180.0

        def arr(key, shape, fill):
            return f.array(key, shape=shape, valid=FIELD_RANGES[key], none=fill)

        calibrated = np.zeros(k, bool)
        calibrated[f.indices("calibrated_units", size=k)] = True
        n_sessions = f.array("n_sessions", shape=(k,), valid=FIELD_RANGES["n_sessions"], integer=True, optional=True,
                             default=np.zeros(k, np.int64))
        if not isinstance(sessions := data.get("sessions", []), list) or not all(isinstance(v, str) for v in sessions):
            f.fail("sessions", "is not a list of session names", "a list of strings")
        tilt = None if data.get("mount_tilt_deg") is None else f.array(
            "mount_tilt_deg", shape=(2,), valid=FIELD_RANGES["mount_tilt_deg"]) * rad
        return cls(arr("gain", (k, p), 1.0), arr("gain_log_sigma", (k, p), np.nan),
                   arr("angle_offset_deg", (k, p), 0.0) * rad, arr("angle_sigma_deg", (k, p), np.nan) * rad,
                   arr("azimuth_offset_deg", (k,), 0.0) * rad, arr("azimuth_sigma_deg", (k,), np.nan) * rad,
                   calibrated, n_sessions, list(sessions), tilt)

    @classmethod
    def load(cls, path) -> "ArrayCalibration":
        """Read a calibration file written by :meth:`save` (size-capped, every field checked)."""
        from bionav.datafile import read_user_json
        from bionav.files import user_path

        fix = ("Point recordings.calibration at a calibration.json written by experiment=pol_recordings, or use "
               "recordings.calibration=auto or none.")
        data = read_user_json(path, what="The POL-OP calibration", fix=fix, kind="calibration")
        return cls.from_dict(data, source=f"The POL-OP calibration {user_path(path)}", fix=fix)

    def save(self, path) -> None:
        """Write the calibration as JSON."""
        Path(path).write_text(json.dumps(self.to_dict(), indent=2))


def combine_sessions(estimates, names=None) -> ArrayCalibration:
    """Pool per-session estimates into one :class:`ArrayCalibration` (robustly).

    Gains: ``log g_skp = log g_kp + o_s`` (one gauge ``o_s`` per session, because each session's
    gains are relative to its own fitted units), solved by alternating medians; angle offsets:
    medians over sessions (a session whose symmetry gauge failed, e.g. with the sun near the zenith,
    does not move them). Standard errors: ``1.4826 MAD / sqrt(n)`` over the sessions.

    Parameters
    ----------
    estimates : list of SessionCalibration
    names : list of str, optional

    Returns
    -------
    ArrayCalibration
    """
    if not estimates:
        raise UserError("No session could be used for the self-calibration (it needs daylight rotations with two or "
                        "more healthy units); use recordings.calibration=none or a calibration file.")
    lg = np.stack([e.log_gain for e in estimates])  # (S, K, P)
    an = np.stack([e.angle_offset for e in estimates])
    az = np.stack([e.azimuth_offset for e in estimates])
    has = np.isfinite(lg)
    n = has.sum(axis=0)
    any_has = n > 0
    offsets = np.zeros(len(estimates))
    g = np.zeros(lg.shape[1:])
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN slices: units no session calibrated
        for _ in range(20):
            g = np.where(any_has, np.nanmedian(lg - offsets[:, None, None], axis=0), 0.0)
            g = g - np.mean(g[any_has])
            offsets = np.array([np.median((lg[i] - g)[has[i]]) if has[i].any() else 0.0 for i in range(len(estimates))])
        angle = np.where(any_has, np.nanmedian(an, axis=0), 0.0)
        nk = np.isfinite(az).sum(axis=0)
        azim = np.where(nk > 0, np.nanmedian(az, axis=0), 0.0)

        def sem(v, centre, count):
            mad = np.nanmedian(np.abs(v - centre), axis=0)
            return np.where(count > 1, 1.4826 * mad / np.sqrt(np.maximum(count, 1)), np.nan)

        out = ArrayCalibration(np.where(any_has, np.exp(g), 1.0), sem(lg - offsets[:, None, None], g, n), angle,
                               sem(an, angle, n), azim, sem(az, azim, nk), nk > 0, nk.astype(int),
                               list(names) if names is not None else [])
    return out
