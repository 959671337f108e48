"""``pantilt=sim``: a simulated pan-tilt unit with the PTU-46-17.5's geometry.

Moves are instantaneous and quantised to the unit's resolution (185.1428
seconds of arc per position); the reached pose is written into the
experiment's simulated scene, where the simulated sensors read it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from bionav.errors import UserError
from bionav.plugins.sensors.base import PanTiltPlugin
from bionav.validation import bounded


@dataclass
class PanTiltSimConfig:
    """Parameters of ``pantilt=sim`` (defaults: PTU-46-17.5)."""

    resolution_arcsec: float = bounded(185.1428, gt=0.0, le=36000.0)
    pan_min_pos: int = bounded(-3090, ge=-1_000_000, le=1_000_000)
    pan_max_pos: int = bounded(3090, ge=-1_000_000, le=1_000_000)
    tilt_min_pos: int = bounded(-907, ge=-1_000_000, le=1_000_000)
    tilt_max_pos: int = bounded(604, ge=-1_000_000, le=1_000_000)


class PanTiltSim(PanTiltPlugin):
    """Simulated pan-tilt unit."""

    Config = PanTiltSimConfig
    config_group = "pantilt"
    simulated = True

    def __init__(self, config: PanTiltSimConfig) -> None:
        super().__init__(config)
        self.scene = None
        self._res = math.radians(config.resolution_arcsec / 3600.0)

    def attach_simulation(self, scene, rng) -> None:
        self.scene = scene

    def resolution(self) -> tuple[float, float]:
        return self._res, self._res

    def limits(self) -> tuple[float, float, float, float]:
        c = self.config
        return c.pan_min_pos * self._res, c.pan_max_pos * self._res, c.tilt_min_pos * self._res, c.tilt_max_pos * self._res

    def move_to(self, pan: float, tilt: float) -> dict:
        c = self.config
        pan_pos = int(round(pan / self._res))
        tilt_pos = int(round(tilt / self._res))
        if not (c.pan_min_pos <= pan_pos <= c.pan_max_pos and c.tilt_min_pos <= tilt_pos <= c.tilt_max_pos):
            lo_p, hi_p, lo_t, hi_t = (math.degrees(v) for v in self.limits())
            raise UserError(
                f"pantilt=sim cannot move to pan {math.degrees(pan):.2f} deg, tilt {math.degrees(tilt):.2f} deg: "
                f"outside the limits pan [{lo_p:.2f}, {hi_p:.2f}], tilt [{lo_t:.2f}, {hi_t:.2f}] deg. "
                "Keep the experiment's pan/tilt range within them."
            )
        if self.scene is not None:
            self.scene.set_pose(pan_pos * self._res, tilt_pos * self._res)
        return {
            "pan_pos": pan_pos,
            "tilt_pos": tilt_pos,
            "pan": pan_pos * self._res,
            "tilt": tilt_pos * self._res,
            "pan_cmd": float(pan),
            "tilt_cmd": float(tilt),
        }
