"""Published baselines: ``decoder=sol``, ``four_zeros``, ``eigenvector``, ``mean_vector``.

Implemented from the papers' equations (see :mod:`bionav.polcompass.decoders`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.errors import UserError
from bionav.plugins.decoders.base import Decoder, check_range
from bionav.polcompass.decoders import sun_from_eigenvector, sun_from_four_zeros, sun_from_mean_vector, sun_from_sol


@dataclass
class SolConfig:
    """Parameters of ``decoder=sol`` (Gkanias et al. 2019 / 2023)."""

    n_sol: int = 8  # SOL neurons, [3, 360]
    response: str = "c"  # per-unit response: p (polarization), i (intensity), c = i - p
    analyser_deg: float = 90.0  # analyser of the POL response in the unit frame (90: horizontal), [-180, 180]

    def __post_init__(self):
        check_range("n_sol", self.n_sol, 3, 360)
        check_range("analyser_deg", self.analyser_deg, -180.0, 180.0)
        if self.response not in ("p", "i", "c"):
            raise UserError(f"decoder.response={self.response!r} is unknown; choose p, i or c.")


class Sol(Decoder):
    """Sinusoidal population (SOL) decoder."""

    Config = SolConfig

    def decode(self, evectors, valid, *, array, sun_elevation: float):
        return sun_from_sol(evectors, valid, array=array, n_sol=self.config.n_sol, response=self.config.response,
                            analyser=np.deg2rad(self.config.analyser_deg))


@dataclass
class FourZerosConfig:
    """``decoder=four_zeros`` has no parameters."""


class FourZeros(Decoder):
    """Four-zeros method (Smith & Stewart 2014)."""

    Config = FourZerosConfig

    def decode(self, evectors, valid, *, array, sun_elevation: float):
        return sun_from_four_zeros(evectors, valid, array=array)


@dataclass
class VectorConfig:
    """Parameters of ``decoder=eigenvector`` / ``mean_vector``."""

    margin_deg: float = 2.0  # sun elevation needed for a resolved sign (above the horizon), degrees, [0, 90]

    def __post_init__(self):
        check_range("margin_deg", self.margin_deg, 0.0, 90.0)


class Eigenvector(Decoder):
    """Eigenvector method: the sun is perpendicular to all e-vectors."""

    Config = VectorConfig

    def decode(self, evectors, valid, *, array, sun_elevation: float):
        return sun_from_eigenvector(evectors, valid, margin=np.deg2rad(self.config.margin_deg))


class MeanVector(Decoder):
    """Mean-vector method: mean of pairwise e-vector cross products."""

    Config = VectorConfig

    def decode(self, evectors, valid, *, array, sun_elevation: float):
        return sun_from_mean_vector(evectors, valid, margin=np.deg2rad(self.config.margin_deg))
