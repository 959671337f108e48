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


def match_features(snapshot, current, *, ratio: float = 0.8):
    """Nearest-neighbour SIFT matches with Lowe's ratio test.

    Parameters
    ----------
    snapshot, current : SiftFeatures
        Results of :func:`bionav.homing.features.sift_features`.
    ratio : float
        A current keypoint is matched to its nearest snapshot descriptor only
        if that is closer than ``ratio`` times the second nearest.

    Returns
    -------
    ndarray, shape (M, 2), int64
        Pairs ``(snapshot index, current index)``.
    """
    import cv2

    ds = np.asarray(snapshot.descriptors, dtype=np.float32)
    dc = np.asarray(current.descriptors, dtype=np.float32)
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
    snapshot, current : SiftFeatures
        SIFT features of the snapshot and the current view
        (:func:`bionav.homing.features.sift_features` with ``wrap_pad``, same image width).
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
    width = int(current.width)
    if int(snapshot.width) != width or width < 1:
        raise ValueError(
            f"snapshot and current features come from different or unknown widths ({int(snapshot.width)} vs {width})"
        )
    if scale_threshold < 0:
        raise ValueError(f"scale_threshold must be >= 0, got {scale_threshold}")
    pairs = match_features(snapshot, current, ratio=ratio)
    if len(pairs) == 0:
        return HissResult(float("nan"), 0, 0, 0)
    change = np.asarray(current.size)[pairs[:, 1]] / np.asarray(snapshot.size)[pairs[:, 0]]
    azimuth = 2.0 * np.pi * np.asarray(current.xy[:, 0], dtype=np.float64)[pairs[:, 1]] / width
    contracted = change < 1.0 / (1.0 + scale_threshold)
    expanded = change > 1.0 + scale_threshold
    sign = contracted.astype(np.float64) - expanded.astype(np.float64)
    vx, vy = np.sum(sign * np.cos(azimuth)), np.sum(sign * np.sin(azimuth))
    n_c, n_e = int(contracted.sum()), int(expanded.sum())
    if n_c + n_e == 0 or (vx == 0.0 and vy == 0.0):
        return HissResult(float("nan"), len(pairs), n_c, n_e)
    angle = float((np.arctan2(vy, vx) + np.pi) % (2.0 * np.pi) - np.pi)
    return HissResult(angle, len(pairs), n_c, n_e)
