"""``homing=mfdid``: matched-filter descent in image distances (Möller & Vardy 2006)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from bionav.homing.base import HomeVector, HomingMethod
from bionav.validation import Range, bounded


@dataclass
class MfdidConfig:
    """Parameters of MFDID.

    Attributes
    ----------
    image_size : list of int, optional
        ``[W, H]`` to resize to first (area averaging); None keeps the database size.
    lowpass_sigma : float
        Gaussian low-pass sigma along the azimuth as a fraction of the image
        width (the flow templates hold for small image shifts only, so the
        images are smoothed; 0.04 is best on sim_original).
    vertical_sigma : float
        Gaussian low-pass sigma along the elevation, fraction of the width.
    vertical_flow : bool
        Also use the elevation flow template (see :mod:`bionav.homing.mfdid`);
        off by default because the equal-distance assumption is poor for the
        floor and ceiling close to the robot.
    """

    image_size: Optional[list[int]] = bounded(None, length=2, item=Range(ge=8, le=8192))
    lowpass_sigma: float = bounded(0.04, ge=0.0, le=1.0)
    vertical_sigma: float = bounded(0.0, ge=0.0, le=1.0)
    vertical_flow: bool = False


class MfdidHoming(HomingMethod):
    """Holistic homing by descending the image distance with flow templates; needs aligned images.

    Reference: Möller & Vardy 2006, doi:10.1007/s00422-006-0095-3.
    """

    Config = MfdidConfig
    requires_alignment = True

    def __init__(self, config: MfdidConfig, *, geometry) -> None:
        super().__init__(config, geometry=geometry)
        from bionav.homing.imageops import resize_panorama

        _, self.work_geometry = resize_panorama(
            np.zeros((geometry.height, geometry.width), np.float32), geometry=geometry, size=config.image_size
        )

    def prepare(self, image: np.ndarray) -> dict:
        from bionav.homing.imageops import gaussian_lowpass, resize_panorama
        from bionav.homing.mfdid import azimuthal_derivative, elevation_derivative

        image, geometry = resize_panorama(image, geometry=self.geometry, size=self.config.image_size)
        smooth = gaussian_lowpass(
            image,
            sigma_azimuth=self.config.lowpass_sigma * geometry.width,
            sigma_elevation=self.config.vertical_sigma * geometry.width,
        )
        out = {"image": smooth, "d_theta": azimuthal_derivative(smooth, geometry=geometry)}
        if self.config.vertical_flow:
            out["d_eps"] = elevation_derivative(smooth, geometry=geometry)
        return out

    def home_vector(self, snapshot, current, *, neighbours=None) -> HomeVector:
        from bionav.homing.mfdid import mfdid_home_vector

        v = mfdid_home_vector(
            snapshot["image"],
            current["image"],
            geometry=self.work_geometry,
            current_derivative=current["d_theta"],
            current_elevation_derivative=current.get("d_eps"),
        )
        if not np.any(v):
            return HomeVector(angle=float("nan"))
        return HomeVector(angle=float(np.arctan2(v[1], v[0])))
