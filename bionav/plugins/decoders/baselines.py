"""Published baselines: ``decoder=sol``, ``four_zeros``, ``eigenvector``, ``mean_vector``.

Implemented from the papers' equations (see :mod:`bionav.polcompass.decoders`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.plugins.decoders.base import Decoder
from bionav.polcompass.published_decoders import sun_from_eigenvector, sun_from_four_zeros, sun_from_mean_vector, sun_from_sol
from bionav.validation import bounded


@dataclass
class SolConfig:
    """Parameters of ``decoder=sol`` (Gkanias et al. 2019 / 2023).

    n_sol : SOL neurons. response : per-unit response ``p`` (polarization), ``i`` (intensity) or
    ``c = i - p``. analyser_deg : analyser of the POL response in the unit frame (90: horizontal).
    """

    n_sol: int = bounded(8, ge=3, le=360)
    response: str = bounded("c", choices=("p", "i", "c"))
    analyser_deg: float = bounded(90.0, ge=-180.0, le=180.0)


class Sol(Decoder):
    """Sinusoidal population (SOL) decoder."""

    Config = SolConfig

    def decode(self, evectors, valid, *, array, sun_elevation: float):
        return sun_from_sol(evectors, valid, array=array, n_sol=self.config.n_sol, response=self.config.response,
                            analyser=np.deg2rad(self.config.analyser_deg))


@dataclass
class FourZerosConfig:
    """Parameters of ``decoder=four_zeros``: harmonics of the ring interpolation, azimuth grid."""

    n_harmonics: int = bounded(3, ge=1, le=3)
    n_grid: int = bounded(360, ge=36, le=7200)


class FourZeros(Decoder):
    """Four-zeros method (Smith & Stewart 2014)."""

    Config = FourZerosConfig

    def decode(self, evectors, valid, *, array, sun_elevation: float):
        return sun_from_four_zeros(evectors, valid, array=array, n_harmonics=self.config.n_harmonics,
                                   n_grid=self.config.n_grid)


@dataclass
class VectorConfig:
    """Parameters of ``decoder=eigenvector`` / ``mean_vector``: sun elevation (deg) for a resolved sign."""

    margin_deg: float = bounded(2.0, ge=0.0, le=90.0)


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
