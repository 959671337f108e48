"""``sensor=recording``: recorded POL-OP counts as a sensor source.

Plays the samples of recorded rotation files (:mod:`bionav.polcompass.recordings`;
``sensor.path`` is one ``<n>.json`` file or a session folder) in order, one per
:meth:`Recording.read`, as raw readings ``{"counts": [...], "units": K,
"photodiodes": P, "yaw": rad, "file": name, "sample": i}`` (counts flattened
unit by unit in file order). Experiments record these readings to
``run.mcap`` like any sensor's, so ``sensor=replay`` reproduces them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from bionav.errors import UserError
from bionav.plugins.sensors.base import SensorPlugin

READING_SCHEMA = {
    "type": "object",
    "properties": {
        "counts": {"type": "array", "items": {"type": "number"}, "description": "photodiode counts, K x P flattened"},
        "units": {"type": "integer"},
        "photodiodes": {"type": "integer"},
        "yaw": {"type": "number", "description": "IMU yaw, radians CCW (up to a constant)"},
        "azimuths": {"type": "array", "items": {"type": "number"}, "description": "unit azimuths as in the file, radians"},
        "file": {"type": "string"},
        "sample": {"type": "integer"},
    },
    "required": ["counts", "units", "photodiodes"],
}


@dataclass
class RecordingConfig:
    """Parameters of ``sensor=recording``."""

    path: str = ""  # a rotation file <n>.json or a session folder
    photodiodes: int = 4  # photodiodes per unit in the files, [1, 16]
    loop: bool = False  # start again at the end instead of stopping
    # how the array reads (used by experiment=pol_compass mode=rotation on recorded counts)
    tilt_deg: float = 45.0  # zenith angle of the units, [0, 90]
    azimuth_sign: float = -1.0  # file azimuths clockwise (-1) or counter-clockwise (+1)
    photodiode_angles_deg: list = field(default_factory=lambda: [-45.0, 45.0, 0.0, 90.0])
    pairs: list = field(default_factory=lambda: [[2, 3], [1, 0]])
    saturation_counts: float = 11000.0  # (0, inf)
    dark_counts: float = 5.0  # [0, inf)
    imbalance_decades: float = 0.15  # (0, 3]

    def __post_init__(self):
        if not 1 <= self.photodiodes <= 16:
            raise UserError(f"sensor.photodiodes={self.photodiodes} is out of range; allowed: [1, 16].")
        if not 0.0 <= self.tilt_deg <= 90.0:
            raise UserError(f"sensor.tilt_deg={self.tilt_deg} is out of range; allowed: [0, 90].")
        if self.azimuth_sign not in (-1.0, 1.0):
            raise UserError(f"sensor.azimuth_sign={self.azimuth_sign} must be -1 (clockwise) or 1 (counter-clockwise).")
        if self.saturation_counts <= 0 or self.dark_counts < 0 or not 0 < self.imbalance_decades <= 3:
            raise UserError("sensor.saturation_counts must be > 0, sensor.dark_counts >= 0 and sensor.imbalance_decades in (0, 3].")


class Recording(SensorPlugin):
    """Recorded POL-OP counts, sample by sample."""

    Config = RecordingConfig
    schema_name = "bionav.PolOpArrayReading"
    schema = READING_SCHEMA

    def __init__(self, config: RecordingConfig) -> None:
        super().__init__(config)
        self._samples = None
        self._cursor = 0

    def open(self) -> None:
        if self._samples is not None:
            return
        from bionav.polcompass.recordings import find_sessions, load_rotation

        if not self.config.path:
            raise UserError("sensor=recording needs sensor.path=<rotation .json file or session folder>.")
        samples = []
        for _folder, files in find_sessions(self.config.path):
            for f in files:
                rot = load_rotation(f, n_photodiodes=self.config.photodiodes)
                az = [float(a) for a in rot.file_azimuths]
                for i in range(rot.yaw.size):
                    samples.append((rot.counts[i], float(rot.yaw[i]), f.name, i, az))
        self._samples = samples

    def read(self) -> dict:
        self.open()
        if self._cursor >= len(self._samples):
            if not self.config.loop or not self._samples:
                raise UserError(
                    f"sensor=recording has played all {len(self._samples)} samples of {self.config.path}; "
                    "ask for fewer readings or set sensor.loop=true."
                )
            self._cursor = 0
        counts, yaw, name, i, az = self._samples[self._cursor]
        self._cursor += 1
        k, p = counts.shape
        return {"counts": [float(v) for v in np.ravel(counts)], "units": int(k), "photodiodes": int(p),
                "yaw": yaw, "azimuths": az, "file": name, "sample": int(i)}

    def remaining(self) -> int:
        """Samples not read yet."""
        self.open()
        return len(self._samples) - self._cursor
