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
from bionav.validation import Range, bounded

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
    """Parameters of ``sensor=recording``.

    path : a rotation file ``<n>.json`` or a session folder. photodiodes : per unit in the files.
    loop : start again at the end instead of stopping.
    How the array reads (used by ``experiment=pol_compass mode=rotation`` on recorded counts; the
    same keys as ``recordings.*`` of ``experiment=pol_recordings``): tilt_deg, azimuth_sign (-1:
    file azimuths clockwise), photodiode_angles_deg (unit frame, file order), pairs (POL-OPs),
    saturation_counts, dark_counts, imbalance_decades.
    calibration : ``none`` (nominal photodiode gains and polarizer angles), ``auto`` (self-calibrated from
        the played rotations and their yaw, :mod:`bionav.polcompass.array_calibration`) or the path of a
        ``calibration.json`` written by ``experiment=pol_recordings recordings.calibration=auto``.
    """

    path: str = ""
    photodiodes: int = bounded(4, ge=1, le=16)
    loop: bool = False
    tilt_deg: float = bounded(45.0, ge=0.0, le=90.0)
    azimuth_sign: float = bounded(-1.0, choices=(-1.0, 1.0))
    photodiode_angles_deg: list[float] = bounded([-45.0, 45.0, 0.0, 90.0], length=(1, 16), item=Range(ge=-360.0, le=360.0))
    pairs: list[list[int]] = bounded([[2, 3], [1, 0]], length=(1, 8), item=Range(length=2, item=Range(ge=0, le=15)))
    saturation_counts: float = bounded(11000.0, gt=0.0, le=1e12)
    dark_counts: float = bounded(1.0, ge=0.0, le=1e12)
    imbalance_decades: float = bounded(0.15, gt=0.0, le=3.0)
    calibration: str = "none"


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
