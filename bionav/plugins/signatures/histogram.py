"""Histogram signatures [hist] and [ent] (thesis 3.5.2, eqs. 3.53-3.54).

Both rotation invariant. Bins are fixed over ``[0, 1]``; [hist] holds relative
frequencies and [ent] the Shannon entropy of them (see
:mod:`bionav.homing.signatures.histogram` for these documented choices).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.homing.signatures.base import Signature


@dataclass
class HistogramConfig:
    """Parameters of the histogram signatures.

    rings : number of rings ``R`` (thesis sweep: 1, 5, 10, 15, 20, 25).
    bins : number of histogram bins ``B`` over the intensity range ``[0, 1]``
        (the thesis does not state ``B``; 16 is bionav's choice).
    """

    rings: int = 20
    bins: int = 16


class Hist(Signature):
    """[hist]: relative histogram with ``B`` bins per ring; shape ``(R * B,)``."""

    Config = HistogramConfig
    name = "hist"
    rotation_invariant = True

    def compute(self, image, *, raw=None) -> np.ndarray:
        from bionav.homing.signatures.histogram import ring_histogram

        return ring_histogram(image, rings=self.config.rings, bins=self.config.bins).ravel()


class Ent(Signature):
    """[ent]: entropy of each ring's ``B``-bin histogram (nats); shape ``(R,)``."""

    Config = HistogramConfig
    name = "ent"
    rotation_invariant = True

    def compute(self, image, *, raw=None) -> np.ndarray:
        from bionav.homing.signatures.histogram import ring_entropy

        return ring_entropy(image, rings=self.config.rings, bins=self.config.bins)
