"""Default sky radiance and per-band material albedos for outdoor worlds.

These are *simple, replaceable defaults*: the outdoor world builder accepts
any sky callable and any table of per-band albedos, so a physically based
sky and measured reflectances (bionav's spectral models) can be plugged in.

Band names follow the thesis' five-channel sensor (chapter 6): ``UV`` (350
nm), ``B`` (440 nm), ``G`` (500 nm), ``R`` (680 nm), ``IR`` (800 nm); a
single grey channel is called ``grey``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Relative reflectance of material kinds, per band. Rough textbook shapes
#: (vegetation: red edge and low UV; concrete/stone: flat and slightly rising;
#: glass: low; sky-facing metal: flat). Assumption: UV reflectance of most
#: terrestrial materials is low (0.03-0.1), which is what makes UV a good sky
#: separator in the thesis.
BAND_ALBEDO: dict[str, dict[str, float]] = {
    "grey": {"concrete": 0.45, "brick": 0.3, "glass": 0.15, "foliage": 0.3, "bark": 0.25, "grass": 0.3,
             "paving": 0.4, "asphalt": 0.15, "metal": 0.5, "paint": 0.6, "wood": 0.35, "soil": 0.2},
    "UV": {"concrete": 0.08, "brick": 0.05, "glass": 0.06, "foliage": 0.03, "bark": 0.04, "grass": 0.03,
           "paving": 0.07, "asphalt": 0.04, "metal": 0.2, "paint": 0.1, "wood": 0.04, "soil": 0.04},
    "B": {"concrete": 0.25, "brick": 0.12, "glass": 0.1, "foliage": 0.05, "bark": 0.08, "grass": 0.05,
          "paving": 0.22, "asphalt": 0.08, "metal": 0.4, "paint": 0.5, "wood": 0.12, "soil": 0.08},
    "G": {"concrete": 0.3, "brick": 0.18, "glass": 0.12, "foliage": 0.14, "bark": 0.12, "grass": 0.15,
          "paving": 0.27, "asphalt": 0.09, "metal": 0.45, "paint": 0.55, "wood": 0.2, "soil": 0.12},
    "R": {"concrete": 0.36, "brick": 0.38, "glass": 0.12, "foliage": 0.06, "bark": 0.2, "grass": 0.07,
          "paving": 0.32, "asphalt": 0.1, "metal": 0.45, "paint": 0.6, "wood": 0.35, "soil": 0.2},
    "IR": {"concrete": 0.42, "brick": 0.45, "glass": 0.12, "foliage": 0.5, "bark": 0.35, "grass": 0.45,
           "paving": 0.38, "asphalt": 0.12, "metal": 0.45, "paint": 0.6, "wood": 0.45, "soil": 0.28},
}

#: Relative sky radiance per band (blue sky: strong at short wavelengths).
SKY_GAIN = {"grey": 1.0, "UV": 1.4, "B": 1.3, "G": 1.0, "R": 0.6, "IR": 0.4}
#: Relative direct-sun irradiance per band.
SUN_GAIN = {"grey": 1.0, "UV": 0.7, "B": 1.0, "G": 1.05, "R": 1.0, "IR": 0.9}


def band_albedos(channels: tuple[str, ...]) -> dict[str, np.ndarray]:
    """Albedo per material kind as arrays of shape ``(C,)`` for the given band names."""
    unknown = [c for c in channels if c not in BAND_ALBEDO]
    if unknown:
        raise ValueError(f"no default albedos for bands {unknown}; pass albedos explicitly")
    kinds = BAND_ALBEDO["grey"].keys()
    return {k: np.array([BAND_ALBEDO[c][k] for c in channels]) for k in kinds}


@dataclass(frozen=True)
class SimpleSky:
    """A smooth clear/overcast sky with a sun glow and optional cloud texture.

    ``radiance(d) = gain_c * (zenith + (horizon - zenith) * (1 - sin(el))**2
    + glow * exp(-angle_to_sun / 0.15)) * (1 - clouds * (...))``; below the
    horizon the sky is not visible (ground covers it) but returns the horizon
    value.

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
    """

    sun_direction: tuple[float, float, float]
    channels: tuple[str, ...] = ("grey",)
    zenith: float = 0.55
    horizon: float = 0.95
    glow: float = 1.2
    clouds: float = 0.3
    seed: int = 0

    def __call__(self, directions: np.ndarray) -> np.ndarray:
        d = np.asarray(directions, float).reshape(-1, 3)
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
