"""Ring-wise statistics signatures [mean] [std] [skew] [kurt] (thesis 3.5.2, eqs. 3.49-3.52).

All four are rotation invariant. ``rings`` ``R`` equal row bands of the
unfolded image (= concentric rings of the mirror image) give ``R`` values.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.homing.signatures.base import Signature
from bionav.validation import bounded


@dataclass
class RingsConfig:
    """Parameters of a ring-wise statistic.

    rings : number of rings ``R`` (thesis sweep: 1, 5, 10, 15, 20, 25; the
        thesis' best ring-based results mostly use 20 or 25).
    """

    rings: int = bounded(20, ge=1, le=1000)


class Mean(Signature):
    """[mean]: average intensity per ring (eq. 3.49); shape ``(R,)``."""

    Config = RingsConfig
    name = "mean"
    rotation_invariant = True

    def compute(self, image, *, raw=None) -> np.ndarray:
        from bionav.homing.signatures.statistics import ring_mean

        return ring_mean(image, rings=self.config.rings)


class Std(Signature):
    """[std]: population standard deviation per ring (eq. 3.50); shape ``(R,)``."""

    Config = RingsConfig
    name = "std"
    rotation_invariant = True

    def compute(self, image, *, raw=None) -> np.ndarray:
        from bionav.homing.signatures.statistics import ring_std

        return ring_std(image, rings=self.config.rings)


class Skew(Signature):
    """[skew]: skewness per ring (eq. 3.51); shape ``(R,)``."""

    Config = RingsConfig
    name = "skew"
    rotation_invariant = True

    def compute(self, image, *, raw=None) -> np.ndarray:
        from bionav.homing.signatures.statistics import ring_skewness

        return ring_skewness(image, rings=self.config.rings)


class Kurt(Signature):
    """[kurt]: excess kurtosis per ring (eq. 3.52); shape ``(R,)``."""

    Config = RingsConfig
    name = "kurt"
    rotation_invariant = True

    def compute(self, image, *, raw=None) -> np.ndarray:
        from bionav.homing.signatures.statistics import ring_kurtosis

        return ring_kurtosis(image, rings=self.config.rings)
