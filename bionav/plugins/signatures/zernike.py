"""``signature=zernike``: Zernike-moment amplitudes of the panorama (Sun, Yue & Mangan 2020, eLife).

doi:10.7554/eLife.54026. The amplitudes ``|Z_nm|`` are rotation invariant, so
``homing=parameter signature=zernike`` needs no aligned views; the phases
give the rotation between two views (:meth:`Zernike.rotation`, used by
``experiment=route_homing`` as a visual compass). See
:mod:`bionav.homing.signatures.zernike` for the mapping onto the disc.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.homing.signatures.base import Signature
from bionav.validation import bounded

MODES = ("intensity", "skyline")


@dataclass
class ZernikeConfig:
    """Parameters of ``signature=zernike``.

    order : highest moment order ``n``, 1..40 (the paper: 16; amplitudes of
        ``(order + 1)(order + 2) / 2`` rounded moments).
    mode : ``intensity`` (moments of the grey image) or ``skyline`` (of the
        binary sky mask ``image > threshold``, the paper's input).
    threshold : sky threshold in [0, 1] for ``mode=skyline``.
    """

    order: int = bounded(16, ge=1, le=40)
    mode: str = bounded("intensity", choices=MODES)
    threshold: float = bounded(0.7, ge=0.0, le=1.0)


class Zernike(Signature):
    """[zernike]: amplitudes ``|Z_nm|`` of the panorama on the unit disc; shape ``(K,)``; rotation invariant."""

    Config = ZernikeConfig
    name = "zernike"
    rotation_invariant = True

    def __init__(self, config=None) -> None:
        super().__init__(config)

    def _input(self, image) -> np.ndarray:
        img = np.asarray(image, np.float64)
        if img.ndim == 3:
            img = img.mean(axis=2)
        return (img > self.config.threshold).astype(np.float64) if self.config.mode == "skyline" else img

    def moments(self, image) -> tuple[np.ndarray, np.ndarray]:
        """Complex moments and their ``(n, m)`` (:func:`bionav.homing.signatures.zernike.zernike_moments`)."""
        from bionav.homing.signatures.zernike import zernike_moments

        return zernike_moments(self._input(image), order=self.config.order)

    def compute(self, image, *, raw=None) -> np.ndarray:
        return np.abs(self.moments(image)[0])

    def rotation(self, current, snapshot) -> float:
        """``heading(current) - heading(snapshot)`` in radians CCW, from the moments' phases."""
        from bionav.homing.signatures.zernike import rotation_from_moments

        zc, idx = self.moments(current)
        zs, _ = self.moments(snapshot)
        return rotation_from_moments(zc, zs, idx)
