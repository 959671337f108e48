"""``sensor=tcm2_sim``: a simulated TCM2 compass riding on the simulated pan-tilt unit.

Reports the compass bearing (clockwise from magnetic north) of the compass
plate's forward axis in the experiment's simulated scene, with Gaussian noise
and the TCM2's 0.1 degree resolution, as the same output words the real
device sends (so readings look exactly like ``sensor=tcm2``'s).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from bionav.errors import UserError
from bionav.plugins.sensors.base import SensorPlugin
from bionav.plugins.sensors.tcm2 import READING_SCHEMA
from bionav.validation import bounded


@dataclass
class TCM2SimConfig:
    """Parameters of ``sensor=tcm2_sim``."""

    noise_deg: float = bounded(0.3, ge=0.0, le=180.0)  # heading noise, one standard deviation
    # TCM2 forward axis relative to the polarized-light compass' x axis (CCW)
    mounting_offset_deg: float = bounded(0.0, ge=-360.0, le=360.0)
    output: str = bounded("standard", choices=("standard", "nmea"))


def simulated_attitude(scene, rng, *, noise_deg: float, mounting_offset_deg: float = 0.0) -> tuple[float, float, float]:
    """``(heading_deg, pitch_deg, roll_deg)`` of a TCM2 on the simulated compass plate.

    The bearing is clockwise from magnetic north: ``90 deg - azimuth`` minus
    the magnetic declination (east positive).
    """
    heading, tilt, _ = scene.pose()
    azimuth = heading + math.radians(mounting_offset_deg)
    bearing = math.degrees(math.pi / 2.0 - azimuth - scene.magnetic_declination)
    if noise_deg > 0.0:
        bearing += noise_deg * float(rng.standard_normal())
    return bearing % 360.0, math.degrees(tilt), 0.0


class TCM2Sim(SensorPlugin):
    """Simulated TCM2 (needs the experiment's simulated scene)."""

    Config = TCM2SimConfig
    simulated = True
    schema_name = "bionav.TCM2Reading"
    schema = READING_SCHEMA

    def __init__(self, config: TCM2SimConfig) -> None:
        super().__init__(config)
        if config.output not in ("standard", "nmea"):
            raise UserError(f"output={config.output!r} is not a TCM2 output format; choose standard or nmea.")
        self.scene = None
        self.rng = None

    def attach_simulation(self, scene, rng) -> None:
        self.scene = scene
        self.rng = rng

    def read(self) -> dict:
        from bionav.plugins.sensors.tcm2_protocol import format_nmea, format_standard, parse_line

        if self.scene is None:
            raise UserError("sensor=tcm2_sim needs a simulated scene; use it within experiment=pol_compass.")
        heading, pitch, roll = simulated_attitude(
            self.scene, self.rng, noise_deg=self.config.noise_deg, mounting_offset_deg=self.config.mounting_offset_deg
        )
        if round(heading, 1) >= 360.0:
            heading = 0.0
        if self.config.output == "nmea":
            line = format_nmea(heading_deg=heading)
        else:
            line = format_standard(heading_deg=heading, pitch_deg=pitch, roll_deg=roll)
        text = line.strip()
        return {"line": text, **parse_line(text)}
