"""Histogram signatures [hist] and [ent] (thesis 3.5.2, eqs. 3.53-3.54).

Both rotation invariant. [hist] holds relative frequencies and [ent] the
Shannon entropy of them; the bins span the fixed range ``[0, 1]`` by default,
or each image's own range (see :mod:`bionav.homing.signatures.histogram` for
these documented choices).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.homing.signatures.base import Signature
from bionav.validation import bounded


@dataclass
class HistogramConfig:
    """Parameters of the histogram signatures.

    rings : number of rings ``R`` (thesis sweep: 1, 5, 10, 15, 20, 25).
    bins : number of histogram bins ``B`` (the thesis does not state ``B``;
        16 is bionav's choice).
    bin_range : ``unit`` -- the fixed range ``[0, 1]`` shared by all images
        (like the fixed grey levels of 8-bit images); ``image`` -- each image's
        own ``[min, max]``, which keeps the histogram informative after
        preprocessing that compresses the range (a low-passed, edge-filtered
        panorama may lie within ``[0, 0.02]`` and fill only the first bin),
        at the price of depending on two extreme pixels.
    """

    rings: int = bounded(20, ge=1, le=1000)
    bins: int = bounded(16, ge=2, le=4096)
    bin_range: str = bounded("unit", choices=("unit", "image"))


def _value_range(signature):
    return None if signature.config.bin_range == "image" else (0.0, 1.0)


class Hist(Signature):
    """[hist]: relative histogram with ``B`` bins per ring; shape ``(R * B,)``."""

    Config = HistogramConfig
    name = "hist"
    rotation_invariant = True

    def compute(self, image, *, raw=None) -> np.ndarray:
        from bionav.homing.signatures.histogram import ring_histogram

        return ring_histogram(
            image, rings=self.config.rings, bins=self.config.bins, value_range=_value_range(self)
        ).ravel()


class Ent(Signature):
    """[ent]: entropy of each ring's ``B``-bin histogram (nats); shape ``(R,)``."""

    Config = HistogramConfig
    name = "ent"
    rotation_invariant = True

    def compute(self, image, *, raw=None) -> np.ndarray:
        from bionav.homing.signatures.histogram import ring_entropy

        return ring_entropy(image, rings=self.config.rings, bins=self.config.bins, value_range=_value_range(self))
