"""Average landmark vector (ALV) homing as a bionav plugin.

Landmarks are the pixels of a band around the horizon that are darker (or
brighter) than a quantile of that band. The ALV of a view is the mean of the
unit vectors towards its landmark pixels; the home vector is
``ALV(current) - ALV(snapshot)`` (Lambrinos et al. 2000, "A mobile robot
employing insect strategies for navigation", Robotics and Autonomous Systems
30, doi:10.1016/S0921-8890(99)00064-0). Needs aligned images. Angles are
radians, counter-clockwise, in the current view's frame (bionav's canonical
panoramas).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.homing.base import HomeVector, HomingMethod


@dataclass
class AlvConfig:
    """Parameters of ALV homing.

    Attributes
    ----------
    band_deg : float
        Half-height of the band around the horizon that holds landmarks, degrees.
    quantile : float
        Pixels beyond this quantile of the band's brightness are landmarks.
    dark_landmarks : bool
        Landmarks are the darkest pixels (True) or the brightest (False).
    """

    band_deg: float = 10.0
    quantile: float = 0.2
    dark_landmarks: bool = True


class AlvHoming(HomingMethod):
    """Average-landmark-vector homing (no test steps, aligned images)."""

    Config = AlvConfig
    requires_alignment = True

    def prepare(self, image: np.ndarray) -> np.ndarray:
        g = self.geometry
        elevation = g.row_elevations()
        band = image[np.abs(elevation) <= np.deg2rad(self.config.band_deg)]
        threshold = np.quantile(band, self.config.quantile)
        mask = band <= threshold if self.config.dark_landmarks else band >= threshold
        theta = g.column_azimuths()
        weights = mask.sum(axis=0)
        if weights.sum() == 0:
            return np.zeros(2)
        return np.array([np.dot(weights, np.cos(theta)), np.dot(weights, np.sin(theta))]) / weights.sum()

    def home_vector(self, snapshot, current, *, neighbours=None) -> HomeVector:
        v = current - snapshot
        if not np.any(v):
            return HomeVector(angle=float("nan"))
        return HomeVector(angle=float(np.arctan2(v[1], v[0])))
