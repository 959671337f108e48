"""Matched-filter descent in image distances (MFDID; Möller & Vardy 2006).

The image distance ``D(x) = sum (C(x) - S)^2`` between current view and
snapshot is descended without test steps: the change of the current view
under a small translation is predicted by *flow templates* under the
equal-distance assumption. A landmark at azimuth ``theta`` (CCW, distance
``d``) shifts by ``dtheta = (sin(theta) dx - cos(theta) dy) / d`` when the
robot moves by ``(dx, dy)``, so ``dC/dx = -C_theta sin(theta) / d`` and
``dC/dy = C_theta cos(theta) / d``. The home vector is ``-grad D``::

    h = ( sum (C - S) C_theta sin(theta),  -sum (C - S) C_theta cos(theta) )

(the positive factor ``2/d`` dropped). With ``vertical_flow``, the
elevation flow of the same assumption (all points at one horizontal
distance ``d``, so a point at elevation ``eps`` moves by
``deps = sin(eps) cos(eps) (cos(theta) dx + sin(theta) dy) / d``) adds
``C_eps sin(eps) cos(eps) (cos(theta), sin(theta))`` to the summands. Angles are radians, CCW, in the
current view's frame; images are canonical panoramas (:mod:`bionav.geometry`)
and must be aligned.

Reference
---------
Möller, R. & Vardy, A. (2006). Local visual homing by matched-filter descent
in image distances. Biological Cybernetics 95, 413-430.
doi:10.1007/s00422-006-0095-3
"""

from __future__ import annotations

import numpy as np

from bionav.geometry import PanoramaGeometry


def azimuthal_derivative(image: np.ndarray, *, geometry: PanoramaGeometry) -> np.ndarray:
    """``dI/dtheta`` per pixel (central difference, cyclic in azimuth), per radian.

    Parameters
    ----------
    image : ndarray, shape (H, W)
    """
    return (np.roll(image, -1, axis=1) - np.roll(image, 1, axis=1)) / (2.0 * geometry.rad_per_column)


def elevation_derivative(image: np.ndarray, *, geometry: PanoramaGeometry) -> np.ndarray:
    """``dI/deps`` per pixel (central differences along the column, one-sided at the ends), per radian.

    Elevation grows upwards, rows downwards, hence the sign.
    """
    return -np.gradient(image, axis=0) / geometry.rad_per_row


def mfdid_home_vector(
    snapshot: np.ndarray,
    current: np.ndarray,
    *,
    geometry: PanoramaGeometry,
    current_derivative: np.ndarray | None = None,
    current_elevation_derivative: np.ndarray | None = None,
) -> np.ndarray:
    """MFDID home vector, shape ``(2,)``, in the current view's frame (not normalised).

    Parameters
    ----------
    snapshot, current : ndarray, shape (H, W)
        Aligned canonical panoramas (low-pass filtered by the caller as wanted).
    geometry : PanoramaGeometry
        Their pixel geometry.
    current_derivative : ndarray, shape (H, W), optional
        Precomputed :func:`azimuthal_derivative` of ``current``.
    current_elevation_derivative : ndarray, shape (H, W), optional
        :func:`elevation_derivative` of ``current``; when given, the vertical
        flow template is used as well.
    """
    if current_derivative is None:
        current_derivative = azimuthal_derivative(current, geometry=geometry)
    theta = geometry.column_azimuths()
    diff = current - snapshot
    horizontal = np.sum(diff * current_derivative, axis=0)  # (W,)
    h = np.array([np.dot(horizontal, np.sin(theta)), -np.dot(horizontal, np.cos(theta))])
    if current_elevation_derivative is not None:
        eps = geometry.row_elevations()[:, None]
        vertical = np.sum(diff * current_elevation_derivative * np.sin(eps) * np.cos(eps), axis=0)
        h += np.array([np.dot(vertical, np.cos(theta)), np.dot(vertical, np.sin(theta))])
    return h
