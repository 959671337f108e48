"""Parameter homing: descent in the distance of image parameter signatures.

Thesis section 5.2 and appendix C (after Fischer 2006); the matched-filter
gradient follows Möller, R. & Vardy, A. (2006), Local visual homing by
matched-filter descent in image distances, *Biological Cybernetics* 95,
413-430, doi:10.1007/s00422-006-0095-3.

The potential of a current view ``C`` with respect to a snapshot ``S`` is the
squared Euclidean distance of their signatures (eq. 5.17)::

    p = sum_i (f_i(S) - f_i(C))**2

and the home vector its negative spatial gradient (eq. 5.18). Two estimators:

* :func:`gradient_from_test_steps` -- finite differences of ``p`` over the images of
  neighbouring positions (eq. 5.19, the explorative test steps).
* :func:`matched_filter_gradient` -- chain rule with the signature's derivative
  along the flow-template image derivatives (predicted images, no test steps);
  :func:`mffc_phase_home_vector` and :func:`mffc_abs_home_vector` are the
  closed forms of eqs. C.9 and C.11.

All vectors are in the current view's own frame (``x`` along its heading,
``y`` to its left, angles counter-clockwise in radians).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np


def parameter_potential(f_snapshot: np.ndarray, f_current: np.ndarray) -> float:
    """Potential ``p = sum_i (f_i(S) - f_i(C))**2`` (thesis eq. 5.17).

    Parameters
    ----------
    f_snapshot, f_current : ndarray, shape (L,)
        Signature vectors of snapshot and current view.

    Returns
    -------
    float
    """
    d = np.asarray(f_current, dtype=np.float64) - np.asarray(f_snapshot, dtype=np.float64)
    return float(d @ d)


def gradient_from_test_steps(
    p_center: float, neighbour_potentials: Mapping[tuple[float, float], float]
) -> np.ndarray:
    """Gradient of the potential from test steps to neighbouring positions (eq. 5.19).

    The gradient ``g`` is the least-squares fit of ``p(x + d) - p(x) = d . g``
    over the available offsets ``d``. For the grid's axis-aligned unit steps
    this is exactly:

    * the central difference ``(p(x+1) - p(x-1)) / 2`` along an axis where both
      neighbours exist,
    * the one-sided difference of eq. 5.19, ``p(x+1) - p(x)`` or
      ``p(x) - p(x-1)``, where only one exists,
    * 0 along an axis without any neighbour (no information; the
      minimum-norm least-squares solution).

    Parameters
    ----------
    p_center : float
        Potential at the current position.
    neighbour_potentials : mapping
        ``{(dx, dy): p}`` for the neighbours that exist, offsets in grid units in
        the current view's frame.

    Returns
    -------
    ndarray, shape (2,)
        ``(dp/dx, dp/dy)`` per grid unit; NaN when there is no neighbour at all.
    """
    if not neighbour_potentials:
        return np.full(2, np.nan)
    offsets = np.array([tuple(map(float, d)) for d in neighbour_potentials], dtype=np.float64).reshape(-1, 2)
    dp = np.array(list(neighbour_potentials.values()), dtype=np.float64) - float(p_center)
    return np.linalg.lstsq(offsets, dp, rcond=None)[0]


def matched_filter_gradient(
    f_snapshot: np.ndarray, f_current: np.ndarray, df_dx: np.ndarray, df_dy: np.ndarray
) -> np.ndarray:
    """Gradient of ``p / 2`` from the signature's spatial derivatives (chain rule).

    ``grad(p / 2) = sum_i (f_i(C) - f_i(S)) grad f_i(C)``, with ``grad f(C)``
    estimated on the matched filter's predicted images
    (:meth:`bionav.homing.signatures.base.Signature.derivative` along
    :func:`bionav.homing.flow_templates.translation_derivatives`).

    Parameters
    ----------
    f_snapshot, f_current : ndarray, shape (L,)
    df_dx, df_dy : ndarray, shape (L,)
        Derivatives of the current view's signature for unit moves along ``x`` and ``y``.

    Returns
    -------
    ndarray, shape (2,)
        ``(dp/dx, dp/dy) / 2``; the home vector is its negative.
    """
    d = np.asarray(f_current, dtype=np.float64) - np.asarray(f_snapshot, dtype=np.float64)
    return np.array([d @ df_dx, d @ df_dy])


def mffc_phase_home_vector(
    spec_snapshot: np.ndarray, spec_current: np.ndarray, spec_phi: np.ndarray, spec_psi: np.ndarray
) -> np.ndarray:
    """Home vector of [mffc_phase], thesis eq. C.9.

    ``h = -sum_j sum_k [Re F_k(Phi_j), Re F_k(Psi_j)] Re(F_k(C_j) - F_k(S_j))
    + [Im F_k(Phi_j), Im F_k(Psi_j)] Im(F_k(C_j) - F_k(S_j))``.

    Parameters
    ----------
    spec_snapshot, spec_current : ndarray, shape (H, K), complex
        Row spectra ``F_k(S_j)``, ``F_k(C_j)``
        (:func:`bionav.homing.signatures.fourier.row_spectrum`).
    spec_phi, spec_psi : ndarray, shape (H, K), complex
        Row spectra of the flow-template derivatives ``Phi = dC/dx``, ``Psi = dC/dy`` (eq. C.6).

    Returns
    -------
    ndarray, shape (2,)
        Home vector in the current view's frame (unnormalised).
    """
    d = spec_current - spec_snapshot
    hx = np.sum(spec_phi.real * d.real + spec_phi.imag * d.imag)
    hy = np.sum(spec_psi.real * d.real + spec_psi.imag * d.imag)
    return -np.array([hx, hy])


def mffc_abs_home_vector(
    spec_snapshot: np.ndarray, spec_current: np.ndarray, spec_phi: np.ndarray, spec_psi: np.ndarray
) -> np.ndarray:
    """Home vector of [mffc_abs], thesis eq. C.11 (Möller & Vardy 2006).

    ``h = -sum_j sum_k |F_k(C_j)|^-1 A_jk (|F_k(C_j)| - |F_k(S_j)|)`` with
    ``A_jk = [Re F_k(Phi_j) Re F_k(C_j) + Im F_k(Phi_j) Im F_k(C_j), (same with Psi)]``.
    Terms with ``|F_k(C_j)| = 0`` are left out.

    Parameters
    ----------
    spec_snapshot, spec_current, spec_phi, spec_psi : ndarray, shape (H, K), complex
        As in :func:`mffc_phase_home_vector`.

    Returns
    -------
    ndarray, shape (2,)
    """
    amp_c = np.abs(spec_current)
    w = np.divide(amp_c - np.abs(spec_snapshot), amp_c, out=np.zeros_like(amp_c), where=amp_c > 0)
    ax = spec_phi.real * spec_current.real + spec_phi.imag * spec_current.imag
    ay = spec_psi.real * spec_current.real + spec_psi.imag * spec_current.imag
    return -np.array([np.sum(w * ax), np.sum(w * ay)])


# --- all pairs at once (grid evaluation) --------------------------------------------------------


def potential_matrix(f_snapshots: np.ndarray, f_currents: np.ndarray) -> np.ndarray:
    """Potentials (eq. 5.17) of every snapshot/current-view pair.

    Parameters
    ----------
    f_snapshots : ndarray, shape (S, L)
    f_currents : ndarray, shape (C, L)

    Returns
    -------
    ndarray, shape (S, C)
        ``P[s, c] = sum_i (f_i(S_s) - f_i(C_c))**2``.
    """
    from scipy.spatial.distance import cdist

    return cdist(np.asarray(f_snapshots, dtype=np.float64), np.asarray(f_currents, dtype=np.float64), "sqeuclidean")


def gradient_matrix_from_test_steps(potentials: np.ndarray, neighbours: np.ndarray) -> np.ndarray:
    """Test-step gradients (eq. 5.19) for every pair from a potential matrix.

    The same estimate as :func:`gradient_from_test_steps` for the grid's four
    axis-aligned unit neighbours: central differences where both neighbours
    along an axis exist, one-sided where one exists, 0 where none does, NaN for
    a cell without any neighbour.

    Parameters
    ----------
    potentials : ndarray, shape (..., S, C)
        :func:`potential_matrix` of the snapshots against *all* current views
        (leading axes: independent potentials, e.g. several configurations).
    neighbours : ndarray of int, shape (C, 4)
        Index (into the current views) of the neighbours at offsets
        ``(+1, 0), (-1, 0), (0, +1), (0, -1)``; -1 where missing.

    Returns
    -------
    ndarray, shape (..., S, C, 2)
        ``(dp/dx, dp/dy)`` per grid unit.
    """
    p = np.asarray(potentials, dtype=np.float64)
    nb = np.asarray(neighbours, dtype=np.int64)
    grad = np.zeros(p.shape + (2,))
    for axis, (plus, minus) in enumerate(((0, 1), (2, 3))):
        ip, im = nb[:, plus], nb[:, minus]
        has_p, has_m = ip >= 0, im >= 0
        pp = p[..., np.where(has_p, ip, 0)]
        pm = p[..., np.where(has_m, im, 0)]
        g = np.where(has_p & has_m, (pp - pm) / 2.0, np.where(has_p, pp - p, np.where(has_m, p - pm, 0.0)))
        grad[..., axis] = g
    grad[..., ~np.any(nb >= 0, axis=1), :] = np.nan
    return grad


def matched_filter_gradient_matrix(
    f_snapshots: np.ndarray, f_currents: np.ndarray, df_dx: np.ndarray, df_dy: np.ndarray
) -> np.ndarray:
    """:func:`matched_filter_gradient` for every snapshot/current-view pair.

    Parameters
    ----------
    f_snapshots : ndarray, shape (S, L)
    f_currents, df_dx, df_dy : ndarray, shape (C, L)

    Returns
    -------
    ndarray, shape (S, C, 2)
        ``sum_i (f_i(C) - f_i(S)) grad f_i(C)`` (the gradient of ``p / 2``).
    """
    fs = np.asarray(f_snapshots, dtype=np.float64)
    fc = np.asarray(f_currents, dtype=np.float64)
    out = np.empty((len(fs), len(fc), 2))
    for axis, d in enumerate((df_dx, df_dy)):
        d = np.asarray(d, dtype=np.float64)
        out[..., axis] = np.einsum("cl,cl->c", fc, d)[None, :] - fs @ d.T
    return out


# --- all numbers of Fourier coefficients at once (parameter sweep) -----------------------------


def _levels_index(n_coeffs, coeff_index: np.ndarray) -> np.ndarray:
    ks = np.asarray(n_coeffs, dtype=np.int64).ravel()
    k_max = int(coeff_index.max()) + 1 if coeff_index.size else 0
    if ks.size == 0 or ks.min() < 1 or ks.max() > k_max:
        raise ValueError(f"n_coeffs must lie in 1..{k_max} (the coefficients present), got {ks.tolist()}")
    return ks - 1


def _coefficient_blocks(coeff_index: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Column order grouping the entries by coefficient (stable) and the bounds of coefficients ``0 .. n-1``."""
    order = np.argsort(coeff_index, kind="stable")
    bounds = np.searchsorted(coeff_index[order], np.arange(n + 1), side="left")
    return order, bounds


def potential_matrices_by_coefficients(
    f_snapshots: np.ndarray, f_currents: np.ndarray, coeff_index: np.ndarray, n_coeffs
) -> np.ndarray:
    """:func:`potential_matrix` for several numbers ``K`` of Fourier coefficients from one signature.

    The potential of the first ``K`` coefficients is a partial sum over ``k``
    (eq. 5.17 / C.2): the squared distances of each coefficient's entries are
    computed once and summed cumulatively, so all ``K`` cost one potential.

    Parameters
    ----------
    f_snapshots : ndarray, shape (S, L)
    f_currents : ndarray, shape (C, L)
        Signatures with the largest ``K``.
    coeff_index : ndarray of int, shape (L,)
        Coefficient ``k`` of every signature entry (e.g.
        :meth:`bionav.plugins.signatures.fourier.FcAbs.coefficient_index`).
    n_coeffs : sequence of int, shape (N,)
        The numbers of coefficients ``K`` (entries with ``k < K`` are kept).

    Returns
    -------
    ndarray, shape (N, S, C)
        Equal to :func:`potential_matrix` of the signatures restricted to
        ``k < K`` up to the order of summation (float rounding).
    """
    from scipy.spatial.distance import cdist

    kidx = np.asarray(coeff_index, dtype=np.int64)
    levels = _levels_index(n_coeffs, kidx)
    order, bounds = _coefficient_blocks(kidx, int(levels.max()) + 1)
    fs = np.ascontiguousarray(np.asarray(f_snapshots, dtype=np.float64)[:, order])
    fc = fs if f_currents is f_snapshots else np.ascontiguousarray(np.asarray(f_currents, dtype=np.float64)[:, order])
    total = np.zeros((len(fs), len(fc)))
    out = np.empty((len(levels), len(fs), len(fc)))
    for k in range(len(bounds) - 1):
        lo, hi = bounds[k], bounds[k + 1]
        if hi > lo:
            total += cdist(fs[:, lo:hi], fc[:, lo:hi], "sqeuclidean")
        out[levels == k] = total
    return out


def matched_filter_gradient_matrices_by_coefficients(
    f_snapshots: np.ndarray,
    f_currents: np.ndarray,
    df_dx: np.ndarray,
    df_dy: np.ndarray,
    coeff_index: np.ndarray,
    n_coeffs,
) -> np.ndarray:
    """:func:`matched_filter_gradient_matrix` for several numbers ``K`` of Fourier coefficients.

    The gradient is a sum over the signature entries, so that of the first
    ``K`` coefficients is a partial sum over ``k`` (eqs. C.9, C.11).

    Parameters
    ----------
    f_snapshots : ndarray, shape (S, L)
    f_currents, df_dx, df_dy : ndarray, shape (C, L)
        Signatures and derivatives with the largest ``K``.
    coeff_index : ndarray of int, shape (L,)
    n_coeffs : sequence of int, shape (N,)

    Returns
    -------
    ndarray, shape (N, S, C, 2)
    """
    kidx = np.asarray(coeff_index, dtype=np.int64)
    levels = _levels_index(n_coeffs, kidx)
    order, bounds = _coefficient_blocks(kidx, int(levels.max()) + 1)
    fs, fc, dx, dy = (np.ascontiguousarray(np.asarray(a, dtype=np.float64)[:, order])
                      for a in (f_snapshots, f_currents, df_dx, df_dy))
    total = np.zeros((len(fs), len(fc), 2))
    out = np.empty((len(levels), len(fs), len(fc), 2))
    for k in range(len(bounds) - 1):
        lo, hi = bounds[k], bounds[k + 1]
        if hi > lo:
            total += matched_filter_gradient_matrix(fs[:, lo:hi], fc[:, lo:hi], dx[:, lo:hi], dy[:, lo:hi])
        out[levels == k] = total
    return out
