"""Five-channel (UV, B, G, R, IR) log sensor: serial driver and simulator plugins.

``sensor=spectral5_serial sensor.port=/dev/ttyUSB0`` talks to the ADuC812 board
over bionav's line protocol (documented in :mod:`bionav.spectral.protocol`);
``sensor=spectral5_sim`` computes the same readings from the physical model of
:mod:`bionav.spectral`. Both return raw readings as an integer array of shape
``(n, 6)``: ``uv, b, g, r, ir, ref`` 12-bit ADC counts.

Experiments record every raw reading to ``run.mcap`` under the topic
:data:`RAW_TOPIC` (``/spectral5/raw``, schema ``bionav.Spectral5Reading``: one
message per reading with integer fields ``uv, b, g, r, ir, ref`` and, where the
sensor sits on a pan-tilt unit, ``pan`` and ``tilt`` in radians), so that a
session can be replayed.

This module stays light: pyserial and the physical model are imported inside
methods.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from bionav.errors import DeviceError

#: MCAP topic of raw readings.
RAW_TOPIC = "/spectral5/raw"
#: Schema name and JSON schema of one raw reading message.
RAW_SCHEMA_NAME = "bionav.Spectral5Reading"
RAW_SCHEMA = {
    "type": "object",
    "title": RAW_SCHEMA_NAME,
    "description": "One raw reading of the five-channel log sensor (12-bit ADC counts).",
    "properties": {
        "uv": {"type": "integer"}, "b": {"type": "integer"}, "g": {"type": "integer"},
        "r": {"type": "integer"}, "ir": {"type": "integer"}, "ref": {"type": "integer"},
        "pan": {"type": "number", "description": "pan angle, radians CCW"},
        "tilt": {"type": "number", "description": "tilt angle, radians, positive up"},
    },
    "required": ["uv", "b", "g", "r", "ir", "ref"],
}
_FIELDS = ("uv", "b", "g", "r", "ir", "ref")


class BadReply(DeviceError):
    """A garbage, short, incomplete or missing reply (worth retrying the command)."""


def reading_messages(readings, **extra) -> list[dict]:
    """Raw readings ``(n, 6)`` as :data:`RAW_TOPIC` messages (``extra`` fields added to each)."""
    return [dict(zip(_FIELDS, (int(v) for v in row)), **extra) for row in np.asarray(readings).reshape(-1, 6)]


def readings_from_messages(messages) -> np.ndarray:
    """Inverse of :func:`reading_messages`: ``(n, 6)`` int array from message dicts."""
    return np.array([[int(m[f]) for f in _FIELDS] for m in messages], dtype=np.int64).reshape(-1, 6)


class Spectral5Serial:
    """Driver of the five-channel sensor board (ADuC812) over a serial line.

    Protocol: :mod:`bionav.spectral.protocol` (9600 8N1, ``M<n>\\r`` /
    ``?\\r``). Every reply line is awaited at most ``timeout_s``; garbage, short
    and silent replies are retried ``retries`` times, then raise
    :class:`~bionav.errors.DeviceError` naming the port and the command.
    """

    config_group = "sensor"

    @dataclass
    class Config:
        """Parameters of ``sensor=spectral5_serial``.

        Attributes
        ----------
        port : str
            Serial device (``/dev/ttyUSB0``, ``COM3``, a pty path).
        baudrate : int
            Line speed (8N1 framing is fixed by the protocol).
        timeout_s : float
            Longest wait for one reply line, seconds.
        retries : int
            Repetitions of a command after a garbage, short or silent reply.
        readings_per_point : int
            ``n`` of ``M<n>``: subsequent readings per measurement.
        """

        port: str = "/dev/ttyUSB0"
        baudrate: int = 9600
        timeout_s: float = 2.0
        retries: int = 1
        readings_per_point: int = 1

    def __init__(self, config: "Spectral5Serial.Config | None" = None, **_ignored) -> None:
        self.config = config or self.Config()
        self._serial = None

    # -- connection -------------------------------------------------------
    def open(self) -> "Spectral5Serial":
        """Open the port (idempotent)."""
        if self._serial is not None:
            return self
        import serial

        c = self.config
        try:
            self._serial = serial.Serial(
                port=c.port, baudrate=c.baudrate, bytesize=serial.EIGHTBITS, parity=serial.PARITY_NONE,
                stopbits=serial.STOPBITS_ONE, timeout=c.timeout_s, write_timeout=c.timeout_s,
                xonxoff=False, rtscts=False, exclusive=True,
            )
        except (serial.SerialException, OSError, ValueError) as exc:
            raise DeviceError(
                f"spectral5_serial: cannot open serial port {c.port!r} ({exc}). Check that the sensor is plugged "
                f"in, that the port exists and no other program holds it, and set sensor.port=<device> "
                f"(e.g. /dev/ttyUSB0 or COM3)."
            ) from None
        return self

    def close(self) -> None:
        """Close the port."""
        if self._serial is not None:
            try:
                self._serial.close()
            finally:
                self._serial = None

    def __enter__(self) -> "Spectral5Serial":
        return self.open()

    def __exit__(self, *exc) -> None:
        self.close()

    # -- protocol ---------------------------------------------------------
    def _fail(self, command: bytes, problem: str) -> BadReply:
        c = self.config
        cmd = command.decode("ascii", "replace").rstrip("\r")
        return BadReply(
            f"spectral5_serial on {c.port}: {problem} in reply to {cmd!r}. Check the cable and power, that the "
            f"board runs bionav's line protocol at {c.baudrate} 8N1 (sensor.baudrate), and raise "
            f"sensor.timeout_s if the device is slow."
        )

    def _readline(self, command: bytes) -> bytes:
        import serial

        try:
            line = self._serial.read_until(b"\r\n", size=512)
        except (serial.SerialException, OSError) as exc:
            raise DeviceError(
                f"spectral5_serial on {self.config.port}: the device went away while answering "
                f"{command.decode('ascii', 'replace').rstrip()!r} ({exc}). Reconnect it and resume; readings "
                f"taken so far are in run.mcap."
            ) from None
        if not line.endswith(b"\r\n"):
            if line:
                raise self._fail(command, f"incomplete line {line!r} (no reply within {self.config.timeout_s} s)")
            raise self._fail(command, f"no reply within {self.config.timeout_s} s (device silent)")
        return line[:-2]

    def _send(self, command: bytes) -> None:
        import serial

        if self._serial is None:
            self.open()
        try:
            self._serial.reset_input_buffer()
            self._serial.write(command)
            self._serial.flush()
        except (serial.SerialException, OSError) as exc:
            raise DeviceError(
                f"spectral5_serial on {self.config.port}: cannot send {command.decode('ascii', 'replace').rstrip()!r}"
                f" ({exc}). Reconnect the sensor and resume."
            ) from None

    def _check_error(self, command: bytes, line: bytes) -> None:
        if line.startswith(b"ERR"):
            text = line[3:].strip().decode("ascii", "replace")
            raise DeviceError(
                f"spectral5_serial on {self.config.port}: the device reported an error for "
                f"{command.decode('ascii').rstrip()!r}: {text}. Check the command parameters (n in 1..1000) "
                f"and the board's firmware."
            )

    def identify(self) -> str:
        """Send ``?`` and return the identification line."""
        from bionav.spectral.protocol import IDENT_COMMAND

        self._send(IDENT_COMMAND)
        line = self._readline(IDENT_COMMAND)
        self._check_error(IDENT_COMMAND, line)
        return line.decode("ascii", "replace")

    def _measure_once(self, command: bytes, n: int) -> np.ndarray:
        from bionav.spectral.protocol import ProtocolError, parse_reading

        self._send(command)
        rows = []
        while True:
            line = self._readline(command)
            if line == b"OK":
                break
            self._check_error(command, line)
            try:
                rows.append(parse_reading(line))
            except ProtocolError:
                raise self._fail(command, f"garbage line {line!r}") from None
            if len(rows) > n:
                raise self._fail(command, f"more than the {n} requested readings")
        if len(rows) != n:
            raise self._fail(command, f"short reply: {len(rows)} of {n} readings before OK")
        return np.array(rows, dtype=np.int64)

    def measure(self, n: int | None = None) -> np.ndarray:
        """Take ``n`` subsequent readings.

        Parameters
        ----------
        n : int, optional
            Readings to take (default ``readings_per_point``), 1..1000.

        Returns
        -------
        ndarray of int64, shape (n, 6)
            ``uv, b, g, r, ir, ref`` counts.
        """
        from bionav.spectral.protocol import measure_command

        n = int(n or self.config.readings_per_point)
        command = measure_command(n)
        for attempt in range(self.config.retries + 1):
            try:
                return self._measure_once(command, n)
            except BadReply:
                if attempt == self.config.retries:
                    raise
        raise AssertionError("unreachable")  # pragma: no cover


class Spectral5Sim:
    """Simulated five-channel sensor from the physical model of :mod:`bionav.spectral`.

    The sensor looks along a direction set by :meth:`point` (pan = azimuth,
    radians CCW from east; tilt = elevation, radians) into a scene: a callable
    ``scene(pan, tilt) -> band radiance (5,)``. The default scene is an open
    field under a clear sky with the sun at 45 degrees: sky above the horizon,
    sunlit grass below it.
    """

    config_group = "sensor"

    @dataclass
    class Config:
        """Parameters of ``sensor=spectral5_sim``.

        Attributes
        ----------
        noise_counts : float
            Standard deviation of per-reading noise, ADC counts.
        readings_per_point : int
            Readings per measurement.
        seed : int
            Seed of the noise when no generator is passed.
        """

        noise_counts: float = 4.0
        readings_per_point: int = 1
        seed: int = 0

    def __init__(self, config: "Spectral5Sim.Config | None" = None, *, rng: np.random.Generator | None = None,
                 scene: Callable | None = None, **_ignored) -> None:
        from bionav.spectral.sensor_model import LogSensorModel

        self.config = config or self.Config()
        self.rng = rng if rng is not None else np.random.default_rng(self.config.seed)
        self.model = LogSensorModel(noise_counts=self.config.noise_counts)
        self.scene = scene or _open_field_scene()
        self.pan = 0.0
        self.tilt = 0.0

    def point(self, pan: float, tilt: float) -> None:
        """Aim the sensor: ``pan`` azimuth and ``tilt`` elevation in radians."""
        self.pan, self.tilt = float(pan), float(tilt)

    def identify(self) -> str:
        """Identification line (as the board would send it)."""
        return "SPECTRAL5 simulated (bionav.spectral physical model)"

    def measure(self, n: int | None = None) -> np.ndarray:
        """``n`` readings ``(n, 6)`` of the scene in the current direction."""
        n = int(n or self.config.readings_per_point)
        rad = np.asarray(self.scene(self.pan, self.tilt), dtype=float)
        return self.model.read(rad, rng=self.rng, n_readings=n)

    def open(self) -> "Spectral5Sim":
        return self

    def close(self) -> None:
        """Nothing to release."""

    def __enter__(self) -> "Spectral5Sim":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _open_field_scene():
    from bionav.spectral.bands import band_integrate
    from bionav.spectral.materials import MATERIALS
    from bionav.spectral.sky import SkyState, band_sky_radiance, direction, illumination

    state = SkyState(sun_elevation=np.deg2rad(45.0), sun_azimuth=np.deg2rad(200.0))
    grass = np.asarray(MATERIALS["grass"].reflectance)
    ground = grass * band_integrate(illumination(state).global_horizontal) / np.pi

    def scene(pan, tilt):
        if tilt > 0:
            return band_sky_radiance(state, direction(tilt, pan))
        return ground

    return scene
