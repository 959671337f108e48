"""Default sky radiance of the rendered outdoor worlds (:class:`SimpleSky`).

A *simple, replaceable default*: the outdoor world builder accepts any sky
callable and any table of per-band albedos (default
:func:`bionav.light.materials.band_albedos`), so the physically based sky of
:mod:`bionav.light.daylight` and measured reflectances can be plugged in.

Band names follow the thesis' five-channel sensor (chapter 6): ``UV`` (350
nm), ``B`` (440 nm), ``G`` (500 nm), ``R`` (680 nm), ``IR`` (800 nm); a
single grey channel is called ``grey``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.light.clouds import CloudLayer

#: Relative sky radiance per band (blue sky: strong at short wavelengths).
SKY_GAIN = {"grey": 1.0, "UV": 1.4, "B": 1.3, "G": 1.0, "R": 0.6, "IR": 0.4}
#: Relative direct-sun irradiance per band.
SUN_GAIN = {"grey": 1.0, "UV": 0.7, "B": 1.0, "G": 1.05, "R": 1.0, "IR": 0.9}


@dataclass(frozen=True)
class SimpleSky:
    """A smooth clear/overcast sky with a sun glow and optional cloud texture.

    ``radiance(d) = gain_c * (zenith + (horizon - zenith) * (1 - sin(el))**2
    + glow * exp(-angle_to_sun / 0.15)) * (1 - clouds * (...))``; below the
    horizon the sky is not visible (ground covers it) but returns the horizon
    value. Behind a cloud ``layer`` (:class:`~bionav.light.clouds.CloudLayer`)
    the radiance is ``(1 - c) L(d) + c * layer.brightness * L(horizon)`` with
    the layer's cloudiness ``c`` at ``time_s`` (sunlit cumulus are brighter
    than the blue sky they hide).

    Parameters
    ----------
    sun_direction : tuple of float
        Unit vector towards the sun (world frame).
    channels : tuple of str
        Band names (see :data:`SKY_GAIN`).
    zenith, horizon, glow : float
        Radiance at the zenith, at the horizon and of the sun's aureole.
    clouds : float
        Cloud cover in [0, 1] (brightness modulation by a fixed noise field).
    seed : int
        Seed of the cloud pattern.
    layer : CloudLayer, optional
        A drifting cloud layer in front of the sky (e.g. the uni capture's,
        :mod:`bionav.light.capture`); ``None``: none.
    time_s : float
        Seconds since the layer's epoch (its drift).
    """

    sun_direction: tuple[float, float, float]
    channels: tuple[str, ...] = ("grey",)
    zenith: float = 0.55
    horizon: float = 0.95
    glow: float = 1.2
    clouds: float = 0.3
    seed: int = 0
    layer: CloudLayer | None = None
    time_s: float = 0.0

    def __call__(self, directions: np.ndarray) -> np.ndarray:
        d = np.asarray(directions, float).reshape(-1, 3)
        if self.layer is not None:
            clear = self._clear(d)
            horizon = self._clear(np.array([[1.0, 0.0, 0.0]]))  # (1, C)
            c = self.layer.cloudiness_at(d, time_s=self.time_s)[:, None]
            return (1.0 - c) * clear + c * (self.layer.brightness * horizon)
        return self._clear(d)

    def _clear(self, d: np.ndarray) -> np.ndarray:
        """The sky without the layer, ``(N, C)`` for unit directions ``(N, 3)``."""
        el = np.arcsin(np.clip(d[:, 2], -1.0, 1.0))
        s = np.asarray(self.sun_direction, float)
        ang = np.arccos(np.clip(d @ s, -1.0, 1.0))
        base = self.zenith + (self.horizon - self.zenith) * (1.0 - np.sin(np.maximum(el, 0.0))) ** 2
        base = base + self.glow * np.exp(-ang / 0.15)
        if self.clouds > 0:
            base = base * (1.0 + self.clouds * self._cloud_field(d))
        gains = np.array([SKY_GAIN.get(c, 1.0) for c in self.channels])
        return base[:, None] * gains[None, :]

    def _cloud_field(self, d: np.ndarray) -> np.ndarray:
        """Smooth deterministic pattern in [-0.5, 0.5] over the sky dome (sum of random plane waves)."""
        rng = np.random.default_rng(self.seed)
        k = rng.normal(size=(24, 3)) * np.linspace(2.0, 14.0, 24)[:, None]
        ph = rng.uniform(0, 2 * np.pi, 24)
        amp = 1.0 / np.linspace(1.0, 4.0, 24)
        f = (amp[None, :] * np.sin(d @ k.T + ph[None, :])).sum(1)
        f = f / (np.abs(amp).sum() * 0.5)
        return np.clip(f, -1, 1) * 0.5
