"""Home vectors from true geometry: a stand-in for visual homing in tests and quick simulations.

In *oracle* mode the simulated camera returns the true pose ``(x, y, theta)``
instead of a rendered panorama, and :class:`GeometricHoming` turns two such
"images" into the exact home vector and compass angle, optionally with
Gaussian noise. The noise of one (snapshot, current view) pair is drawn from a
generator seeded by the pair's bytes and the method's seed, so the same pair
always gets the same error (replays reproduce runs exactly) and no hidden
global random state is involved.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass

import numpy as np

from bionav.geometry import wrap_angle
from bionav.homing.base import HomeVector, HomingMethod


@dataclass
class GeometricHomingConfig:
    """Noise of the oracle (degrees in ``_deg`` fields).

    Attributes
    ----------
    angle_noise_deg : float
        Std of the home-vector angle error.
    compass_noise_deg : float
        Std of the compass (rotation) error.
    seed : int
        Seed mixed into every pair's noise generator.
    """

    angle_noise_deg: float = 0.0
    compass_noise_deg: float = 0.0
    seed: int = 0


class GeometricHoming(HomingMethod):
    """Exact (or noisy) home vectors for "images" that are true poses ``(x, y, theta)``.

    ``home_vector(snapshot, current)`` returns
    ``angle = atan2(s_y - c_y, s_x - c_x) - c_theta`` (current view's frame,
    radians CCW) and ``compass = c_theta - s_theta``, each plus noise.
    """

    Config = GeometricHomingConfig
    requires_alignment = False

    def __init__(self, config: GeometricHomingConfig | None = None, *, geometry=None) -> None:
        super().__init__(config or GeometricHomingConfig(), geometry=geometry)

    def prepare(self, image: np.ndarray) -> np.ndarray:
        pose = np.asarray(image, dtype=np.float64).reshape(-1)
        if pose.shape != (3,):
            raise ValueError("GeometricHoming needs pose 'images' (x, y, theta) from an oracle camera")
        return pose

    def home_vector(self, snapshot, current, *, neighbours=None) -> HomeVector:
        s, c = np.asarray(snapshot, float), np.asarray(current, float)
        angle = np.arctan2(s[1] - c[1], s[0] - c[0]) - c[2]
        compass = c[2] - s[2]
        cfg = self.config
        if cfg.angle_noise_deg > 0 or cfg.compass_noise_deg > 0:
            digest = hashlib.sha256(s.tobytes() + c.tobytes() + int(cfg.seed).to_bytes(8, "little", signed=True))
            rng = np.random.default_rng(int.from_bytes(digest.digest()[:8], "little"))
            e = rng.standard_normal(2)
            angle += np.radians(cfg.angle_noise_deg) * e[0]
            compass += np.radians(cfg.compass_noise_deg) * e[1]
        return HomeVector(float(wrap_angle(angle)), float(wrap_angle(compass)))


def oracle_camera(pose, capture_index: int) -> np.ndarray:
    """Camera for oracle mode: the "image" is the true pose ``(x, y, theta)`` as float64."""
    return np.array(pose.as_tuple(), dtype=np.float64)
