"""Homing in Scale Space as a homing plugin: ``hiss``."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from bionav.homing.base import HomeVector, HomingMethod
from bionav.validation import Range, bounded


class HissHoming(HomingMethod):
    """Homing in Scale Space (Churchill & Vardy 2008), SIFT-based, no compass needed.

    SIFT matches whose keypoints shrank pull the home vector towards them,
    those that grew push it away (:func:`bionav.homing.hiss.hiss`). Only
    azimuths within the current view are used, so the views need not be
    aligned.
    """

    cache_version = "2"  # prepare() returns bionav.homing.features.SiftFeatures (was a dict)

    name = "hiss"
    requires_alignment = False

    @dataclass
    class Config:
        """Parameters of HiSS.

        image_size: [W, H] the panorama is resized to (area averaging); null keeps it.
        wrap_pad: columns copied from the other end on each side before SIFT, as a
            fraction of the width (keypoints across the 0/360 degree seam).
        ratio: Lowe ratio of the descriptor matching.
        scale_threshold: matches with size ratio within [1/(1+t), 1+t] are ignored.
        n_features, contrast_threshold, edge_threshold, sigma: OpenCV SIFT parameters.
        """

        image_size: list[int] | None = bounded(None, length=2, item=Range(ge=8, le=8192))
        wrap_pad: float = bounded(0.1, ge=0.0, le=0.5)
        ratio: float = bounded(0.8, gt=0.0, le=1.0)
        scale_threshold: float = bounded(0.0, ge=0.0, le=10.0)
        n_features: int = bounded(0, ge=0, le=100_000)
        contrast_threshold: float = bounded(0.04, ge=0.0, le=1.0)
        edge_threshold: float = bounded(10.0, gt=0.0, le=1000.0)
        sigma: float = bounded(1.6, gt=0.0, le=10.0)

    def __init__(self, config: Any, *, geometry) -> None:
        super().__init__(config, geometry=geometry)

    def prepare(self, image):
        """SIFT features of the (resized) panorama, seamless across the border (:func:`bionav.homing.features.sift_features`)."""
        from bionav.homing.features import sift_features
        from bionav.homing.imageops import resize_panorama

        img = np.asarray(image, dtype=np.float32)
        if img.ndim == 3:
            img = img.mean(axis=2, dtype=np.float32)
        geometry = self.geometry
        if img.shape != (geometry.height, geometry.width):
            geometry = geometry.resized(img.shape[1], img.shape[0])
        img, _ = resize_panorama(img, geometry=geometry, size=self.config.image_size)
        cfg = self.config
        return sift_features(
            img,
            wrap_pad=cfg.wrap_pad,
            n_features=cfg.n_features,
            contrast_threshold=cfg.contrast_threshold,
            edge_threshold=cfg.edge_threshold,
            sigma=cfg.sigma,
        )

    def home_vector(self, snapshot, current, *, neighbours=None) -> HomeVector:
        """HiSS home direction in the current view's frame (NaN when no match changed scale)."""
        from bionav.homing.hiss import hiss

        r = hiss(snapshot, current, ratio=self.config.ratio, scale_threshold=self.config.scale_threshold)
        return HomeVector(
            angle=r.home_angle,
            compass=None,
            extras={"n_matches": r.n_matches, "n_contracted": r.n_contracted, "n_expanded": r.n_expanded},
        )
