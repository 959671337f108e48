"""Optics of the polarized-light compass: mounting frame, acceptance cone, polarizers.

Sensor frame
------------
The compass sits on a pan-tilt unit. With pan and tilt zero it looks at the
zenith. Its frame has the optical axis ``z_s`` (towards the sky), ``x_s``
along the transmission axis of unit 0's first polarizer and ``y_s = z_s x
x_s``; angles in the sensor plane (e-vector angles, polarizer angles) are
measured from ``x_s`` towards ``y_s``, i.e. counter-clockwise seen from
above when the compass looks up. The *sensor heading* ``h`` is the azimuth
(CCW from east) of ``x_s`` when the compass looks at the zenith; panning by
``p`` adds ``p`` to it; tilting by ``t`` turns the optical axis by ``t`` from
the zenith towards ``x_s`` (negative ``t`` towards ``-x_s``), so the compass
then looks at zenith angle ``|t|``.

Photodiode signals
------------------
Every photodiode integrates the sky over a circular acceptance cone
(half-angle 10 degrees for the Hamamatsu S5821-1, thesis 4.1), sampled on
rings of equal angular width, weighted by solid angle. The integrated Stokes
vector in the sensor plane is ``(I, Q, U) = sum_k w_k L_k (1, d_k cos 2a_k,
d_k sin 2a_k)`` with ``a_k`` the e-vector angle of direction ``k`` projected
into the sensor plane; a polarizer with transmission axis ``alpha`` and
efficiency ``eta`` passes ``(I + eta (Q cos 2alpha + U sin 2alpha)) / 2``
(eq. 4.1 of the thesis with ``K = 1/2``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


def sensor_frame(heading, tilt):
    """Rotation matrices of the compass for sensor headings and tilts.

    Parameters
    ----------
    heading : float or ndarray
        Sensor heading(s), radians CCW from east (mount heading plus pan).
    tilt : float or ndarray
        Tilt(s) of the optical axis away from the zenith towards ``x_s``,
        radians. Broadcast against ``heading``.

    Returns
    -------
    ndarray, shape ``(..., 3, 3)``
        Columns ``x_s, y_s, z_s`` in the sky frame (east-north-up).
    """
    h, t = np.broadcast_arrays(np.asarray(heading, float), np.asarray(tilt, float))
    ch, sh, ct, st = np.cos(h), np.sin(h), np.cos(t), np.sin(t)
    x = np.stack([ct * ch, ct * sh, -st], axis=-1)
    y = np.stack([-sh, ch, np.zeros_like(h)], axis=-1)
    z = np.stack([st * ch, st * sh, ct], axis=-1)
    return np.stack([x, y, z], axis=-1)


def cone_samples(half_angle: float, *, n_rings: int = 4, n_azimuths: int = 12):
    """Directions and solid-angle weights covering a circular acceptance cone.

    Parameters
    ----------
    half_angle : float
        Cone half-angle, radians (``0`` gives the single axis direction).
    n_rings, n_azimuths : int, optional
        Rings at the mid-points of equal angular steps, each with
        ``n_azimuths`` equally spaced directions (keep it even so the cone is
        symmetric under a half turn).

    Returns
    -------
    directions : ndarray, shape ``(M, 3)``
        Unit directions in the sensor frame (optical axis ``+z``).
    weights : ndarray, shape ``(M,)``
        Solid-angle weights summing to 1.
    """
    if half_angle <= 0.0:
        return np.array([[0.0, 0.0, 1.0]]), np.array([1.0])
    edges = np.linspace(0.0, half_angle, n_rings + 1)
    rho = 0.5 * (edges[:-1] + edges[1:])
    ring_weight = np.cos(edges[:-1]) - np.cos(edges[1:])  # exact solid angle of each ring / 2pi
    omega = (np.arange(n_azimuths) + 0.5) * 2.0 * np.pi / n_azimuths
    r, o = np.meshgrid(rho, omega, indexing="ij")
    directions = np.stack([np.sin(r) * np.cos(o), np.sin(r) * np.sin(o), np.cos(r)], axis=-1).reshape(-1, 3)
    weights = np.repeat(ring_weight / n_azimuths, n_azimuths)
    return directions, weights / weights.sum()


@dataclass(frozen=True)
class CompassOptics:
    """Polarizer arrangement and acceptance cone of the compass.

    Parameters
    ----------
    unit_angles : tuple of float
        Transmission axis of each POL-OP unit's first polarizer in the sensor
        frame, radians (thesis: 0, 60, 120 degrees); the second polarizer of a
        unit is turned by 90 degrees.
    polarizer_efficiency : float
        Polarizing efficiency ``eta`` of the filter foil.
    cone_half_angle : float
        Acceptance half-angle, radians.
    n_rings, n_azimuths : int
        Sampling of the cone (see :func:`cone_samples`).
    """

    unit_angles: tuple = (0.0, np.pi / 3.0, 2.0 * np.pi / 3.0)
    polarizer_efficiency: float = 0.99
    cone_half_angle: float = np.deg2rad(10.0)
    n_rings: int = 4
    n_azimuths: int = 12
    _cone: tuple = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        object.__setattr__(self, "_cone", cone_samples(self.cone_half_angle, n_rings=self.n_rings, n_azimuths=self.n_azimuths))

    def stokes(self, source, heading, tilt):
        """Integrated normalised Stokes parameters in the sensor plane.

        Parameters
        ----------
        source : object with ``light(view) -> SkyLight``
            A :class:`bionav.light.SkyModel` or :class:`bionav.light.PolarizerLamp`.
        heading, tilt : float or ndarray
            Sensor heading(s) and tilt(s), radians, broadcast together to
            shape ``S``.

        Returns
        -------
        intensity : ndarray, shape ``S``
            Cone-averaged radiance ``I``.
        q, u : ndarray, shape ``S``
            ``Q / I`` and ``U / I``: the cone's effective degree ``d`` and
            e-vector angle ``a`` in the sensor frame are
            ``d = hypot(q, u)``, ``a = atan2(u, q) / 2``.
        """
        frames = sensor_frame(heading, tilt)  # (..., 3, 3)
        local, weights = self._cone
        view = np.einsum("...ij,mj->...mi", frames, local)  # (..., M, 3)
        light = source.light(view)
        x_s = frames[..., :, 0][..., None, :]
        y_s = frames[..., :, 1][..., None, :]
        ex = np.sum(light.evector * x_s, axis=-1)
        ey = np.sum(light.evector * y_s, axis=-1)
        a2 = 2.0 * np.arctan2(ey, ex)
        wl = weights * light.radiance
        intensity = np.sum(wl, axis=-1)
        q = np.sum(wl * light.degree * np.cos(a2), axis=-1) / intensity
        u = np.sum(wl * light.degree * np.sin(a2), axis=-1) / intensity
        return intensity, q, u

    def unit_signals(self, q, u, *, unit_angles=None):
        """Ideal delogarithmised unit outputs ``x_i = eta d cos(2a - 2alpha_i)``.

        This is what eq. 4.3 returns for a perfect sensor chain.

        Parameters
        ----------
        q, u : ndarray, shape ``S``
            Normalised Stokes parameters from :meth:`stokes`.
        unit_angles : array_like, optional
            Polarizer angles to use instead of :attr:`unit_angles`.

        Returns
        -------
        ndarray, shape ``S + (K,)``
        """
        alpha = np.asarray(self.unit_angles if unit_angles is None else unit_angles, float)
        q = np.asarray(q)[..., None]
        u = np.asarray(u)[..., None]
        return self.polarizer_efficiency * (q * np.cos(2.0 * alpha) + u * np.sin(2.0 * alpha))
