"""Typed configs of labelled sample sets: ``data=<name>`` and the samples separation lines are learned on.

:class:`DataConfig` is the ``data=`` group of ``experiment=contrast_lda`` (simulated samples or a
CSV file); :class:`LearnSamplesConfig` the ``experiment.learn`` node of the experiments that learn
the ``J_sigma`` lines (``contrast_scan``, ``skyline_homing``). Both are read by
:func:`bionav.spectral.samples.load_sample_set`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

from omegaconf import II

from bionav.validation import bounded


@dataclass
class LearnSamplesConfig:
    """Labelled samples the separation lines are learned on (thesis: the natural samples)."""

    name: str = bounded("sim_natural", choices=("sim_natural", "sim_artificial"))
    seed: int = bounded(II("seed"), ge=0, le=2**32 - 1)
    n_objects: int = bounded(239, ge=2, le=1_000_000)
    n_sky: int = bounded(233, ge=2, le=1_000_000)


@dataclass
class DataConfig:
    """``data=<name>`` of ``experiment=contrast_lda``: simulated labelled samples or a CSV file."""

    name: str = bounded("sim_natural", choices=("sim_natural", "sim_artificial", "csv"))
    path: Optional[str] = None
    seed: int = bounded(0, ge=0, le=2**32 - 1)
    n_objects: Optional[int] = bounded(None, ge=2, le=1_000_000)
    n_sky: int = bounded(233, ge=2, le=1_000_000)
    noise_counts: float = bounded(4.0, ge=0.0, le=1e6)
    n_average: int = bounded(10, ge=1, le=100_000)
