"""Quality measures of thesis 3.2: AE, AAE_s, AAE*, MAE_s, MAE*, RR_s, RR*.

Conventions (documented choices where the thesis is silent)
------------------------------------------------------------
* Angles in radians; home directions in the grid frame (CCW from +x).
* The ideal home direction from current view ``c`` to snapshot ``s`` is
  ``atan2(s_y - c_y, s_x - c_x)`` (eq. 3.1).
* AE is the absolute wrapped angular difference, in ``[0, pi]`` (eq. 3.2).
* A pair for which a method gave no direction (NaN) scores AE = pi/2, the
  expected error of a uniformly random direction.
* Only existing grid cells take part: AAE_s averages over every existing
  current-view cell except ``s`` (eq. 3.3 with ``mn - 1`` replaced by the
  number of existing cells minus one); AAE* averages AAE_s over existing
  snapshot cells (eq. 3.4).
* MAE_s is the median of AE over ``c != s`` and MAE* the median of the MAE_s
  (eqs. 3.5, 3.6; the mean of the two middle values for even counts, as
  ``numpy.median``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.geometry import angular_difference

#: AE given to pairs without a home direction
AE_NO_DIRECTION = np.pi / 2


def ideal_home_angles(snapshots: np.ndarray, currents: np.ndarray) -> np.ndarray:
    """Ideal home directions, shape ``(S, C)``, radians CCW in the grid frame.

    Parameters
    ----------
    snapshots : ndarray, shape (S, 2)
        Snapshot positions ``(x, y)`` in grid units.
    currents : ndarray, shape (C, 2)
        Current-view positions.

    Returns
    -------
    ndarray, shape (S, C)
        ``atan2(s_y - c_y, s_x - c_x)``; NaN where ``s == c``.
    """
    s = np.asarray(snapshots, dtype=float)[:, None, :]
    c = np.asarray(currents, dtype=float)[None, :, :]
    d = s - c
    angles = np.arctan2(d[..., 1], d[..., 0])
    angles[(d[..., 0] == 0) & (d[..., 1] == 0)] = np.nan
    return angles


def angular_errors(home_angles: np.ndarray, ideal_angles: np.ndarray) -> np.ndarray:
    """AE (eq. 3.2) per pair, radians in ``[0, pi]``.

    NaN in ``ideal_angles`` (the snapshot's own cell) stays NaN; NaN in
    ``home_angles`` (no direction) becomes :data:`AE_NO_DIRECTION`.
    """
    ae = angular_difference(home_angles, ideal_angles)
    ae = np.where(np.isnan(home_angles) & ~np.isnan(ideal_angles), AE_NO_DIRECTION, ae)
    return ae


@dataclass(frozen=True)
class QualityMeasures:
    """Per-snapshot and overall measures.

    Attributes
    ----------
    aae_s, mae_s, rr_s : ndarray, shape (S,)
        Per-snapshot average and median angular error (radians) and return ratio.
    aae, mae, rr : float
        AAE*, MAE*, RR*.
    """

    aae_s: np.ndarray
    mae_s: np.ndarray
    rr_s: np.ndarray
    aae: float
    mae: float
    rr: float


def quality_measures(ae: np.ndarray, success: np.ndarray) -> QualityMeasures:
    """AAE*, MAE*, RR* from an AE matrix and agent outcomes.

    Parameters
    ----------
    ae : ndarray, shape (S, C)
        Angular errors with NaN where a pair does not count (``s == c``).
    success : ndarray of bool, shape (S, C)
        Whether the agent starting at ``c`` reached ``s``; entries where
        ``ae`` is NaN are ignored.
    """
    ae = np.asarray(ae, dtype=float)
    counted = ~np.isnan(ae)
    aae_s = np.nanmean(ae, axis=1)
    mae_s = np.nanmedian(ae, axis=1)
    rr_s = np.sum(np.asarray(success) & counted, axis=1) / np.sum(counted, axis=1)
    return QualityMeasures(
        aae_s=aae_s,
        mae_s=mae_s,
        rr_s=rr_s,
        aae=float(np.mean(aae_s)),
        mae=float(np.median(mae_s)),
        rr=float(np.mean(rr_s)),
    )
