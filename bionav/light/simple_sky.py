"""Default sky radiance of the rendered outdoor worlds (:class:`SimpleSky`).

A *simple, replaceable default*: the outdoor world builder accepts any sky
callable and any table of per-band albedos (default
:func:`bionav.light.materials.band_albedos`), so the physically based sky of
:mod:`bionav.light.daylight` and measured reflectances can be plugged in.

Its clouds are a view of the one cloud layer,
:class:`bionav.light.clouds.CloudLayer` (the layer's cloudiness blends the
clear sky towards the cloud radiance); there is no other cloud texture.

Band names follow the thesis' five-channel sensor (chapter 6): ``UV`` (350
nm), ``B`` (440 nm), ``G`` (500 nm), ``R`` (680 nm), ``IR`` (800 nm); a
single grey channel is called ``grey``.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from bionav.light.clouds import CloudLayer

#: Relative sky radiance per band (blue sky: strong at short wavelengths).
SKY_GAIN = {"grey": 1.0, "UV": 1.4, "B": 1.3, "G": 1.0, "R": 0.6, "IR": 0.4}
#: Relative direct-sun irradiance per band.
SUN_GAIN = {"grey": 1.0, "UV": 0.7, "B": 1.0, "G": 1.05, "R": 1.0, "IR": 0.9}


@dataclass(frozen=True)
class SimpleSky:
    """A smooth clear sky with a sun glow, seen through an optional cloud layer.

    Radiance (renderer units, per band ``(N, C)``) seen along unit viewing
    directions ``d`` ``(N, 3)`` in the world frame (east-north-up: ``x`` east,
    ``y`` north, ``z`` up). The clear sky is

    ``L(d) = gain_c * (zenith + (horizon - zenith) * (1 - sin(el))**2 + glow * exp(-angle_to_sun / 0.15))``

    with ``el`` the elevation of ``d`` (radians, clipped at 0: below the
    horizon, where the ground hides the sky, it returns the horizon value)
    and ``gain_c`` = :data:`SKY_GAIN` of band ``c``. The clouds are a view of
    the one cloud layer (:class:`~bionav.light.clouds.CloudLayer`): a line of
    sight whose footprint on the layer is a fraction ``c`` cloud
    (:meth:`CloudLayer.cloudiness_at` at ``time_s``, in ``[0, 1]``) sees
    ``(1 - c) L(d) + c * layer.brightness * L(horizon)``: the clear sky where
    the layer is clear, a uniform cloud radiance of ``layer.brightness``
    times the clear horizon's (sunlit cumulus are brighter than the blue sky
    they hide) where it is cloud, blended over the cloud edges and, towards
    the horizon, where distant clouds merge, towards the layer's ``cover``.
    ``L(horizon)`` is the clear sky at the east horizon, ``d = (1, 0, 0)``:
    ``horizon`` plus the sun's glow there (``glow * exp(-angle / 0.15)``, a
    few 1e-4 for a sun 75-90 degrees away, as the campus').
    Without a layer (or with ``cover=0``) the sky is exactly the clear ``L``.

    Parameters
    ----------
    sun_direction : tuple of float
        Unit vector towards the sun (world frame).
    channels : tuple of str
        Band names (see :data:`SKY_GAIN`).
    zenith, horizon, glow : float
        Radiance of the clear sky at the zenith, at the horizon and of the
        sun's aureole (renderer units, before :data:`SKY_GAIN`).
    layer : CloudLayer, optional
        The cloud layer in front of the sky (e.g. the campus'
        :func:`bionav.world.worlds.outdoor.campus_clouds`); ``None``: a clear sky.
    time_s : float
        Seconds since the layer's epoch (its drift with the wind).
    """

    sun_direction: tuple[float, float, float]
    channels: tuple[str, ...] = ("grey",)
    zenith: float = 0.55
    horizon: float = 0.95
    glow: float = 1.2
    layer: CloudLayer | None = None
    time_s: float = 0.0

    def __call__(self, directions: np.ndarray) -> np.ndarray:
        """Radiance ``(N, C)`` along unit directions ``(N, 3)`` (east-north-up)."""
        d = np.asarray(directions, float).reshape(-1, 3)
        clear = self._clear(d)
        if self.layer is None:
            return clear
        horizon = self._clear(np.array([[1.0, 0.0, 0.0]]))  # (1, C)
        c = self.layer.cloudiness_at(d, time_s=self.time_s)[:, None]
        return (1.0 - c) * clear + c * (self.layer.brightness * horizon)

    def describe(self) -> dict:
        """The sky's parameters (JSON; part of a render cache key)."""
        layer = None if self.layer is None else {k: (list(v) if isinstance(v, tuple) else v)
                                                 for k, v in dataclasses.asdict(self.layer).items()}
        return {"model": "simple-sky-2", "sun_direction": [float(v) for v in self.sun_direction],
                "channels": list(self.channels), "zenith": float(self.zenith), "horizon": float(self.horizon),
                "glow": float(self.glow), "layer": layer, "time_s": float(self.time_s)}

    def _clear(self, d: np.ndarray) -> np.ndarray:
        """The clear sky ``L``, ``(N, C)`` for unit directions ``(N, 3)``."""
        el = np.arcsin(np.clip(d[:, 2], -1.0, 1.0))
        s = np.asarray(self.sun_direction, float)
        ang = np.arccos(np.clip(d @ s, -1.0, 1.0))
        base = self.zenith + (self.horizon - self.zenith) * (1.0 - np.sin(np.maximum(el, 0.0))) ** 2
        base = base + self.glow * np.exp(-ang / 0.15)
        gains = np.array([SKY_GAIN.get(c, 1.0) for c in self.channels])
        return base[:, None] * gains[None, :]
