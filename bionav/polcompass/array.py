"""One sensor chain for any POL-OP array: photodiode counts to e-vectors to the sun.

A *POL-OP array* is ``K`` units; unit ``k`` looks at the sky along the
direction with azimuth ``unit_azimuths[k]`` (radians, counter-clockwise seen
from above, in the *sensor frame* whose azimuth 0 is the robot's front) and
zenith angle ``unit_tilts[k]``. Each unit carries ``P`` photodiodes behind
linear polarizers at ``polarizer_angles[k, p]`` in the *unit frame*:
:func:`bionav.polcompass.optics.sensor_frame` with heading = unit azimuth and
tilt = unit tilt, i.e. ``x_u`` points away from the zenith along the unit's
meridian (for a zenith unit: towards the sensor front), ``y_u`` along
increasing azimuth, angles from ``x_u`` towards ``y_u``. Two photodiodes with
orthogonal polarizers form one POL-OP (``pairs``). The thesis' compass
(chapter 4) is three zenith units with one POL-OP each at 0, 60 and 120
degrees (:meth:`PolArray.thesis`); the recorded compass of Gkanias et al.
(2023, doi:10.1038/s44172-023-00132-w) is a fan of eight units tilted 45
degrees with four photodiodes each, i.e. two POL-OPs at 45 degrees to each
other (:meth:`PolArray.fan8`).

The chain (all vectorised over samples):

1. :func:`log_ratios_from_counts`: per POL-OP ``p = log10(s_a / s_b)``
   (thesis eq. 4.2, with ``s = K I (1 + d cos(2 phi - 2 alpha))``, eq. 4.1);
2. :func:`bionav.polcompass.compass.delogarithmise` (eq. 4.3):
   ``x = 1 - 2 / (1 + 10^p) = d cos(2 a - 2 alpha_a)``;
3. :func:`evectors_from_counts`: the e-vector angle ``a`` and degree ``d`` of
   each unit from its POL-OPs (eqs. 4.4-4.5 for two POL-OPs, least squares
   for more) and the e-vector as a 3-D unit vector in the sensor frame;
4. decoders (:mod:`bionav.polcompass.decoders`) turn the e-vectors of the
   units read at one moment into the solar azimuth in the sensor frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.geometry import wrap_axial
from bionav.polcompass.compass import delogarithmise, least_squares_evector
from bionav.polcompass.optics import sensor_frame


@dataclass(frozen=True)
class PolArray:
    """Geometry of a POL-OP array.

    Attributes
    ----------
    unit_azimuths : ndarray, shape ``(K,)``
        Viewing azimuth of each unit, radians CCW from the sensor front.
    unit_tilts : ndarray, shape ``(K,)``
        Zenith angle of each unit's optical axis, radians (0 = zenith).
    polarizer_angles : ndarray, shape ``(K, P)``
        Transmission axis of each photodiode's polarizer in its unit frame,
        radians (see the module docstring).
    pairs : ndarray of int, shape ``(J, 2)``
        Photodiode indices ``(a, b)`` of each POL-OP (orthogonal polarizers);
        its output is ``log10(s_a / s_b)``.
    gains : ndarray, shape ``(K, P)``
        Relative photodiode sensitivities (counts are divided by them).
    solver : {'pol_op', 'stokes'}
        How :func:`evectors_from_counts` reads a unit: ``pol_op`` from the POL-OPs' log ratios
        (eqs. 4.2-4.5, orthogonal pairs assumed); ``stokes`` from all photodiodes at once by linear
        least squares on ``s_p / g_p = I (1 + q cos 2 alpha_p + u sin 2 alpha_p) / 2`` (any
        polarizer angles, e.g. calibrated ones: :mod:`bionav.polcompass.array_calibration`).
    """

    unit_azimuths: np.ndarray
    unit_tilts: np.ndarray
    polarizer_angles: np.ndarray
    pairs: np.ndarray
    gains: np.ndarray | None = None
    solver: str = "pol_op"

    def __post_init__(self):
        az = np.atleast_1d(np.asarray(self.unit_azimuths, float))
        tilt = np.broadcast_to(np.asarray(self.unit_tilts, float), az.shape).copy()
        pol = np.asarray(self.polarizer_angles, float)
        if pol.ndim == 1:
            pol = np.broadcast_to(pol, (az.size, pol.size)).copy()
        pairs = np.atleast_2d(np.asarray(self.pairs, int))
        if pol.shape[0] != az.size:
            raise ValueError(f"polarizer_angles has {pol.shape[0]} rows for {az.size} units")
        if pairs.shape[1] != 2 or pairs.min() < 0 or pairs.max() >= pol.shape[1]:
            raise ValueError(f"pairs must be (J, 2) photodiode indices below {pol.shape[1]}, got {pairs.tolist()}")
        if self.solver not in ("pol_op", "stokes"):
            raise ValueError(f"solver must be 'pol_op' or 'stokes', got {self.solver!r}")
        gains = np.ones_like(pol) if self.gains is None else np.broadcast_to(np.asarray(self.gains, float), pol.shape).copy()
        object.__setattr__(self, "unit_azimuths", az)
        object.__setattr__(self, "unit_tilts", tilt)
        object.__setattr__(self, "polarizer_angles", pol)
        object.__setattr__(self, "pairs", pairs)
        object.__setattr__(self, "gains", gains)

    @property
    def n_units(self) -> int:
        return int(self.unit_azimuths.size)

    @property
    def n_photodiodes(self) -> int:
        return int(self.polarizer_angles.shape[1])

    @property
    def pair_angles(self) -> np.ndarray:
        """Angle ``alpha_a`` of each POL-OP's first polarizer, shape ``(K, J)``."""
        return self.polarizer_angles[:, self.pairs[:, 0]]

    def unit_frames(self) -> np.ndarray:
        """Unit frames in the sensor frame, shape ``(K, 3, 3)``: columns ``x_u, y_u, z_u`` (view)."""
        return sensor_frame(self.unit_azimuths, self.unit_tilts)

    def subset(self, units) -> "PolArray":
        """The array made of some units only (indices or a boolean mask)."""
        idx = np.arange(self.n_units)[np.asarray(units)]
        return PolArray(self.unit_azimuths[idx], self.unit_tilts[idx], self.polarizer_angles[idx], self.pairs, self.gains[idx],
                        self.solver)

    @classmethod
    def thesis(cls, unit_angles_deg=(0.0, 60.0, 120.0)) -> "PolArray":
        """The thesis' compass: zenith units, one POL-OP (polarizers ``alpha``, ``alpha + 90``) each."""
        alpha = np.deg2rad(np.asarray(unit_angles_deg, float))
        k = alpha.size
        return cls(np.zeros(k), np.zeros(k), np.stack([alpha, alpha + np.pi / 2.0], axis=1), [[0, 1]])

    @classmethod
    def fan(
        cls,
        unit_azimuths_deg,
        *,
        tilt_deg: float = 45.0,
        photodiode_angles_deg=(-45.0, 45.0, 0.0, 90.0),
        pairs=((2, 3), (1, 0)),
    ) -> "PolArray":
        """A fan of tilted units with the same photodiode layout."""
        az = np.deg2rad(np.asarray(unit_azimuths_deg, float))
        pol = np.deg2rad(np.asarray(photodiode_angles_deg, float))
        return cls(az, np.full(az.size, np.deg2rad(tilt_deg)), np.broadcast_to(pol, (az.size, pol.size)), pairs)

    @classmethod
    def fan8(cls) -> "PolArray":
        """The 8-unit fan of Gkanias et al. (2023) as recorded in its JSON files.

        The files list unit azimuths 0, 90, 180, 270, 45, 135, 225, 315 degrees
        *clockwise* from the robot's front and the four counts of a unit in the
        polarizer order 135, 45, 90, 0 degrees, with 0 along the horizontal
        and angles growing towards the zenith side; in this module's frames
        (CCW azimuths, ``x_u`` away from the zenith) that is azimuths ``-A``
        and photodiode angles ``90 - (135, 45, 90, 0) = (-45, 45, 0, 90)``.
        These conventions were checked against the recordings (the clear-sky
        Rayleigh pattern fits them, and only them, with mean resultant 0.86-0.90
        of the e-vector residuals; see docs/polcompass.md).
        """
        return cls.fan(-np.array([0.0, 90.0, 180.0, 270.0, 45.0, 135.0, 225.0, 315.0]))


def log_ratios_from_counts(counts, array: PolArray):
    """POL-OP log ratios ``p = log10(s_a / s_b)`` (thesis eq. 4.2), in decades.

    Parameters
    ----------
    counts : ndarray, shape ``(..., K, P)``
        Photodiode readings (proportional to the light through each
        polarizer), divided by :attr:`PolArray.gains`.
    array : PolArray

    Returns
    -------
    ndarray, shape ``(..., K, J)``
        ``NaN`` where a count is not positive.
    """
    s = np.asarray(counts, float) / array.gains
    with np.errstate(divide="ignore", invalid="ignore"):
        a = s[..., array.pairs[:, 0]]
        b = s[..., array.pairs[:, 1]]
        p = np.log10(a / b)
    return np.where((a > 0) & (b > 0), p, np.nan)


@dataclass(frozen=True)
class UnitEvectors:
    """E-vectors measured by every unit of an array.

    Attributes
    ----------
    x : ndarray, shape ``(N, K, J)``
        Delogarithmised POL-OP outputs (eq. 4.3).
    angle : ndarray, shape ``(N, K)``
        E-vector angle in each unit frame, radians ``[-pi/2, pi/2)``.
    degree : ndarray, shape ``(N, K)``
        Measured degree of polarization (times the polarizer efficiency).
    intensity : ndarray, shape ``(N, K)``
        Mean photodiode reading of each unit.
    evector : ndarray, shape ``(N, K, 3)``
        E-vector as a unit vector in the sensor frame (axial).
    pair_total : ndarray, shape ``(N, K, J)``, optional
        Light through each POL-OP, ``s_a + s_b`` (counts divided by the gains): its count-noise scale.
    pol_op_valid : ndarray of bool, shape ``(N, K, J)``, optional
        Which POL-OPs read usable counts (:func:`masked_pol_ops`: no saturated, overflowing or dark
        photodiode, unit not faulty), so that a unit with one good POL-OP still gives
        ``x = d cos(2a - 2 alpha)`` (:func:`bionav.polcompass.decoders.sun_from_pol_op_fit`). ``None``
        (not checked): only the POL-OPs of the units a decoder's ``valid`` mask keeps are used.
    """

    x: np.ndarray
    angle: np.ndarray
    degree: np.ndarray
    intensity: np.ndarray
    evector: np.ndarray
    pair_total: np.ndarray | None = None
    pol_op_valid: np.ndarray | None = None

    def rows(self, index) -> "UnitEvectors":
        """The samples ``index`` (an integer index or boolean mask over ``N``) of every field."""
        pt = None if self.pair_total is None else self.pair_total[index]
        ok = None if self.pol_op_valid is None else self.pol_op_valid[index]
        return UnitEvectors(self.x[index], self.angle[index], self.degree[index], self.intensity[index],
                            self.evector[index], pt, ok)


def stokes_evector(counts, array: PolArray):
    """E-vector angle and degree of each unit from all its photodiodes (``solver="stokes"``).

    ``s_p / g_p = (I / 2) (1 + q cos 2 alpha_p + u sin 2 alpha_p)`` is linear in ``(I, I q, I u)``;
    three or more polarizer angles give it by least squares (exactly the POL-OP result for two
    ideal orthogonal pairs with equal pair totals).

    Parameters
    ----------
    counts : ndarray, shape ``(..., K, P)``
    array : PolArray

    Returns
    -------
    angle, degree : ndarray, shape ``(..., K)``
        Radians ``[-pi/2, pi/2)`` in the unit frame; NaN where a count is not positive or the intensity is.
    """
    s = np.asarray(counts, float) / array.gains
    a2 = 2.0 * array.polarizer_angles
    design = 0.5 * np.stack([np.ones_like(a2), np.cos(a2), np.sin(a2)], axis=-1)  # (K, P, 3)
    pinv = np.linalg.pinv(design)  # (K, 3, P)
    sol = np.einsum("kip,...kp->...ki", pinv, s)
    with np.errstate(divide="ignore", invalid="ignore"):
        q = sol[..., 1] / sol[..., 0]
        u = sol[..., 2] / sol[..., 0]
    bad = ~(np.all(s > 0, axis=-1) & (sol[..., 0] > 0))
    return (np.where(bad, np.nan, wrap_axial(0.5 * np.arctan2(u, q))), np.where(bad, np.nan, np.hypot(q, u)))


def view_groups(array: PolArray) -> list[list[int]]:
    """Units sharing one unit frame (same view and same polarizer reference), in order of first appearance."""
    frames = np.round(array.unit_frames().reshape(array.n_units, -1), 9)
    groups: dict = {}
    for k, key in enumerate(map(tuple, frames)):
        groups.setdefault(key, []).append(k)
    return list(groups.values())


def evectors_from_counts(counts, array: PolArray) -> UnitEvectors:
    """Counts to per-unit e-vectors in the sensor frame (eqs. 4.2-4.5).

    Units that look at the same sky point in the same frame (the thesis'
    three zenith units) are solved together from all their POL-OPs; a unit
    with two or more POL-OPs of its own is solved alone.

    Parameters
    ----------
    counts : ndarray, shape ``(N, K, P)``
    array : PolArray

    Returns
    -------
    UnitEvectors
    """
    counts = np.asarray(counts, float)
    x = delogarithmise(log_ratios_from_counts(counts, array))
    frames = array.unit_frames()  # (K, 3, 3)
    groups = view_groups(array)
    if array.solver == "stokes":
        angle, degree = stokes_evector(counts, array)
    elif all(len(g) == 1 for g in groups):
        angle, degree = least_squares_evector(x, array.pair_angles)
    else:  # units looking at the same sky point (the thesis' zenith units) are solved together
        angle = np.empty(x.shape[:-1])
        degree = np.empty(x.shape[:-1])
        for g in groups:
            xs = x[..., g, :].reshape(x.shape[:-2] + (1, -1))
            a, d = least_squares_evector(xs, array.pair_angles[g].reshape(1, -1))
            angle[..., g] = a
            degree[..., g] = d
    evector = np.cos(angle)[..., None] * frames[:, :, 0] + np.sin(angle)[..., None] * frames[:, :, 1]
    s = counts / array.gains
    intensity = np.mean(s, axis=-1)
    return UnitEvectors(x, angle, degree, intensity, evector, s[..., array.pairs[:, 0]] + s[..., array.pairs[:, 1]])


def masked_pol_ops(ev: UnitEvectors, pol_op_valid, *, faulty_units=()) -> UnitEvectors:
    """The e-vectors with every unusable POL-OP's output ``x`` set to NaN (a fault mask per POL-OP, not per unit).

    Parameters
    ----------
    ev : UnitEvectors
    pol_op_valid : ndarray of bool, shape ``(N, K, J)``
        Whether both photodiodes of each POL-OP read usable counts at each sample
        (:func:`bionav.polcompass.recordings.pol_op_validity`).
    faulty_units : sequence of int
        Units dropped for the whole session (blind, a bad photodiode): every reading of theirs, the
        intensity included, becomes NaN.

    Returns
    -------
    UnitEvectors
        Angles, degrees and e-vectors unchanged (a decoder's per-unit ``valid`` mask still says which
        units read both POL-OPs); ``x`` NaN and :attr:`UnitEvectors.pol_op_valid` false where
        ``pol_op_valid`` is false or the unit is faulty.
    """
    units = np.zeros(np.shape(ev.x)[-2], bool)
    units[list(faulty_units)] = True
    ok = np.asarray(pol_op_valid, bool) & ~units[:, None] & np.isfinite(ev.x)
    x = np.where(ok, ev.x, np.nan)
    intensity = np.where(units, np.nan, ev.intensity)
    return UnitEvectors(x, ev.angle, ev.degree, intensity, ev.evector, ev.pair_total, ok)


def counts_from_stokes(intensity, q, u, array: PolArray, *, efficiency: float = 1.0):
    """Ideal photodiode readings for given per-unit Stokes parameters (eq. 4.1, ``K = 1/2``).

    Parameters
    ----------
    intensity, q, u : ndarray, shape ``(..., K)``
        Radiance and normalised Stokes ``Q/I``, ``U/I`` in each unit frame.
    array : PolArray
    efficiency : float
        Polarizer efficiency.

    Returns
    -------
    ndarray, shape ``(..., K, P)``
        ``I (1 + eta (q cos 2alpha + u sin 2alpha)) / 2`` times the gains.
    """
    alpha = array.polarizer_angles
    i = np.asarray(intensity, float)[..., None]
    q = np.asarray(q, float)[..., None]
    u = np.asarray(u, float)[..., None]
    return array.gains * i * (1.0 + efficiency * (q * np.cos(2 * alpha) + u * np.sin(2 * alpha))) / 2.0


def unit_views(array: PolArray, heading=0.0):
    """Viewing directions of the units in the sky frame for sensor headings.

    Parameters
    ----------
    heading : float or ndarray, shape ``S``
        Sensor heading(s), radians CCW from east.

    Returns
    -------
    frames : ndarray, shape ``S + (K, 3, 3)``
        Unit frames (columns ``x_u, y_u, view``) in the sky frame.
    """
    h = np.asarray(heading, float)[..., None]
    return sensor_frame(h + array.unit_azimuths, array.unit_tilts)


def stokes_from_sky(source, array: PolArray, heading=0.0):
    """Radiance and normalised Stokes parameters each unit sees (point optics).

    Parameters
    ----------
    source : object with ``light(view) -> SkyLight``
        A :class:`bionav.light.SkyModel`.
    array : PolArray
    heading : float or ndarray, shape ``S``
        Sensor heading(s), radians CCW from east.

    Returns
    -------
    intensity, q, u : ndarray, shape ``S + (K,)``
    """
    frames = unit_views(array, heading)
    view = frames[..., :, 2]
    light = source.light(view)
    ex = np.sum(light.evector * frames[..., :, 0], axis=-1)
    ey = np.sum(light.evector * frames[..., :, 1], axis=-1)
    a2 = 2.0 * np.arctan2(ey, ex)
    return light.radiance, light.degree * np.cos(a2), light.degree * np.sin(a2)
