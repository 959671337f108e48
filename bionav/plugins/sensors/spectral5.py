"""Five-channel (UV, B, G, R, IR) log sensor: serial driver and simulator plugins.

``sensor=spectral5_serial sensor.port=/dev/ttyUSB0`` talks to the ADuC812 board
over bionav's line protocol (documented in :mod:`bionav.spectral.protocol`);
``sensor=spectral5_sim`` computes the same readings from the physical model of
:mod:`bionav.spectral`. Both return raw readings as an integer array of shape
``(n, 6)``: ``uv, b, g, r, ir, ref`` 12-bit ADC counts.

Both are ``bionav.sensors`` plugins with the life cycle of bionav's sensor
contract (``open``/``close``/context manager, ``attach_simulation(scene, rng)``)
and ``read() -> dict``: one raw reading ``{"counts": [[uv, b, g, r, ir, ref],
...]}`` (the reply to one ``M<n>``). Experiments record every raw reading to
``run.mcap`` under :data:`bionav.spectral.protocol.RAW_TOPIC` (``/sensor/raw``, schema
``bionav.Spectral5Reading``) as it is taken, and pan-tilt states under
``/pantilt/state``, so that ``sensor=replay`` re-runs a session from its log.

This module stays light: pyserial and the physical model are imported inside
methods.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.errors import DeviceError
from bionav.plugins.sensors.base import SensorPlugin
from bionav.spectral.protocol import RAW_SCHEMA, RAW_SCHEMA_NAME, reading_message
from bionav.validation import bounded


class BadReply(DeviceError):
    """A garbage, short, incomplete or missing reply (worth retrying the command)."""


class _Spectral5Base(SensorPlugin):
    """What both spectral5 plugins share: schema of raw readings, life cycle, ``read()``."""

    config_group = "sensor"
    simulated = False
    schema_name = RAW_SCHEMA_NAME
    schema = RAW_SCHEMA

    def measure(self, n: int | None = None) -> np.ndarray:  # pragma: no cover - overridden
        raise NotImplementedError

    def read(self) -> dict:
        """One raw reading: the reply to ``M<readings_per_point>`` as ``{"counts": [[uv, b, g, r, ir, ref], ...]}``."""
        return reading_message(self.measure())


class Spectral5Serial(_Spectral5Base):
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
        baudrate: int = bounded(9600, ge=50, le=4_000_000)
        timeout_s: float = bounded(2.0, gt=0.0, le=3600.0)
        retries: int = bounded(1, ge=0, le=1000)
        readings_per_point: int = bounded(1, ge=1, le=100_000)

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


class Spectral5Sim(_Spectral5Base):
    """Simulated five-channel sensor from the physical model of :mod:`bionav.spectral`.

    The sensor reads its *scene*: any object with ``band_radiance() -> (5,)``
    (the band radiance along the current optical axis) and ``set_pose(pan,
    tilt)`` (radians), such as :class:`bionav.world.worlds.garden.OutdoorScene`. An
    experiment hands its scene over with :meth:`attach_simulation` (a
    simulated pan-tilt unit aims it); without one, the sensor looks into an
    open field under a clear sky with the sun at 45 degrees (sky above the
    horizon, sunlit grass below), aimed with :meth:`point`.
    """

    config_group = "sensor"
    simulated = True

    @dataclass
    class Config:
        """Parameters of ``sensor=spectral5_sim``.

        Attributes
        ----------
        noise_counts : float
            Standard deviation of per-reading noise, ADC counts.
        readings_per_point : int
            Readings per measurement (``n`` of the board's ``M<n>``).
        seed : int
            Seed of the noise until an experiment attaches its generator.
        """

        noise_counts: float = bounded(4.0, ge=0.0, le=1e6)
        readings_per_point: int = bounded(1, ge=1, le=100_000)
        seed: int = bounded(0, ge=0)

    def __init__(self, config: "Spectral5Sim.Config | None" = None, **_ignored) -> None:
        from bionav.spectral.sensor_model import LogSensorModel

        self.config = config or self.Config()
        self.rng = np.random.default_rng(self.config.seed)
        self.model = LogSensorModel(noise_counts=self.config.noise_counts)
        self.scene = None

    def attach_simulation(self, scene, rng) -> None:
        """Read ``scene`` from now on, with noise drawn from ``rng``."""
        if not hasattr(scene, "band_radiance"):
            raise TypeError(f"spectral5_sim needs a spectral scene with band_radiance(), got {type(scene).__name__}")
        self.scene = scene
        if rng is not None:
            self.rng = rng

    def _scene(self):
        if self.scene is None:
            self.scene = OpenField()
        return self.scene

    def point(self, pan: float, tilt: float) -> None:
        """Aim the sensor: ``pan`` azimuth and ``tilt`` elevation in radians (sets the scene's pose)."""
        self._scene().set_pose(pan, tilt)

    def identify(self) -> str:
        """Identification line (as the board would send it)."""
        return "SPECTRAL5 simulated (bionav.spectral physical model)"

    def measure(self, n: int | None = None) -> np.ndarray:
        """``n`` readings ``(n, 6)`` of the scene along the current optical axis."""
        n = int(n or self.config.readings_per_point)
        rad = np.asarray(self._scene().band_radiance(), dtype=float)
        return self.model.read(rad, rng=self.rng, n_readings=n)

    def open(self) -> "Spectral5Sim":
        return self

    def close(self) -> None:
        """Nothing to release."""


class OpenField:
    """The default scene of ``spectral5_sim``: clear sky (sun at 45 degrees elevation) over sunlit grass.

    Pan is the azimuth (radians CCW from east), tilt the elevation (radians).
    """

    def __init__(self) -> None:
        from bionav.light.bands import band_integrate
        from bionav.light.daylight import SkyState, illumination
        from bionav.light.materials import MATERIALS

        self.sky = SkyState(sun_elevation=np.deg2rad(45.0), sun_azimuth=np.deg2rad(200.0))
        grass = np.asarray(MATERIALS["grass"].reflectance)
        self._ground = grass * band_integrate(illumination(self.sky).global_horizontal) / np.pi
        self.pose = (0.0, 0.0)

    def set_pose(self, pan: float, tilt: float) -> None:
        self.pose = (float(pan), float(tilt))

    def band_radiance(self) -> np.ndarray:
        from bionav.geometry import direction_from_angles
        from bionav.light.daylight import band_sky_radiance

        pan, tilt = self.pose
        if tilt > 0:
            return band_sky_radiance(self.sky, direction_from_angles(pan, tilt))
        return self._ground
