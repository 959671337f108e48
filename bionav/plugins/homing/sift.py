"""``homing=sift``: SIFT homing (thesis 5.1)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from bionav.homing.base import HomeVector, HomingMethod
from bionav.validation import Range, bounded


@dataclass
class SiftConfig:
    """Parameters of SIFT homing.

    Attributes
    ----------
    search_radius : float
        Neighbourhood radius ``q`` for matching (eq. 5.3) as a fraction of the
        image width (Schatz 2006 found 20-25 % best).
    combine : str
        ``average`` (histogram-weighted average vector, eqs. 5.14-5.15) or
        ``max`` (centre of the best histogram window).
    window : int
        Window width in 1-degree bins for ``combine=max``.
    image_size : list of int, optional
        ``[W, H]`` to resize to before feature extraction; None keeps the database size.
    n_features, contrast_threshold, edge_threshold, sigma
        OpenCV SIFT parameters.
    """

    search_radius: float = bounded(0.22, gt=0.0, le=0.5)
    combine: str = bounded("average", choices=("average", "max"))
    window: int = bounded(10, ge=1, le=360)
    image_size: Optional[list[int]] = bounded(None, length=2, item=Range(ge=8, le=8192))
    n_features: int = bounded(0, ge=0, le=100_000)
    contrast_threshold: float = bounded(0.04, ge=0.0, le=1.0)
    edge_threshold: float = bounded(10.0, gt=0.0, le=1000.0)
    sigma: float = bounded(1.6, gt=0.0, le=10.0)


class SiftHoming(HomingMethod):
    """SIFT homing: per-correspondence home angles (eq. 5.12) combined by an angle histogram.

    Needs aligned images. Reference: Vardy & Möller 2005, doi:10.1080/09540090500140958.
    """

    Config = SiftConfig
    requires_alignment = True
    cache_version = "2"  # prepare() returns bionav.homing.features.SiftFeatures with size and width

    def __init__(self, config: SiftConfig, *, geometry) -> None:
        super().__init__(config, geometry=geometry)
        from bionav.homing.imageops import resize_panorama

        _, self.work_geometry = resize_panorama(
            np.zeros((geometry.height, geometry.width), np.float32), geometry=geometry, size=config.image_size
        )

    def prepare(self, image: np.ndarray):
        from bionav.homing.features import sift_features
        from bionav.homing.imageops import resize_panorama

        image, _ = resize_panorama(image, geometry=self.geometry, size=self.config.image_size)
        c = self.config
        return sift_features(
            image,
            n_features=c.n_features,
            contrast_threshold=c.contrast_threshold,
            edge_threshold=c.edge_threshold,
            sigma=c.sigma,
        )

    def describe_prepared(self, prepared) -> dict[str, float]:
        """``keypoints``: the number of SIFT keypoints of the image (thesis tables B.1-B.4, "Keys")."""
        xy = prepared["xy"] if isinstance(prepared, dict) else prepared.xy
        return {"keypoints": float(len(xy))}

    def home_vector(self, snapshot, current, *, neighbours=None) -> HomeVector:
        from bionav.homing.sift_homing import sift_home_vector

        angle, used = sift_home_vector(
            snapshot,
            current,
            geometry=self.work_geometry,
            search_radius=self.config.search_radius * self.work_geometry.width,
            combine=self.config.combine,
            window=self.config.window,
        )
        return HomeVector(angle=angle, extras={"correspondences": used})

    def all_pairs_angles(self, prepared, *, headings: np.ndarray, neighbours: np.ndarray, snapshot_index=None,
                         workers: int = 1, progress=None, on_row=None) -> np.ndarray | None:
        """Grid-frame home angles of all pairs, each pair's descriptor distances computed once.

        The same angles as :meth:`home_vector` pair by pair
        (:func:`bionav.homing.sift_homing.sift_home_angles_all_pairs`); ``None``
        (per-pair calls) for features whose descriptors are not integers.
        ``on_row(s, angles, compass)`` receives each snapshot row (grid frame)
        as soon as it is complete, in ascending ``s``.
        """
        from bionav.geometry import wrap_angle
        from bionav.homing.sift_homing import sift_home_angles_all_pairs

        headings = np.asarray(headings, dtype=np.float64)
        no_compass = np.full(len(headings), np.nan)

        def row_done(s: int, angles: np.ndarray, _used: np.ndarray) -> None:
            on_row(s, wrap_angle(angles + headings), no_compass)

        out = sift_home_angles_all_pairs(
            prepared, geometry=self.work_geometry, search_radius=self.config.search_radius * self.work_geometry.width,
            combine=self.config.combine, window=self.config.window, snapshot_index=snapshot_index, workers=workers,
            progress=progress, on_row=None if on_row is None else row_done,
        )
        if out is None:
            return None
        return wrap_angle(out[0] + headings[None, :])
