"""SIFT homing (thesis 5.1; Vardy & Möller 2005, Schatz 2006).

Conventions: canonical panoramas (:mod:`bionav.geometry`); every angle in
radians, azimuths counter-clockwise in the image frame, elevations positive
above the horizon. Snapshot and current view are assumed aligned (same
orientation); the home angle is returned in the current view's frame.

References
----------
Vardy, A. & Möller, R. (2005). Biologically plausible visual homing methods
based on optical flow techniques. Connection Science 17(1-2), 47-89.
doi:10.1080/09540090500140958
Lowe, D. G. (2004). Distinctive image features from scale-invariant
keypoints. IJCV 60(2), 91-110. doi:10.1023/B:VISI.0000029664.99615.94
"""

from __future__ import annotations

from typing import Any, Callable, Iterable, NamedTuple, Sequence

import numpy as np

from bionav.geometry import TWO_PI, PanoramaGeometry, wrap_angle
from bionav.homing.features import SiftFeatures

#: keypoints whose snapshot elevation is at most this (radians) are ignored (thesis 5.1.2)
MIN_ELEVATION = 0.01
#: bins of the home-angle histogram over 360 degrees (1-degree bins, thesis 5.1.3)
N_BINS = 360


class ColumnIndex(NamedTuple):
    """Keypoints of one image sorted by column, with exact integer descriptors (per-image work once).

    Built by :func:`column_index`; used by :func:`match_in_neighbourhood` and
    :func:`sift_home_angles_all_pairs`.

    Attributes
    ----------
    x, y : ndarray, shape (N,), float64
        Columns (ascending) and rows, pixels.
    descriptors : ndarray, shape (ceil(N / 8) * 8, 128), float32
        Descriptors in sorted order, integers (zero rows pad to a multiple of 8, the kernels' group).
    sq_norms : ndarray, shape (N,), int64
        Squared descriptor norms.
    rank : ndarray, shape (N,), int64
        Index of each sorted keypoint in the original :class:`SiftFeatures`.
    where : ndarray, shape (N,), int64
        Sorted position of each original keypoint (``where[rank] = arange(N)``).
    """

    x: np.ndarray
    y: np.ndarray
    descriptors: np.ndarray
    sq_norms: np.ndarray
    rank: np.ndarray
    where: np.ndarray


def column_index(features: SiftFeatures) -> ColumnIndex | None:
    """Sort keypoints by column for windowed matching; ``None`` unless descriptors are integers in ``[-255, 255]``.

    OpenCV SIFT descriptors are integers in 0..255 (stored as float32), so
    their distances are exact in integer arithmetic; other descriptors (``None``)
    are matched by :func:`match_in_neighbourhood_reference`.
    """
    from bionav.homing.sift_kernels import GROUP

    desc = np.asarray(features.descriptors)
    if desc.size and (not np.all(np.abs(desc) <= 255) or not np.array_equal(desc, np.rint(desc))):
        return None
    xy = np.asarray(features.xy, dtype=np.float64).reshape(-1, 2)
    order = np.argsort(xy[:, 0], kind="stable")
    n = len(order)
    padded = np.zeros(((n + GROUP - 1) // GROUP * GROUP, desc.shape[1] if desc.ndim == 2 else 128), np.float32)
    padded[:n] = desc[order]
    d = padded[:n].astype(np.int64)
    where = np.empty(n, np.int64)
    where[order] = np.arange(n)
    return ColumnIndex(np.ascontiguousarray(xy[order, 0]), np.ascontiguousarray(xy[order, 1]), padded,
                       np.einsum("ij,ij->i", d, d), order.astype(np.int64), where)


def match_in_neighbourhood(
    current: SiftFeatures, snapshot: SiftFeatures, *, radius: float, width: int
) -> tuple[np.ndarray, np.ndarray]:
    """Nearest-descriptor matching limited to a pixel neighbourhood (eqs. 5.1-5.3).

    For every current keypoint ``p`` the snapshot keypoint with the smallest
    Euclidean descriptor distance (eq. 5.1) among those closer than ``radius``
    pixels (eq. 5.3; the column distance wraps around the panorama of width
    ``width``: ``dx = min(|x_c - x_s|, W - |x_c - x_s|)``, neighbours satisfy
    ``dx^2 + dy^2 < radius^2``) is chosen (eq. 5.2); ties go to the lowest
    snapshot index. Keypoints are sorted by column and only snapshot keypoints
    within ``radius`` columns are visited; distances of OpenCV SIFT
    descriptors (integers) are exact, so the result equals
    :func:`match_in_neighbourhood_reference` (which is used for other
    descriptors).

    Parameters
    ----------
    current, snapshot : SiftFeatures or ColumnIndex
        Keypoints of the current view and the snapshot (a :class:`ColumnIndex`
        from :func:`column_index` saves sorting again).
    radius : float
        Neighbourhood radius ``q`` in pixels.
    width : int
        Panorama width ``W`` in pixels.

    Returns
    -------
    current_idx, snapshot_idx : ndarray of int
        Matched index pairs, ascending current index (current keypoints
        without any candidate are dropped).
    """
    from bionav.homing.sift_kernels import match_sorted, matches_from_keys

    a = current if isinstance(current, ColumnIndex) else column_index(current)
    b = snapshot if isinstance(snapshot, ColumnIndex) else column_index(snapshot)
    if a is None or b is None:
        if isinstance(current, ColumnIndex) or isinstance(snapshot, ColumnIndex):
            raise TypeError("a ColumnIndex can only be matched against features with integer descriptors")
        return match_in_neighbourhood_reference(current, snapshot, radius=radius, width=width)
    key_a = np.empty(len(a.x), np.int64)
    match_sorted(a.x, a.y, a.descriptors, a.sq_norms, a.rank, b.x, b.y, b.descriptors, b.sq_norms, b.rank,
                 float(radius), float(width), key_a, key_a[:0], False)
    return matches_from_keys(key_a, a.rank, len(a.x))


def match_in_neighbourhood_reference(
    current: SiftFeatures, snapshot: SiftFeatures, *, radius: float, width: int
) -> tuple[np.ndarray, np.ndarray]:
    """Plain all-against-all version of :func:`match_in_neighbourhood` (the definition; for tests).

    Squared distances ``|d_c|^2 + |d_s|^2 - 2 d_c . d_s`` and the
    neighbourhood test in float64 over every keypoint pair; ``numpy.argmin``
    (lowest snapshot index on ties).
    """
    if len(current.xy) == 0 or len(snapshot.xy) == 0:
        empty = np.zeros(0, np.int64)
        return empty, empty
    cxy = np.asarray(current.xy, dtype=np.float64)
    sxy = np.asarray(snapshot.xy, dtype=np.float64)
    dx = np.abs(cxy[:, None, 0] - sxy[None, :, 0])
    dx = np.minimum(dx, float(width) - dx)
    dy = cxy[:, None, 1] - sxy[None, :, 1]
    near = dx * dx + dy * dy < float(radius) * float(radius)
    dc = np.asarray(current.descriptors, dtype=np.float64)
    ds = np.asarray(snapshot.descriptors, dtype=np.float64)
    d2 = np.einsum("ij,ij->i", dc, dc)[:, None] + np.einsum("ij,ij->i", ds, ds)[None, :] - 2.0 * (dc @ ds.T)
    d2 = np.where(near, d2, np.inf)
    best = np.argmin(d2, axis=1)
    ok = np.isfinite(d2[np.arange(len(best)), best])
    return np.flatnonzero(ok), best[ok]


def correspondence_home_angles(
    theta_s: np.ndarray, eps_s: np.ndarray, theta_c: np.ndarray, eps_c: np.ndarray
) -> np.ndarray:
    """Home angle of each landmark correspondence (thesis eq. 5.12, quadrant-safe).

    A landmark seen at azimuth ``theta_s`` and elevation ``eps_s`` from the
    snapshot and at ``theta_c``, ``eps_c`` from the current view (aligned
    frames, equal camera heights) lies at horizontal distances with ratio
    ``r = d_s / d_c = tan(eps_c) / tan(eps_s)`` (eq. 5.7). From
    ``L = S + d_s u(theta_s) = C + d_c u(theta_c)`` the home direction is that
    of ``u(theta_c) - r u(theta_s)``::

        beta = atan2(sin(theta_c) - r sin(theta_s), cos(theta_c) - r cos(theta_s))

    which equals eq. 5.12, ``theta_x - arctan(sin(dx) / (r - cos(dx))) + pi``
    with ``dx = theta_c - theta_s``, wherever ``r > cos(dx)``, and keeps the
    right quadrant elsewhere.

    Parameters
    ----------
    theta_s, eps_s, theta_c, eps_c : ndarray
        Radians; azimuths CCW, elevations positive above the horizon.

    Returns
    -------
    ndarray
        Home angles in radians (current view's frame), NaN where the
        correspondence is unusable: ``|eps_s| <= 0.01`` (thesis), or a distance
        ratio that is not positive and finite.
    """
    theta_s, eps_s, theta_c, eps_c = np.broadcast_arrays(theta_s, eps_s, theta_c, eps_c)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.tan(eps_c) / np.tan(eps_s)
        beta = np.arctan2(np.sin(theta_c) - r * np.sin(theta_s), np.cos(theta_c) - r * np.cos(theta_s))
    bad = (np.abs(eps_s) <= MIN_ELEVATION) | ~np.isfinite(r) | (r <= 0)
    return np.where(bad, np.nan, beta)


def combine_home_angles(angles: np.ndarray, *, method: str = "average", n_bins: int = 360, window: int = 10) -> float:
    """Overall home direction from per-correspondence home angles (thesis 5.1.3).

    Parameters
    ----------
    angles : ndarray, shape (K,)
        Home angles in radians (NaN entries ignored).
    method : {"average", "max"}
        ``"average"``: sum of the unit vectors, each weighted by the count of
        its histogram bin (eqs. 5.14-5.15: the histogram-weighted average
        vector). ``"max"``: centre of the cyclic window of ``window`` bins with
        the largest count (Schatz 2006).
    n_bins : int
        Histogram bins over 360 degrees.
    window : int
        Window width in bins for ``"max"``.

    Returns
    -------
    float
        Angle in radians in ``[-pi, pi)``, or NaN without any usable angle.
    """
    angles = np.asarray(angles, dtype=float)
    angles = angles[np.isfinite(angles)]
    if angles.size == 0:
        return float("nan")
    bins = np.floor((angles % TWO_PI) / TWO_PI * n_bins).astype(np.int64) % n_bins
    hist = np.bincount(bins, minlength=n_bins).astype(float)
    if method == "average":
        weights = hist[bins]
        v = np.array([np.sum(weights * np.cos(angles)), np.sum(weights * np.sin(angles))])
        if not np.any(v):
            return float("nan")
        return float(wrap_angle(np.arctan2(v[1], v[0])))
    if method == "max":
        sums = np.convolve(np.concatenate([hist, hist[: window - 1]]), np.ones(window), mode="valid")[:n_bins]
        start = int(np.argmax(sums))
        centre_bin = start + window / 2.0
        return float(wrap_angle(centre_bin / n_bins * TWO_PI))
    raise ValueError(f"unknown combination method {method!r}; use 'average' or 'max'")


def sift_home_vector(
    snapshot: SiftFeatures,
    current: SiftFeatures,
    *,
    geometry: PanoramaGeometry,
    search_radius: float,
    combine: str = "average",
    window: int = 10,
) -> tuple[float, int]:
    """SIFT home vector between two aligned panoramas (thesis 5.1).

    Matches by :func:`match_in_neighbourhood`, home angles per correspondence
    by :func:`correspondence_home_angles` (eq. 5.12), combined by
    :func:`combine_home_angles` (eqs. 5.14-5.15 or the histogram maximum);
    for OpenCV SIFT descriptors all three run in one compiled kernel.

    Parameters
    ----------
    snapshot, current : SiftFeatures
        Features of the snapshot and the current view.
    geometry : PanoramaGeometry
        Pixel geometry of both images.
    search_radius : float
        Neighbourhood radius ``q`` in pixels.
    combine : {"average", "max"}
        How the per-correspondence angles are combined (:func:`combine_home_angles`).
    window : int
        Window width in 1-degree bins for ``combine="max"``.

    Returns
    -------
    angle : float
        Home direction in radians, CCW in the current view's frame (NaN if no
        usable correspondence).
    n_used : int
        Number of correspondences that contributed.
    """
    if combine not in ("average", "max"):
        raise ValueError(f"unknown combination method {combine!r}; use 'average' or 'max'")
    a = column_index(current)
    b = column_index(snapshot)
    if a is not None and b is not None:
        from bionav.homing.sift_kernels import home_angle_from_keys, match_sorted

        keys = np.empty(len(a.x), np.int64)
        match_sorted(a.x, a.y, a.descriptors, a.sq_norms, a.rank, b.x, b.y, b.descriptors, b.sq_norms, b.rank,
                     float(search_radius), float(geometry.width), keys, keys[:0], False)
        angle, used = home_angle_from_keys(
            keys, a.x, a.y, a.where, b.x, b.y, b.where, geometry.rad_per_column, float(geometry.horizon_row),
            float(geometry.rad_per_row), MIN_ELEVATION, combine == "max", N_BINS, int(window))
        return float(angle), int(used)
    ci, si = match_in_neighbourhood_reference(current, snapshot, radius=search_radius, width=geometry.width)
    return _home_vector_from_matches(snapshot, current, ci, si, geometry=geometry, combine=combine, window=window)


def _home_vector_from_matches(snapshot, current, ci, si, *, geometry, combine, window) -> tuple[float, int]:
    """eqs. 5.4-5.15 in numpy from matched index pairs (the reference of the compiled kernel)."""
    if ci.size == 0:
        return float("nan"), 0
    az = geometry.rad_per_column
    cxy = np.asarray(current.xy, dtype=np.float64)[ci]  # float64: float32 pixel angles cost up to 2e-4 rad
    sxy = np.asarray(snapshot.xy, dtype=np.float64)[si]
    theta_c = cxy[:, 0] * az
    theta_s = sxy[:, 0] * az
    eps_c = (geometry.horizon_row - cxy[:, 1]) * geometry.rad_per_row
    eps_s = (geometry.horizon_row - sxy[:, 1]) * geometry.rad_per_row
    beta = correspondence_home_angles(theta_s, eps_s, theta_c, eps_c)
    used = int(np.sum(np.isfinite(beta)))
    return combine_home_angles(beta, method=combine, n_bins=N_BINS, window=window), used


def sift_home_vector_reference(
    snapshot: SiftFeatures, current: SiftFeatures, *, geometry: PanoramaGeometry, search_radius: float,
    combine: str = "average", window: int = 10,
) -> tuple[float, int]:
    """:func:`sift_home_vector` from the plain parts: :func:`match_in_neighbourhood_reference`,
    :func:`correspondence_home_angles` and :func:`combine_home_angles` in numpy (for tests)."""
    ci, si = match_in_neighbourhood_reference(current, snapshot, radius=search_radius, width=geometry.width)
    return _home_vector_from_matches(snapshot, current, ci, si, geometry=geometry, combine=combine, window=window)


def _joined_index(index: Sequence) -> tuple[np.ndarray, np.ndarray, list[np.ndarray]]:
    """Every image's sorted keypoints in one set of arrays: one compiled call per row, no GIL per pair.

    Returns the keypoint offsets (N + 1,), the descriptor offsets (N + 1,) and
    the concatenated ``x, y, descriptors, sq_norms, rank, where`` of the
    column indices ``index`` (:func:`column_index`).
    """
    n = len(index)
    kp_off = np.concatenate([[0], np.cumsum([len(ix.x) for ix in index])]).astype(np.int64)
    desc_off = np.concatenate([[0], np.cumsum([len(ix.descriptors) for ix in index])]).astype(np.int64)
    joined = [np.concatenate([getattr(ix, name) for ix in index]) if n else np.zeros(0)
              for name in ("x", "y", "descriptors", "sq_norms", "rank", "where")]
    return kp_off, desc_off, joined


def sift_home_angles_all_pairs(
    features: Sequence[SiftFeatures],
    *,
    geometry: PanoramaGeometry,
    search_radius: float,
    combine: str = "average",
    window: int = 10,
    snapshot_index: Sequence[int] | None = None,
    workers: int = 1,
    progress: Callable[..., Iterable[Any]] | None = None,
    on_row: Callable[[int, np.ndarray, np.ndarray], None] | None = None,
) -> tuple[np.ndarray, np.ndarray] | None:
    """:func:`sift_home_vector` for every pair of one set of images, each distance computed once.

    The neighbourhood (eq. 5.3) is symmetric, so one pass over the
    descriptor distances of images ``a`` and ``b`` gives the matches of both
    directions (``a`` current / ``b`` snapshot and the reverse); each
    image is sorted by column once. Unordered pairs are shared among
    ``workers`` threads (the kernels release the GIL).

    Parameters
    ----------
    features : sequence of SiftFeatures, length N
        Features of every image (the same geometry).
    geometry, search_radius, combine, window
        As :func:`sift_home_vector`.
    snapshot_index : sequence of int, optional
        Only these snapshots (rows); other rows stay NaN.
    workers : int
        Threads.
    progress : callable, optional
        ``progress(iterable, desc=..., total=...)``, e.g. a tqdm wrapper.
    on_row : callable, optional
        ``on_row(s, angles[s], n_used[s])`` is called in the caller's thread,
        in ascending ``s``, as soon as snapshot row ``s`` is complete (so a
        crash loses no finished row).

    Returns
    -------
    angles : ndarray, shape (N, N)
        ``[s, c]``: home direction from current view ``c`` to snapshot ``s``,
        radians CCW in the current view's own frame; NaN on the diagonal,
        in rows not asked for and without usable correspondences.
    n_used : ndarray of int, shape (N, N)
        Correspondences that contributed.
    None
        When some descriptors are not integers (use :func:`sift_home_vector`).
    """
    from concurrent.futures import ThreadPoolExecutor

    from bionav.homing.sift_kernels import row_home_angles

    if combine not in ("average", "max"):
        raise ValueError(f"unknown combination method {combine!r}; use 'average' or 'max'")
    index = [column_index(f) for f in features]
    if any(ix is None for ix in index):
        return None
    n = len(index)
    wanted = np.zeros(n, bool)
    wanted[np.arange(n) if snapshot_index is None else np.asarray(snapshot_index, dtype=np.int64)] = True
    angles = np.full((n, n), np.nan)
    used = np.zeros((n, n), np.int64)
    kp_off, desc_off, joined = _joined_index(index)
    options = (float(search_radius), float(geometry.width), geometry.rad_per_column, float(geometry.horizon_row),
               float(geometry.rad_per_row), MIN_ELEVATION, combine == "max", N_BINS, int(window))

    def row(a: int) -> None:
        row_home_angles(a, np.arange(a + 1, n, dtype=np.int64), wanted, *joined, kp_off, desc_off, *options,
                        angles, used)

    # row a holds the pairs (a, b > a) of both directions, so snapshot row s is complete once rows 0 .. s are
    pool = ThreadPoolExecutor(max(1, int(workers)))
    try:
        done = pool.map(row, range(n))
        for a, _ in enumerate(progress(done, desc="home vectors (SIFT rows)", total=n) if progress else done):
            if on_row is not None and wanted[a]:
                on_row(a, angles[a].copy(), used[a].copy())
    finally:  # on Ctrl-C or an error, rows not yet started are dropped instead of awaited
        pool.shutdown(wait=True, cancel_futures=True)
    return angles, used
