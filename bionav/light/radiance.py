"""Relative sky radiance: the CIE standard clear sky.

CIE S 011/E:2003 (ISO 15469:2004) general sky, type 12 ("CIE standard clear
sky, low luminance turbidity"): relative luminance
``L / L_zenith = f(gamma) phi(Z) / (f(Z_s) phi(0))`` with the gradation
``phi(Z) = 1 + a exp(b / cos Z)`` and the indicatrix
``f(gamma) = 1 + c (exp(d gamma) - exp(d pi / 2)) + e cos^2 gamma``,
``Z`` the zenith angle of the sky element, ``Z_s`` that of the sun and
``gamma`` their angular distance. The polarized-light compass only needs the
relative weights of directions inside its 10 degree acceptance cone.
"""

from __future__ import annotations

import numpy as np

from bionav.light.rayleigh import scattering_angle

#: Parameters (a, b, c, d, e) of CIE sky type 12.
CIE_CLEAR_SKY = (-1.0, -0.32, 10.0, -3.0, 0.45)


def cie_relative_radiance(view, sun, *, params=CIE_CLEAR_SKY):
    """Sky radiance relative to the zenith.

    Parameters
    ----------
    view : ndarray, shape ``(..., 3)``
        Unit viewing directions, sky frame (east-north-up); directions below
        the horizon get the horizon value.
    sun : ndarray, shape ``(3,)``
        Unit vector towards the sun.
    params : tuple of 5 floats, optional
        CIE parameters ``(a, b, c, d, e)``.

    Returns
    -------
    ndarray, shape ``(...)``
        Relative radiance (1 at the zenith).
    """
    a, b, c, d, e = params
    view = np.asarray(view, float)
    sun = np.asarray(sun, float)

    def gradation(cos_z):
        cos_z = np.maximum(cos_z, 1e-6)
        return 1.0 + a * np.exp(b / cos_z)

    def indicatrix(g):
        return 1.0 + c * (np.exp(d * g) - np.exp(d * np.pi / 2.0)) + e * np.cos(g) ** 2

    gamma = scattering_angle(view, sun)
    z_sun = np.arccos(np.clip(sun[2], -1.0, 1.0))
    return indicatrix(gamma) * gradation(view[..., 2]) / (indicatrix(z_sun) * gradation(1.0))
