"""Homing in Scale Space (HiSS): SIFT matches split by their change of scale.

Churchill & Vardy (2008, "Homing in scale space", Proc. IEEE/RSJ International
Conference on Intelligent Robots and Systems, IROS): a landmark whose SIFT keypoint is smaller in the
current view than in the snapshot is farther away now than from home, so home
lies towards it (*contracted* set); a landmark whose keypoint grew is closer
now, so home lies away from it (*expanded* set). The home vector is the sum of
unit vectors towards the contracted keypoints minus the sum of unit vectors
towards the expanded ones, all taken at the keypoints' azimuths in the
current view. Only angles within the current view are used, so no compass is
needed.

Conventions: canonical panoramas (:mod:`bionav.geometry`); the returned angle
is radians CCW in the current view's own frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class HissResult:
    """Outcome of HiSS homing.

    Attributes
    ----------
    home_angle : float
        Home direction in the current view's frame (radians CCW,
        ``[-pi, pi)``); NaN when no match changed scale.
    n_matches : int
        Matches that passed the ratio test.
    n_contracted, n_expanded : int
        Matches whose keypoint shrank / grew beyond the scale threshold.
    """

    home_angle: float
    n_matches: int
    n_contracted: int
    n_expanded: int


def sift_features(
    image,
    *,
    wrap_pad: float = 0.1,
    n_features: int = 0,
    contrast_threshold: float = 0.04,
    edge_threshold: float = 10.0,
    sigma: float = 1.6,
):
    """SIFT keypoints of a panorama, seamless across the 0/360 degree border.

    The panorama is padded on both sides with ``wrap_pad * W`` columns from the
    other end, SIFT (OpenCV ``cv2.SIFT_create``) runs on the padded image, and
    only keypoints centred in the original columns are kept.

    Parameters
    ----------
    image : ndarray, shape (H, W), float in [0, 1]
        Canonical panorama.
    wrap_pad : float
        Padding on each side as a fraction of the width.
    n_features, contrast_threshold, edge_threshold, sigma
        Parameters of ``cv2.SIFT_create`` (``n_features = 0``: all).

    Returns
    -------
    dict of ndarray
        ``x`` (N,) float32: column of each keypoint (azimuth ``2 pi x / W``
        CCW); ``y`` (N,) float32: row; ``size`` (N,) float32: keypoint diameter
        in pixels; ``desc`` (N, 128) float32; ``width`` 0-d int64 array: ``W``.
    """
    import cv2

    img = np.asarray(image, dtype=np.float32)
    if img.ndim != 2:
        raise ValueError(f"expected a grey-level panorama of shape (H, W), got shape {img.shape}")
    width = img.shape[1]
    pad = int(round(wrap_pad * width))
    if pad < 0 or pad > width:
        raise ValueError(f"wrap_pad must lie in [0, 1], got {wrap_pad}")
    padded = np.concatenate([img[:, width - pad:], img, img[:, :pad]], axis=1) if pad else img
    u8 = np.clip(np.rint(padded * 255.0), 0, 255).astype(np.uint8)
    sift = cv2.SIFT_create(
        nfeatures=int(n_features),
        contrastThreshold=float(contrast_threshold),
        edgeThreshold=float(edge_threshold),
        sigma=float(sigma),
    )
    keypoints, desc = sift.detectAndCompute(u8, None)
    if desc is None or not keypoints:
        return {
            "x": np.zeros(0, np.float32),
            "y": np.zeros(0, np.float32),
            "size": np.zeros(0, np.float32),
            "desc": np.zeros((0, 128), np.float32),
            "width": np.array(width, dtype=np.int64),
        }
    pts = np.array([kp.pt for kp in keypoints], dtype=np.float32).reshape(-1, 2)
    size = np.array([kp.size for kp in keypoints], dtype=np.float32)
    x = pts[:, 0] - pad
    keep = (x >= -0.5) & (x < width - 0.5)
    return {
        "x": np.ascontiguousarray(x[keep] % width, dtype=np.float32),
        "y": np.ascontiguousarray(pts[keep, 1], dtype=np.float32),
        "size": np.ascontiguousarray(size[keep]),
        "desc": np.ascontiguousarray(desc[keep], dtype=np.float32),
        "width": np.array(width, dtype=np.int64),
    }


def match_features(snapshot, current, *, ratio: float = 0.8):
    """Nearest-neighbour SIFT matches with Lowe's ratio test.

    Parameters
    ----------
    snapshot, current : dict
        Results of :func:`sift_features`.
    ratio : float
        A current keypoint is matched to its nearest snapshot descriptor only
        if that is closer than ``ratio`` times the second nearest.

    Returns
    -------
    ndarray, shape (M, 2), int64
        Pairs ``(snapshot index, current index)``.
    """
    import cv2

    ds = np.asarray(snapshot["desc"], dtype=np.float32)
    dc = np.asarray(current["desc"], dtype=np.float32)
    if len(ds) < 2 or len(dc) < 1:
        return np.zeros((0, 2), np.int64)
    matcher = cv2.BFMatcher(cv2.NORM_L2)
    pairs = []
    for m in matcher.knnMatch(dc, ds, k=2):
        if len(m) == 2 and m[0].distance < ratio * m[1].distance:
            pairs.append((m[0].trainIdx, m[0].queryIdx))
    return np.array(pairs, dtype=np.int64).reshape(-1, 2)


def hiss(snapshot, current, *, ratio: float = 0.8, scale_threshold: float = 0.0) -> HissResult:
    """Home direction by Homing in Scale Space (Churchill & Vardy 2008).

    Parameters
    ----------
    snapshot, current : dict
        SIFT features of the snapshot and the current view
        (:func:`sift_features`, same image width).
    ratio : float
        Lowe ratio of the descriptor matching.
    scale_threshold : float
        A match counts as contracted when ``size_current / size_snapshot <
        1 / (1 + scale_threshold)`` and as expanded when the ratio exceeds
        ``1 + scale_threshold``; matches in between are ignored.

    Returns
    -------
    HissResult
        ``home_angle`` in the current view's frame (radians CCW); NaN when no
        match changed scale.
    """
    width = int(current["width"])
    if int(snapshot["width"]) != width:
        raise ValueError(
            f"snapshot and current features come from different widths ({int(snapshot['width'])} vs {width})"
        )
    if scale_threshold < 0:
        raise ValueError(f"scale_threshold must be >= 0, got {scale_threshold}")
    pairs = match_features(snapshot, current, ratio=ratio)
    if len(pairs) == 0:
        return HissResult(float("nan"), 0, 0, 0)
    change = np.asarray(current["size"])[pairs[:, 1]] / np.asarray(snapshot["size"])[pairs[:, 0]]
    azimuth = 2.0 * np.pi * np.asarray(current["x"], dtype=np.float64)[pairs[:, 1]] / width
    contracted = change < 1.0 / (1.0 + scale_threshold)
    expanded = change > 1.0 + scale_threshold
    sign = contracted.astype(np.float64) - expanded.astype(np.float64)
    vx, vy = np.sum(sign * np.cos(azimuth)), np.sum(sign * np.sin(azimuth))
    n_c, n_e = int(contracted.sum()), int(expanded.sum())
    if n_c + n_e == 0 or (vx == 0.0 and vy == 0.0):
        return HissResult(float("nan"), len(pairs), n_c, n_e)
    angle = float((np.arctan2(vy, vx) + np.pi) % (2.0 * np.pi) - np.pi)
    return HissResult(angle, len(pairs), n_c, n_e)
