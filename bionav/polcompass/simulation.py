"""A simulated polarized-light compass under a simulated sky.

:class:`CompassScene` is the world the simulated devices share: the light
source (sky or the filter-test polarizer), the heading of the pan-tilt
mount and the current pan and tilt. The simulated pan-tilt unit (plugin or
fake serial device) writes the pose, the simulated compass (plugin or fake
DLP-IO8-G) and the simulated TCM2 read it. :class:`SimulatedCompassHardware`
turns the light at the current pose into ADC counts through the whole sensor
chain of :mod:`bionav.polcompass.optics` and :mod:`bionav.polcompass.electronics`.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field

import numpy as np

from bionav.polcompass.electronics import (
    ChainParameters,
    ChannelMismatch,
    adc_counts,
    log_ratio_voltage,
)
from bionav.polcompass.optics import CompassOptics


@dataclass
class CompassScene:
    """Shared state of a simulated compass session.

    Attributes
    ----------
    source : SkyModel or PolarizerLamp
        What the compass looks at.
    mount_heading : float
        Heading of the pan-tilt mount at pan 0, radians CCW from east.
    pan, tilt : float
        Current pan (CCW) and tilt, radians, written by the pan-tilt unit.
    magnetic_declination : float
        Magnetic north relative to true north (radians, east positive), for
        the simulated TCM2.
    """

    source: object
    mount_heading: float = 0.0
    pan: float = 0.0
    tilt: float = 0.0
    magnetic_declination: float = 0.0
    lock: threading.Lock = field(default_factory=threading.Lock, repr=False, compare=False)

    def set_pose(self, pan: float, tilt: float) -> None:
        """Set the pan-tilt pose (radians), thread-safe."""
        with self.lock:
            self.pan = float(pan)
            self.tilt = float(tilt)

    def pose(self) -> tuple[float, float, float]:
        """``(sensor_heading, tilt, pan)``: the compass' heading is mount heading plus pan."""
        with self.lock:
            return self.mount_heading + self.pan, self.tilt, self.pan


@dataclass(frozen=True)
class SimulatedCompassHardware:
    """The physical compass: optics, electronics with tolerances, noise.

    Parameters
    ----------
    optics : CompassOptics
        Nominal polarizer angles, cone, polarizer efficiency.
    chain : ChainParameters
        Amplifier and ADC constants.
    mismatch : ChannelMismatch
        This device's component tolerances.
    noise_v : float
        Output noise per reading, volts (one standard deviation).
    """

    optics: CompassOptics = field(default_factory=CompassOptics)
    chain: ChainParameters = field(default_factory=ChainParameters)
    mismatch: ChannelMismatch = field(default_factory=ChannelMismatch.ideal)
    noise_v: float = 0.0

    def volts(self, scene: CompassScene, rng: np.random.Generator | None, *, n: int = 1):
        """Amplifier outputs for ``n`` readings at the scene's current pose.

        Returns
        -------
        ndarray, shape ``(n, K)``
            Volts, clipped to the rails.
        """
        heading, tilt, _ = scene.pose()
        _, q, u = self.optics.stokes(scene.source, heading, tilt)
        angles = np.asarray(self.optics.unit_angles) + self.mismatch.angle_error
        x = self.optics.unit_signals(q, u, unit_angles=angles)
        ratio = (1.0 + x) / (1.0 - x)
        v = log_ratio_voltage(ratio, chain=self.chain, mismatch=self.mismatch)
        v = np.broadcast_to(v, (n, v.shape[-1])).copy()
        if self.noise_v > 0.0:
            if rng is None:
                raise ValueError("a noisy simulated compass needs a numpy Generator")
            v += self.noise_v * rng.standard_normal(v.shape)
        return np.clip(v, 0.0, self.chain.full_scale_v)

    def counts(self, scene: CompassScene, rng: np.random.Generator | None, *, n: int = 1):
        """ADC counts, shape ``(n, K)`` int64, for ``n`` readings at the current pose."""
        return adc_counts(self.volts(scene, rng, n=n), chain=self.chain)
