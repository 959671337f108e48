"""Matched-filter flow templates: image change under small translations.

Möller, R. & Vardy, A. (2006). Local visual homing by matched-filter descent in
image distances. *Biological Cybernetics* 95, 413-430.
doi:10.1007/s00422-006-0095-3 -- and thesis appendix C, eq. C.6.

A translation of the agent by ``(dx, dy)`` (in the current view's own frame:
``x`` along the heading, ``y`` to the left) moves a scene point seen at
azimuth ``theta`` (CCW from the heading) and elevation ``eps`` at distance ``D``
through the panorama by (first order)::

    d theta = ( dx sin(theta) - dy cos(theta)) / (D cos(eps))
    d eps   = (dx cos(theta) + dy sin(theta)) sin(eps) / D

Under the *equal-distance assumption* of the matched filter (every point at
the same distance ``D``), the image after the move is predicted by
``C(phi) -> C(phi - d phi)``, i.e. the spatial image derivatives are::

    dC/dx = -(1/D) [ sin(theta)/cos(eps) dC/dtheta + sin(eps) cos(theta) dC/deps ]
    dC/dy = -(1/D) [-cos(theta)/cos(eps) dC/dtheta + sin(eps) sin(theta) dC/deps ]

which is ``-(1/D) B_i^T Gamma_j grad_phi C`` of eq. C.6 with
``B_i = [[sin theta_i, -cos theta_i], [cos theta_i, sin theta_i]]`` and
``Gamma_j = diag(1 / cos eps_j, sin eps_j)``. ``D`` only scales the
derivatives, so it does not change the direction of any home vector.
"""

from __future__ import annotations

import numpy as np

from bionav.geometry import PanoramaGeometry

#: smallest |cos(elevation)| used in the azimuthal flow (rows within ~2.9 deg of the zenith/nadir)
MIN_COS_ELEVATION = 0.05


def intensity_gradient(image: np.ndarray, *, geometry: PanoramaGeometry) -> tuple[np.ndarray, np.ndarray]:
    """Angular intensity gradient of a canonical panorama.

    Parameters
    ----------
    image : ndarray, shape (H, W)
        Canonical panorama (column ``j`` at azimuth ``2 pi j / W`` CCW).
    geometry : PanoramaGeometry
        Its pixel geometry (azimuth and elevation step per pixel).

    Returns
    -------
    d_theta, d_eps : ndarray, shape (H, W), float64
        ``dC/dtheta`` (per radian of azimuth; central differences, wrapping
        around the closed panorama) and ``dC/deps`` (per radian of elevation,
        positive upwards; central differences inside, one-sided at the top and
        bottom rows).
    """
    img = np.asarray(image, dtype=np.float64)
    if img.shape[:2] != (geometry.height, geometry.width):
        raise ValueError(f"image shape {img.shape} does not match the geometry {geometry.height}x{geometry.width}")
    d_theta = (np.roll(img, -1, axis=1) - np.roll(img, 1, axis=1)) / (2.0 * geometry.rad_per_column)
    if img.shape[0] > 1:
        d_eps = -np.gradient(img, axis=0) / geometry.rad_per_row
    else:
        d_eps = np.zeros_like(img)
    return d_theta, d_eps


def translation_derivatives(
    image: np.ndarray, *, geometry: PanoramaGeometry, distance: float = 1.0
) -> tuple[np.ndarray, np.ndarray]:
    """Predicted image derivatives for unit moves along ``x`` and ``y`` (eq. C.6).

    Parameters
    ----------
    image : ndarray, shape (H, W)
        Canonical panorama of the current view.
    geometry : PanoramaGeometry
        Its pixel geometry.
    distance : float
        Assumed distance ``D`` of every scene point (same unit as the move).

    Returns
    -------
    phi, psi : ndarray, shape (H, W), float64
        ``dC/dx`` and ``dC/dy`` in the current view's own frame (``x`` along the
        heading, ``y`` to the left); ``C + dx * phi + dy * psi`` predicts the view
        after a small move ``(dx, dy)``. ``cos(eps)`` is clipped at
        :data:`MIN_COS_ELEVATION` near the poles.
    """
    d_theta, d_eps = intensity_gradient(image, geometry=geometry)
    theta = geometry.column_azimuths()[None, :]
    eps = geometry.row_elevations()[:, None]
    inv_cos = 1.0 / np.maximum(np.cos(eps), MIN_COS_ELEVATION)
    sin_eps = np.sin(eps)
    s, c = np.sin(theta), np.cos(theta)
    phi = -(s * inv_cos * d_theta + sin_eps * c * d_eps) / distance
    psi = -(-c * inv_cos * d_theta + sin_eps * s * d_eps) / distance
    return phi, psi
