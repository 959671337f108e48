"""``sensor=recording``: recorded POL-OP counts as a sensor source.

Plays the samples of recorded rotation files (:mod:`bionav.polcompass.recordings`;
``sensor.path`` is one ``<n>.json`` file or a session folder) in order, one per
:meth:`Recording.read`, as raw readings ``{"counts": [...], "units": K,
"photodiodes": P, "yaw": rad, "file": name, "sample": i}`` (counts flattened
unit by unit in file order). Experiments record these readings to
``run.mcap`` like any sensor's, so ``sensor=replay`` reproduces them.
"""

from __future__ import annotations

from dataclasses import dataclass

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

    def __post_init__(self):
        if not 1 <= self.photodiodes <= 16:
            raise UserError(f"sensor.photodiodes={self.photodiodes} is out of range; allowed: [1, 16].")


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
                for i in range(rot.yaw.size):
                    samples.append((rot.counts[i], float(rot.yaw[i]), f.name, i))
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
        counts, yaw, name, i = self._samples[self._cursor]
        self._cursor += 1
        k, p = counts.shape
        return {"counts": [float(v) for v in np.ravel(counts)], "units": int(k), "photodiodes": int(p),
                "yaw": yaw, "file": name, "sample": int(i)}
