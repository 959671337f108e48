"""``sensor=polcompass_sim``: the simulated polarized-light compass.

Produces the same raw readings as ``polcompass_serial`` (10-bit counts per
POL-OP unit) from the physical model: the experiment's sky (or filter-test
polarizer) integrated over each photodiode's acceptance cone, the log-ratio
amplifiers with this device's component tolerances, noise and the ADC
(:mod:`bionav.polcompass`). The tolerances are drawn once from
``device_seed`` (the same seed is the same physical device); the noise comes
from the generator the experiment passes in.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.errors import UserError
from bionav.plugins.sensors.base import SensorPlugin
from bionav.plugins.sensors.polcompass_serial import READING_SCHEMA
from bionav.validation import Range, bounded


@dataclass
class PolCompassSimConfig:
    """Parameters of ``sensor=polcompass_sim`` (the simulated device)."""

    noise_v: float = bounded(0.005, ge=0.0, le=10.0)  # output noise per reading, volts (about one ADC step)
    gain_sigma: float = bounded(0.03, ge=0.0, le=10.0)  # relative spread of the log-ratio gains
    offset_sigma_v: float = bounded(0.03, ge=0.0, le=10.0)  # spread of the output offsets, volts
    # relative spread of the photodiode pairs' sensitivity ratio; fitted on the real POL-OP recordings: photodiode log
    # gains spread 0.1 (self-calibration, docs/polcompass.md), a pair's ratio sqrt(2) times that
    sensitivity_sigma: float = bounded(0.14, ge=0.0, le=10.0)
    angle_sigma_deg: float = bounded(2.0, ge=0.0, le=90.0)  # polarizer mounting spread; measured on the recordings: 2.1
    device_seed: int = bounded(7, ge=0)  # which simulated device (its tolerances)
    polarizer_efficiency: float = bounded(0.99, ge=0.0, le=1.0)
    cone_half_angle_deg: float = bounded(10.0, ge=0.0, lt=90.0)  # Hamamatsu S5821-1 with lens
    unit_angles_deg: list[float] = bounded([0.0, 60.0, 120.0], length=(2, 8), item=Range(ge=-360.0, le=360.0))
    lines: list[int] = bounded([1, 2, 3], length=(1, 8), item=Range(ge=1, le=8))


def build_hardware(config: PolCompassSimConfig):
    """The :class:`~bionav.polcompass.SimulatedCompassHardware` described by ``config``."""
    from bionav.polcompass import CompassOptics, SimulatedCompassHardware, sample_mismatch

    if len(config.unit_angles_deg) != len(config.lines):
        raise UserError(
            f"sensor.unit_angles_deg has {len(config.unit_angles_deg)} entries but sensor.lines has "
            f"{len(config.lines)}; give one polarizer angle per POL-OP unit."
        )
    optics = CompassOptics(
        unit_angles=tuple(np.deg2rad(config.unit_angles_deg)),
        polarizer_efficiency=config.polarizer_efficiency,
        cone_half_angle=np.deg2rad(config.cone_half_angle_deg),
    )
    mismatch = sample_mismatch(
        np.random.default_rng(config.device_seed),
        n_units=len(config.lines),
        gain_sigma=config.gain_sigma,
        offset_sigma_v=config.offset_sigma_v,
        sensitivity_sigma=config.sensitivity_sigma,
        angle_sigma=np.deg2rad(config.angle_sigma_deg),
    )
    return SimulatedCompassHardware(optics=optics, mismatch=mismatch, noise_v=config.noise_v)


class PolCompassSim(SensorPlugin):
    """Simulated polarized-light compass (needs the experiment's simulated scene)."""

    Config = PolCompassSimConfig
    simulated = True
    schema_name = "bionav.PolCompassReading"
    schema = READING_SCHEMA

    def __init__(self, config: PolCompassSimConfig) -> None:
        super().__init__(config)
        self.hardware = build_hardware(config)
        self.scene = None
        self.rng = None

    def attach_simulation(self, scene, rng) -> None:
        self.scene = scene
        self.rng = rng

    def read(self) -> dict:
        if self.scene is None:
            raise UserError(
                "sensor=polcompass_sim needs a simulated sky, which only a simulation experiment provides; "
                "use it with experiment=pol_compass, or choose sensor=polcompass_serial for the real compass."
            )
        counts = self.hardware.counts(self.scene, self.rng)[0]
        return {"counts": [int(c) for c in counts], "lines": [int(v) for v in self.config.lines]}
