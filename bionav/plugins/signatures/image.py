"""The [image] signature: the complete image (thesis 3.5.1)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.homing.signatures.base import Signature


@dataclass
class ImageConfig:
    """[image] has no parameters (image size and preprocessing belong to ``db``/``preprocess``)."""


class Image(Signature):
    """[image]: every pixel of the unfolded panorama, row-major; shape ``(H * W,)``.

    With it, the potential of eq. 5.17 is the sum of squared pixel differences
    (the image distance of Zeil et al. 2003 / Möller & Vardy 2006). Not rotation invariant.
    """

    Config = ImageConfig
    name = "image"
    rotation_invariant = False

    def compute(self, image, *, raw=None) -> np.ndarray:
        return np.asarray(image, dtype=np.float64).ravel()

    def derivative(self, image, direction, *, step: float = 0.05) -> np.ndarray:
        """Exact: the signature is the image itself, so the derivative is ``direction``."""
        return np.asarray(direction, dtype=np.float64).ravel()
