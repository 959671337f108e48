"""Scale-plane stacks: vertically magnified, edge-filtered copies of a panorama.

In 2D-warping and min-warping (Möller 2009, doi:10.1016/j.robot.2008.05.005;
Möller, Krzykawski & Gerstmayr 2010, doi:10.1007/s10514-010-9195-y) a column of
the snapshot is compared with a column of the current view under a vertical
scale factor ``sigma = r / r'``: the ratio of a landmark's distance from the
snapshot position ``r`` to its distance from the current position ``r'``
(``sigma > 1``: the landmark is closer now and looks taller in the current view).

For each scale factor ``sigma_k`` of the search, plane ``k`` holds one image for
each role so that both compared columns keep every row:

* ``sigma_k >= 1``: the snapshot magnified by ``sigma_k`` against the
  unmagnified current view;
* ``sigma_k < 1``: the unmagnified snapshot against the current view magnified
  by ``1 / sigma_k``.

Magnification is about the horizon and exact for a panoramic camera: a pixel at
elevation ``e`` of the magnified image shows elevation ``atan(tan(e) / m)`` of
the source (an object at distance ``r`` and height ``z`` above the camera is
seen at ``tan(e) = z / r``). Every plane is then edge filtered by the first
difference along the column (row ``r + 1`` minus row ``r``), which makes the
distance measure tolerant to illumination changes.
"""

from __future__ import annotations

import numpy as np

from bionav.geometry import PanoramaGeometry
from bionav.homing.imageops import vertical_difference


def default_scales(n: int = 9) -> np.ndarray:
    """The fast default scale factors ``2 ** ((k - (n - 1) / 2) / 4)``, shape ``(n,)``.

    For ``n = 9`` these are ``2 ** ((k - 4) / 4)``, k = 0..8: 0.5 ... 1 ... 2.
    """
    k = np.arange(n, dtype=np.float64)
    return 2.0 ** ((k - (n - 1) / 2.0) / 4.0)


def default_thresholds(scales) -> np.ndarray:
    """Upper thresholds ``tau_k`` between neighbouring scale factors.

    Plane ``k`` is used for a scale ``sigma`` with ``tau_{k-1} <= sigma < tau_k``
    (``tau_{-1} = 0``). The default thresholds are the geometric means of
    neighbouring scale factors and the last one is infinite (larger scales use
    the last plane).

    Parameters
    ----------
    scales : array_like, shape (K,)
        Increasing scale factors.

    Returns
    -------
    ndarray, shape (K,)
    """
    s = np.asarray(scales, dtype=np.float64)
    tau = np.empty_like(s)
    tau[:-1] = np.sqrt(s[:-1] * s[1:])
    tau[-1] = np.inf
    return tau


def reference_thresholds(scales, *, max_ratio: float = 2.5) -> np.ndarray:
    """Thresholds of the SIMD reference implementation (WarpingSIMD).

    The arithmetic means of neighbouring scale factors, and a finite last
    threshold: scale ratios above ``max_ratio`` are not allowed (the reference
    default 2.5 with scale factors up to 2).

    Parameters
    ----------
    scales : array_like, shape (K,)
        Increasing scale factors.
    max_ratio : float
        Largest allowed scale ratio (``> scales[-1]``).

    Returns
    -------
    ndarray, shape (K,)
    """
    s = np.asarray(scales, dtype=np.float64)
    if not max_ratio > s[-1]:
        raise ValueError(f"the largest scale ratio {max_ratio} must exceed the largest scale factor {s[-1]}")
    tau = np.empty_like(s)
    tau[:-1] = 0.5 * (s[:-1] + s[1:])
    tau[-1] = float(max_ratio)
    return tau


#: Rules for the thresholds when none are given: ``geometric`` (geometric means,
#: no largest ratio) and ``reference`` (arithmetic means, largest ratio 2.5).
THRESHOLD_RULES = ("geometric", "reference")


def check_scales(scales, thresholds=None):
    """Validate scale factors and thresholds; return both as float64 arrays.

    Raises
    ------
    ValueError
        If the scales are not positive and increasing, if the thresholds do not
        separate them (``sigma_k < tau_k <= sigma_{k+1}``), or if the lengths
        differ.
    """
    s = np.asarray(scales, dtype=np.float64).ravel()
    if s.size < 1 or np.any(s <= 0) or np.any(np.diff(s) <= 0):
        raise ValueError(f"scale factors must be positive and increasing, got {s.tolist()}")
    if thresholds is None:
        tau = default_thresholds(s)
    else:
        tau = np.asarray(thresholds, dtype=np.float64).ravel()
        if tau.shape != s.shape:
            raise ValueError(
                f"need one threshold per scale factor: {s.size} scales but {tau.size} thresholds"
            )
        if np.any(tau <= s) or np.any(tau[:-1] > s[1:]):
            raise ValueError(
                "thresholds must separate the scale factors (sigma_k < tau_k <= sigma_{k+1}); "
                f"got scales {s.tolist()} and thresholds {tau.tolist()}"
            )
    return s, tau


def magnify_vertical(image, *, factor: float, geometry: PanoramaGeometry):
    """Magnify a panorama vertically about the horizon.

    Parameters
    ----------
    image : ndarray, shape (H, W)
        Canonical panorama.
    factor : float
        Magnification ``m > 0``; row elevation ``e`` of the result shows
        elevation ``atan(tan(e) / m)`` of ``image`` (linear interpolation along
        the column; rows outside the image repeat the border row).
    geometry : PanoramaGeometry
        Geometry of ``image`` (horizon row and radians per row).

    Returns
    -------
    ndarray, shape (H, W), float32
    """
    img = np.asarray(image, dtype=np.float32)
    h = img.shape[0]
    if factor == 1.0:
        return img.copy()
    elev = geometry.row_elevations()
    limit = 0.5 * np.pi - 1e-6
    src_elev = np.arctan(np.tan(np.clip(elev, -limit, limit)) / factor)
    src_row = geometry.horizon_row - src_elev / geometry.rad_per_row
    src_row = np.clip(src_row, 0.0, h - 1.0)
    r0 = np.minimum(np.floor(src_row).astype(np.int64), h - 2) if h > 1 else np.zeros(h, np.int64)
    w1 = (src_row - r0).astype(np.float32)[:, None]
    r1 = np.minimum(r0 + 1, h - 1)
    return ((1.0 - w1) * img[r0] + w1 * img[r1]).astype(np.float32)


def scale_plane_stack(image, *, geometry: PanoramaGeometry, scales=None):
    """Per-image work of 2D-warping and min-warping: the scale-plane stack.

    Parameters
    ----------
    image : ndarray, shape (H, W)
        Canonical panorama (already resized and low-pass filtered).
    geometry : PanoramaGeometry
        Its geometry.
    scales : array_like, shape (K,), optional
        Increasing scale factors ``sigma_k``; default :func:`default_scales`.

    Returns
    -------
    dict of ndarray
        ``scales`` (K,) float64; ``snap`` (K, H-1, W) float32: the image's
        planes in the snapshot role; ``cur`` (K, H-1, W) float32: its planes in
        the current-view role; ``snap_norm`` and ``cur_norm`` (K, W) float32:
        the sum of absolute values of every column of those planes (the
        denominators of the normalised sum of absolute differences);
        ``snap_absmax`` and ``cur_absmax`` () float32: the largest absolute
        value of each role's planes (the quantised distances scale both
        images of a pair by the larger of the two).
    """
    s = default_scales() if scales is None else np.asarray(scales, dtype=np.float64)
    s, _ = check_scales(s)
    img = np.asarray(image, dtype=np.float32)
    if img.ndim != 2:
        raise ValueError(f"expected a grey-level panorama of shape (H, W), got shape {img.shape}")
    if img.shape != (geometry.height, geometry.width):
        raise ValueError(
            f"image shape {img.shape} does not match its geometry ({geometry.height}, {geometry.width})"
        )
    cache: dict[float, np.ndarray] = {}

    def planes_for(m: float) -> np.ndarray:
        key = float(m)
        if key not in cache:
            cache[key] = vertical_difference(magnify_vertical(img, factor=key, geometry=geometry))
        return cache[key]

    snap = np.stack([planes_for(sk if sk >= 1.0 else 1.0) for sk in s])
    cur = np.stack([planes_for(1.0 / sk if sk < 1.0 else 1.0) for sk in s])
    return {
        "scales": s,
        "snap": np.ascontiguousarray(snap, dtype=np.float32),
        "cur": np.ascontiguousarray(cur, dtype=np.float32),
        "snap_norm": np.abs(snap).sum(axis=1).astype(np.float32),
        "cur_norm": np.abs(cur).sum(axis=1).astype(np.float32),
        "snap_absmax": np.array(np.abs(snap).max(initial=0.0), dtype=np.float32),
        "cur_absmax": np.array(np.abs(cur).max(initial=0.0), dtype=np.float32),
    }
