"""Min-warping and 2D-warping: the per-pair search over movement direction and rotation.

Conventions
-----------
* ``alpha``: direction of the movement from the snapshot position to the
  current position, in the snapshot's frame (radians CCW from the snapshot's
  column 0).
* ``psi``: rotation of the current view relative to the snapshot,
  ``heading(current) - heading(snapshot)`` (radians CCW). A current view that
  is the snapshot rolled by ``-n`` columns (``np.roll(snapshot, -n, axis=1)``)
  has ``psi = 2 pi n / W``.
* The home direction in the current view's own frame is
  ``alpha + pi - psi`` (wrapped to ``[-pi, pi)``).

Angles are searched on the grids ``alpha = 2 pi a / n_alpha`` and
``psi = 2 pi p / n_psi``, each rounded to whole columns of the panorama (the
search shifts columns, it does not interpolate between them). When ``W`` is a
multiple of ``n_alpha`` the fast kernels compute all alpha steps of one template
entry as one vector; otherwise they search every column and keep the grid.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field

import numpy as np

from bionav.geometry import wrap_angle
from bionav.homing.warping.distance import _scratch, diagonal_distances, distance_quantum
from bionav.homing.warping.kernels import (
    compass_measure,
    fill_window_minima,
    minwarp_scores,
    minwarp_scores_runs,
    swap_roles,
    warp2d_scores,
    warp2d_scores_at,
)
from bionav.homing.warping.pair import minwarp_pair_u8, n_selected, pair_inputs
from bionav.homing.warping.scaleplanes import check_scales
from bionav.homing.warping.templates import minwarp_template, minwarp_windows, warp2d_template
from bionav.homing.warping.vkernels import TABLE_PAD, minwarp_search_u8, padded_lanes, search_scratch_size


@dataclass(frozen=True)
class WarpingResult:
    """Outcome of a warping search.

    Attributes
    ----------
    home_angle : float
        Home direction (current position towards snapshot position) in the
        current view's own frame, radians CCW in ``[-pi, pi)``.
    psi : float
        Estimated rotation ``heading(current) - heading(snapshot)``, radians CCW
        in ``[-pi, pi)`` (the visual compass).
    alpha : float
        Estimated movement direction snapshot -> current in the snapshot's
        frame, radians in ``[0, 2 pi)``.
    rho : float
        Distance ratio ``d / r`` of the best match (equal-distance methods);
        NaN for min-warping.
    score : float
        Match value of the best parameters (lower is better).
    extras : dict
        Diagnostics (``n_psi_searched``, ...).
    """

    home_angle: float
    psi: float
    alpha: float
    rho: float
    score: float
    extras: dict = field(default_factory=dict)


def _column_grid(n_steps: int, width: int) -> np.ndarray:
    key = (int(n_steps), int(width))
    grid = _GRIDS.get(key)
    if grid is None:
        grid = _column_grid_new(*key)
        grid.flags.writeable = False
        _GRIDS[key] = grid
    return grid


_GRIDS: dict = {}


def _column_grid_new(n_steps: int, width: int) -> np.ndarray:
    if n_steps < 1:
        raise ValueError(f"the number of search steps must be >= 1, got {n_steps}")
    if n_steps > width:
        raise ValueError(
            f"{n_steps} search steps exceed the image width {width}: the search shifts whole "
            "columns, so use at most one step per column"
        )
    return np.rint(np.arange(n_steps) * width / n_steps).astype(np.int64) % width


def _layout_step(width: int, n_alpha: int, p_cols, double_search: bool) -> int:
    if width % n_alpha:
        return 1
    step = width // n_alpha
    if double_search and ((width // 2) % step or np.any(np.asarray(p_cols) % step)):
        return 1
    return step


#: Largest window level of the min-warping search (windows of up to 16 columns).
WINDOW_LEVEL = 4


_WORKSPACE = threading.local()


def _buffer(name, shape, dtype):
    """A per-thread array reused between calls (saves allocating and faulting in
    several MB per home vector); valid until the next call on the same thread."""
    cache = _WORKSPACE.__dict__.setdefault("arrays", {})
    arr = cache.get(name)
    if arr is None or arr.shape != shape or arr.dtype != dtype:
        arr = np.empty(shape, dtype=dtype)
        cache[name] = arr
    return arr


def _table(name, shape, dtype):
    """A per-thread window table of ``shape`` followed by :data:`~bionav.homing.warping.vkernels.TABLE_PAD`
    bytes (which the vector search reads past the last row); the table is a view of it."""
    size = int(np.prod(shape))
    flat = _buffer(name, (size * np.dtype(dtype).itemsize + TABLE_PAD,), np.dtype(np.uint8))
    return flat[:size * np.dtype(dtype).itemsize].view(dtype).reshape(shape)


def _padded(levels):
    """The padded 1-D buffer of a table from :func:`_table`, or None for any other array."""
    b = levels.base
    if (b is not None and b.ndim == 1 and b.dtype == np.uint8 and levels.dtype == np.uint8
            and b.ctypes.data == levels.ctypes.data and b.size >= levels.size + TABLE_PAD):
        return b
    return None


def _window_minima(snapshot, current, step, windows, quantised, name="levels"):
    """Column distances (level 0) and the sliding minima the windows read.

    The result is a per-thread buffer ``name`` (a view of a padded one, :func:`_table`).
    """
    n_levels = int(windows[2].max(initial=0)) + 1
    n_planes, _, width = np.shape(snapshot["snap"])
    dtype = np.dtype(np.uint8 if quantised else np.float32)
    levels = _table(name, (n_levels, n_planes, width, step, width // step), dtype)
    diagonal_distances(snapshot, current, step=step, out=levels[0], quantised=quantised)
    if n_levels > 1:
        fill_window_minima(levels)
    return levels


def _search(levels, n_a_eff, p_cols, windows, quantised):
    """Match values of every (psi, alpha step) in distance units (float64)."""
    width = levels.shape[2]
    if quantised:
        q, acc_dtype = distance_quantum(width)
        flat = _padded(levels)
        if acc_dtype == np.uint16 and flat is not None:
            # the vector search (same values) on the padded table of _table
            acc = _buffer("acc", (p_cols.size, padded_lanes(n_a_eff)), np.dtype(np.uint16))
            scratch = _buffer("scratch", (search_scratch_size(n_a_eff),), np.dtype(np.uint8))
            _, n_planes, _, step, _ = levels.shape
            minwarp_search_u8(flat, n_planes, width, step, n_a_eff, p_cols, *windows, acc, scratch)
            return acc[:, :n_a_eff].astype(np.float64)
        out = np.zeros((p_cols.size, n_a_eff), acc_dtype)
        minwarp_scores(levels, n_a_eff, p_cols, *windows, np.uint8(255), out)
    else:
        out = np.zeros((p_cols.size, n_a_eff), np.float32)
        minwarp_scores(levels, n_a_eff, p_cols, *windows, np.float32(np.inf), out)
    return out.astype(np.float64)


def _symmetric_scales(scales) -> bool:
    s = np.asarray(scales, dtype=np.float64)
    return bool(np.allclose(s * s[::-1], 1.0, rtol=1e-9, atol=0.0))


_SCALE_SETUPS: dict = {}


def _scale_setup(scales, thresholds):
    """``check_scales(scales, thresholds)`` and whether the scales are inversion
    symmetric, memoised by value (the search calls it once per pair)."""
    s = np.asarray(scales, dtype=np.float64)
    t = None if thresholds is None else np.asarray(thresholds, dtype=np.float64)
    key = (s.tobytes(), None if t is None else t.tobytes())
    setup = _SCALE_SETUPS.get(key)
    if setup is None:
        s, tau = check_scales(s, t)
        s.flags.writeable = False
        tau.flags.writeable = False
        setup = (s, tau, _symmetric_scales(s))
        if len(_SCALE_SETUPS) < 64:
            _SCALE_SETUPS[key] = setup
    return setup


def _select_psi(dist, p_cols, compass_fraction):
    n_sel = n_selected(p_cols.size, compass_fraction)
    if n_sel == p_cols.size:
        return p_cols
    measure = compass_measure(dist, p_cols)
    keep = np.sort(np.argsort(measure, kind="stable")[:n_sel])
    return p_cols[keep]


def _check_pair(snapshot, current):
    s1 = np.asarray(snapshot["scales"], dtype=np.float64)
    s2 = np.asarray(current["scales"], dtype=np.float64)
    if s1 is not s2 and (s1.shape != s2.shape or not (np.array_equal(s1, s2) or np.allclose(s1, s2))):
        raise ValueError("snapshot and current view were prepared with different scale factors")
    if np.shape(snapshot["snap"]) != np.shape(current["cur"]):
        raise ValueError(
            f"snapshot and current view stacks differ in shape: {np.shape(snapshot['snap'])} "
            f"vs {np.shape(current['cur'])}; prepare both at the same image size"
        )
    return s1


def minwarping_scores(
    snapshot,
    current,
    *,
    n_alpha=96,
    n_psi=96,
    thresholds=None,
    psi_cols=None,
    window_level=WINDOW_LEVEL,
    quantised=False,
):
    """Min-warping match values on the full (psi, alpha) grid (fast kernels).

    Parameters
    ----------
    snapshot, current : dict
        Scale-plane stacks (:func:`~bionav.homing.warping.scaleplanes.scale_plane_stack`).
    n_alpha, n_psi : int
        Search steps over 360 degrees.
    thresholds : array_like, shape (K,), optional
        Scale thresholds; default geometric midpoints.
    psi_cols : array_like of int, optional
        Rotations (columns) to search instead of the ``n_psi`` grid.
    window_level : int
        Largest window level of the sliding minima
        (:func:`~bionav.homing.warping.templates.minwarp_windows`); changes the
        speed, not the result.
    quantised : bool
        8-bit distances summed in 16 bits (the fast default of
        :func:`minwarping`); float32 NSAD otherwise.

    Returns
    -------
    a_cols : ndarray, shape (n_alpha,), int64
        Movement directions in columns.
    p_cols : ndarray, shape (P,), int64
        Rotations in columns.
    scores : ndarray, shape (P, n_alpha), float64
        ``scores[p, a] = sum over snapshot columns of the minimum NSAD over the
        reachable current columns and allowed planes`` (quantised: in units
        of ``1 / q``, :func:`~bionav.homing.warping.distance.distance_quantum`).
    """
    scales = _check_pair(snapshot, current)
    scales, tau, _ = _scale_setup(scales, thresholds)
    width = int(np.shape(snapshot["snap"])[-1])
    a_cols = _column_grid(n_alpha, width)
    p_cols = _column_grid(n_psi, width) if psi_cols is None else np.asarray(psi_cols, np.int64) % width
    step = _layout_step(width, n_alpha, p_cols, False)
    windows = minwarp_windows(minwarp_template(width, scales, tau), max_level=window_level)
    levels = _window_minima(snapshot, current, step, windows, quantised)
    scores = _search(levels, width // step, p_cols, windows, quantised)
    if quantised:
        scores /= distance_quantum(width)[0]
    return a_cols, p_cols, scores[:, a_cols // step]


def minwarping(
    snapshot,
    current,
    *,
    n_alpha: int = 96,
    n_psi: int = 96,
    thresholds=None,
    compass_fraction: float | None = None,
    fine_search: bool = False,
    double_search: bool = False,
    template=None,
    windows=None,
    quantised: bool = True,
) -> WarpingResult:
    """Min-warping home direction and visual compass of one image pair.

    Implements min-warping (Möller, Krzykawski & Gerstmayr 2010, "Three
    2D-warping schemes for visual robot navigation", Autonomous Robots 29,
    doi:10.1007/s10514-010-9195-y), the extension of 2D-warping (Möller 2009,
    doi:10.1016/j.robot.2008.05.005) that drops the equal-distance assumption:
    for every movement hypothesis ``(alpha, psi)`` each snapshot column is
    matched with its best current-view column among those it can reach, with
    the scale plane their positions imply (:func:`~bionav.homing.warping.
    templates.minwarp_template`); the hypothesis with the smallest sum of these
    minima wins. The minimum over a run of reachable columns that share a
    plane is read from sliding minima of the column distances (at most two
    reads per run; :func:`~bionav.homing.warping.templates.minwarp_windows`),
    which gives the same match values as visiting every column.

    Parameters
    ----------
    snapshot, current : dict
        Scale-plane stacks of the snapshot and the current view
        (:func:`~bionav.homing.warping.scaleplanes.scale_plane_stack`, same
        scales and size).
    n_alpha, n_psi : int
        Search steps over 360 degrees for the movement direction and the
        rotation (96 x 96 at width 288 is the fast default).
    thresholds : array_like, shape (K,), optional
        Scale thresholds ``tau_k``; default geometric midpoints.
    compass_fraction : float, optional
        Compass acceleration: search only this fraction of the ``n_psi``
        rotations, those with the smallest compass measure
        (:func:`~bionav.homing.warping.kernels.compass_measure`: the column
        distances along each rotation, best plane per column, summed).
        ``None`` or 1 searches all.
    fine_search : bool
        Afterwards search alpha and psi at one-column resolution around the
        best grid point (within one grid step).
    double_search : bool
        Also search with the roles of snapshot and current view exchanged and
        add the match values of corresponding hypotheses (``alpha' = alpha +
        pi - psi``, ``psi' = -psi``).
    template : tuple, optional
        Precomputed ``minwarp_template(W, scales, thresholds)`` (saves about a
        millisecond per call when many pairs share it).
    windows : tuple, optional
        Precomputed ``minwarp_windows(template)`` (the search reads the
        minimum over runs of allowed current columns from sliding minima).
    quantised : bool
        8-bit column distances with 16-bit sums, as in the SIMD reference
        implementation (default; about as fast as it). ``False`` runs the
        same search on float32 distances (the tests check that both agree
        within one search step).

    Returns
    -------
    WarpingResult
        ``score`` in NSAD units (summed over the snapshot columns, and over
        both searches with ``double_search``).

    Notes
    -----
    Runs on the calling thread and releases the GIL: parallelise over pairs.
    With ``double_search`` and inversion-symmetric scale factors
    (``sigma_{K-1-k} = 1 / sigma_k``, as the default ones) the distances of the
    swapped pair are the pair's, transposed
    (:func:`~bionav.homing.warping.kernels.swap_roles`); otherwise they are
    computed anew.
    """
    scales = _check_pair(snapshot, current)
    scales, tau, symmetric = _scale_setup(scales, thresholds)
    width = int(np.shape(snapshot["snap"])[-1])
    if double_search and width % 2:
        raise ValueError(f"double search needs an even image width, got {width}")
    a_cols = _column_grid(n_alpha, width)
    p_all = _column_grid(n_psi, width)
    step = _layout_step(width, n_alpha, p_all, double_search)
    if windows is None:
        tmpl = minwarp_template(width, scales, tau) if template is None else template
        windows = minwarp_windows(tmpl, max_level=WINDOW_LEVEL)
    grid = (a_cols, p_all, step, n_alpha, n_psi)
    if quantised and width >= 32 and distance_quantum(width)[1] == np.uint16:
        # the whole pair in one compiled call (the same kernels, order and ties as the steps below)
        ra, rp = _fine_radii(width, n_alpha, n_psi)
        best_a, best_p, best, n_p = minwarp_pair_u8(
            *pair_inputs(snapshot, current, step, double_search and not symmetric),
            a_cols, p_all, n_selected(p_all.size, compass_fraction), windows, double_search, symmetric,
            fine_search, ra, rp, _pair_buffers(snapshot, current, step, windows, double_search))
        best /= distance_quantum(width)[0]
        return _result(int(best_a), int(best_p), np.nan, best, width, n_psi_searched=int(n_p))
    return _minwarping_steps(snapshot, current, grid, windows, compass_fraction, fine_search,
                             double_search, symmetric, quantised)


def _minwarping_steps(snapshot, current, grid, windows, compass_fraction, fine_search, double_search, symmetric,
                      quantised):
    """:func:`minwarping` kernel by kernel from Python (float distances, and quantised ones the
    compiled pair does not take); ``grid`` is ``(a_cols, p_all, step, n_alpha, n_psi)``."""
    a_cols, p_all, step, n_alpha, n_psi = grid
    width = int(np.shape(snapshot["snap"])[-1])
    n_a_eff = width // step
    levels = _window_minima(snapshot, current, step, windows, quantised)
    p_cols = _select_psi(levels[0], p_all, compass_fraction)
    scores = _search(levels, n_a_eff, p_cols, windows, quantised)
    levels2 = None
    if double_search:
        levels2 = _table("levels2", levels.shape, levels.dtype)
        if symmetric:
            swap_roles(levels[0], levels2[0])
            if levels2.shape[0] > 1:
                fill_window_minima(levels2)
        else:
            _window_minima(current, snapshot, step, windows, quantised, name="levels2")
        scores2 = _search(levels2, n_a_eff, (-p_cols) % width, windows, quantised)
        # hypothesis (a, p) of the pair corresponds to (a + W/2 - p, -p) of the swapped pair
        a_eff = np.arange(n_a_eff) * step
        idx = ((a_eff[None, :] + width // 2 - p_cols[:, None]) % width) // step
        scores = scores + np.take_along_axis(scores2, idx, axis=1)
    scores = scores[:, a_cols // step]
    ip, ia = np.unravel_index(int(np.argmin(scores)), scores.shape)
    best_a, best_p, best = int(a_cols[ia]), int(p_cols[ip]), float(scores[ip, ia])
    if fine_search:
        best_a, best_p, best = _fine_minwarp(levels, levels2, windows, best_a, best_p, best, width,
                                             n_alpha, n_psi)
    if quantised:
        best /= distance_quantum(width)[0]
    return _result(best_a, best_p, np.nan, best, width, n_psi_searched=int(p_cols.size))


def _fine_radii(width, n_alpha, n_psi):
    """Half widths in columns of the fine search's block (within one grid step)."""
    return max(1, int(np.ceil(width / n_alpha)) - 1), max(1, int(np.ceil(width / n_psi)) - 1)


def _pair_buffers(snapshot, current, step, windows, double_search):
    """The per-thread work arrays of :func:`minwarp_pair_u8` (those of the Python path, shared),
    kept per shape: one lookup per pair instead of ten."""
    n_planes, n_rows, width = np.shape(snapshot["snap"])
    key = (n_planes, n_rows, width, step, int(windows[2].max(initial=0)) + 1, bool(double_search))
    kept = _WORKSPACE.__dict__.setdefault("pair", {})
    bufs = kept.get(key)
    if bufs is None:
        if len(kept) >= 8:
            kept.clear()
        bufs = kept[key] = _pair_buffers_new(*key)
    return bufs


def _pair_buffers_new(n_planes, n_rows, width, step, n_levels, double_search):
    shape = (n_levels, n_planes, width, step, width // step)
    levels = _table("levels", shape, np.dtype(np.uint8))
    levels2 = _table("levels2", shape, np.dtype(np.uint8)) if double_search else levels
    return (_scratch("sq", (n_planes, n_rows, width), np.int16), _scratch("sn", (n_planes, width), np.int32),
            _scratch("cq2", (n_planes, n_rows, 2 * width + 4), np.int16),
            _scratch("cn2", (n_planes, 2 * width + 4), np.int32), _scratch("acc", (width + 4, width), np.uint16),
            levels, _padded(levels), levels2, _padded(levels2),
            _buffer("scratch", (search_scratch_size(width // step),), np.dtype(np.uint8)))


def _fine_minwarp(levels, levels2, windows, best_a, best_p, best, width, n_alpha, n_psi):
    """:func:`_fine` for min-warping: the block of hypotheses as runs of
    directions per rotation (:func:`minwarp_scores_runs`), same order and ties."""
    ra, rp = _fine_radii(width, n_alpha, n_psi)
    pc = (best_p + np.arange(-rp, rp + 1, dtype=np.int64)) % width
    a_first = np.full(pc.size, (best_a - ra) % width, dtype=np.int64)
    vals = minwarp_scores_runs(levels, a_first, 2 * ra + 1, pc, *windows)
    if levels2 is not None:
        # hypothesis (a, p) of the pair is (a + W/2 - p, -p) of the swapped pair
        vals = vals + minwarp_scores_runs(levels2, (a_first + width // 2 - pc) % width, 2 * ra + 1,
                                          (-pc) % width, *windows)
    vals = vals.T.ravel()  # (direction, rotation) order, as _fine
    t = int(np.argmin(vals))
    if vals[t] < best:
        ia, ip = divmod(t, pc.size)
        return int((best_a - ra + ia) % width), int(pc[ip]), float(vals[t])
    return best_a, best_p, best


def _fine(score_at, best_a, best_p, best, width, n_alpha, n_psi):
    ra = max(1, int(np.ceil(width / n_alpha)) - 1)
    rp = max(1, int(np.ceil(width / n_psi)) - 1)
    da, dp = np.meshgrid(np.arange(-ra, ra + 1), np.arange(-rp, rp + 1), indexing="ij")
    ac = (best_a + da.ravel()) % width
    pc = (best_p + dp.ravel()) % width
    vals = score_at(ac.astype(np.int64), pc.astype(np.int64))
    t = int(np.argmin(vals))
    if vals[t] < best:
        return int(ac[t]), int(pc[t]), float(vals[t])
    return best_a, best_p, best


def _result(a_col, p_col, rho, score, width, **extras):
    alpha = 2.0 * np.pi * a_col / width
    psi = float(wrap_angle(2.0 * np.pi * p_col / width))
    home = float(wrap_angle(alpha + np.pi - psi))
    return WarpingResult(home, psi, float(alpha), float(rho), float(score), dict(extras))


def rho_grid(n_rho: int, rho_max: float) -> np.ndarray:
    """Distance ratios ``rho_l = rho_max * l / (n_rho - 1)``, ``l = 0..n_rho-1``."""
    if n_rho < 1:
        raise ValueError(f"n_rho must be >= 1, got {n_rho}")
    if not (0.0 <= rho_max < 1.0):
        raise ValueError(f"rho_max must lie in [0, 1), got {rho_max}")
    if n_rho == 1:
        return np.zeros(1)
    return rho_max * np.arange(n_rho) / (n_rho - 1)


def warping2d_scores(
    snapshot, current, *, n_alpha=96, n_psi=96, n_rho=20, rho_max=0.95, thresholds=None, psi_cols=None
):
    """2D-warping match values on the full (rho, psi, alpha) grid (fast kernels).

    Returns
    -------
    a_cols, p_cols : ndarray of int64
        Movement directions and rotations in columns.
    rhos : ndarray, shape (R,)
    scores : ndarray, shape (R, P, n_alpha), float32
    """
    scales = _check_pair(snapshot, current)
    scales, tau, _ = _scale_setup(scales, thresholds)
    width = int(np.shape(snapshot["snap"])[-1])
    a_cols = _column_grid(n_alpha, width)
    p_cols = _column_grid(n_psi, width) if psi_cols is None else np.asarray(psi_cols, np.int64) % width
    step = _layout_step(width, n_alpha, p_cols, False)
    rhos = rho_grid(n_rho, rho_max)
    v_tab, k_tab = warp2d_template(width, rhos, tau)
    dist = diagonal_distances(snapshot, current, step=step)
    scores = warp2d_scores(dist, width // step, p_cols, v_tab, k_tab)
    return a_cols, p_cols, rhos, scores[:, :, a_cols // step]


def warping2d(
    snapshot,
    current,
    *,
    n_alpha: int = 96,
    n_psi: int = 96,
    n_rho: int = 20,
    rho_max: float = 0.95,
    thresholds=None,
    compass_fraction: float | None = None,
    fine_search: bool = False,
    template=None,
) -> WarpingResult:
    """2D-warping home direction and visual compass of one image pair.

    Implements 2D-warping (Möller 2009, "Local visual homing by warping of
    two-dimensional images", Robotics and Autonomous Systems 57,
    doi:10.1016/j.robot.2008.05.005): under the equal-distance assumption a
    movement hypothesis ``(alpha, psi, rho)`` predicts for every snapshot column
    its current-view column and its vertical scale
    (:func:`~bionav.homing.warping.templates.warp2d_template`); the hypothesis
    with the smallest sum of column distances wins.

    Parameters
    ----------
    snapshot, current : dict
        Scale-plane stacks (same scales and size).
    n_alpha, n_psi : int
        Search steps over 360 degrees.
    n_rho : int
        Distance-ratio steps ``rho = d / r`` over ``[0, rho_max]``.
    rho_max : float
        Largest distance ratio (< 1).
    thresholds : array_like, shape (K,), optional
        Scale thresholds; scales beyond the last threshold use the last plane.
    compass_fraction : float, optional
        Compass acceleration (see :func:`minwarping`).
    fine_search : bool
        Refine alpha and psi at one-column resolution around the best grid
        point (``rho`` kept).
    template : tuple, optional
        Precomputed ``warp2d_template(W, rho_grid(n_rho, rho_max), thresholds)``.

    Returns
    -------
    WarpingResult
    """
    scales = _check_pair(snapshot, current)
    scales, tau, _ = _scale_setup(scales, thresholds)
    width = int(np.shape(snapshot["snap"])[-1])
    a_cols = _column_grid(n_alpha, width)
    p_all = _column_grid(n_psi, width)
    step = _layout_step(width, n_alpha, p_all, False)
    rhos = rho_grid(n_rho, rho_max)
    v_tab, k_tab = warp2d_template(width, rhos, tau) if template is None else template
    dist = diagonal_distances(snapshot, current, step=step)
    p_cols = _select_psi(dist, p_all, compass_fraction)
    scores = warp2d_scores(dist, width // step, p_cols, v_tab, k_tab)[:, :, a_cols // step]
    il, ip, ia = np.unravel_index(int(np.argmin(scores)), scores.shape)
    best_a, best_p, best = int(a_cols[ia]), int(p_cols[ip]), float(scores[il, ip, ia])
    if fine_search:
        def at(ac, pc):
            return warp2d_scores_at(dist, ac, pc, np.full(ac.size, il, np.int64), v_tab, k_tab)

        best_a, best_p, best = _fine(at, best_a, best_p, best, width, n_alpha, n_psi)
    return _result(best_a, best_p, rhos[il], best, width, n_psi_searched=int(p_cols.size))
