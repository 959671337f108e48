"""``sensor=polcompass_serial``: the polarized-light compass read through a DLP-IO8-G.

Hardware (thesis 4.1, appendix A): three POL-OP units (log-ratio amplifiers)
on analog lines of a DLP-IO8-G USB data-acquisition board, 115200 baud 8N1.
On opening, the driver sends ``\\`` once to select binary replies; each
reading then sends, per unit, the line's one-byte analog command (``Z X C V B
N M ,`` for lines 1-8) and reads two bytes, most significant first, of a
10-bit count (``V = count * 5 / 1023``). Every failure (missing or busy port,
silent board, garbage or short reply, unplugged cable) raises
:class:`~bionav.errors.DeviceError` naming the port and the command.
"""

from __future__ import annotations

from dataclasses import dataclass

from bionav.errors import UserError
from bionav.plugins.sensors.base import SensorPlugin, SerialDeviceMixin
from bionav.validation import Range, bounded

ANALOG_COMMANDS = b"ZXCVBNM,"

READING_SCHEMA = {
    "type": "object",
    "title": "Polarized-light compass raw reading",
    "properties": {
        "counts": {"type": "array", "items": {"type": "integer"}, "description": "10-bit ADC counts, one per POL-OP unit"},
        "lines": {"type": "array", "items": {"type": "integer"}, "description": "DLP-IO8-G analog lines read (1-8)"},
    },
    "required": ["counts", "lines"],
}


@dataclass
class PolCompassSerialConfig:
    """Parameters of ``sensor=polcompass_serial``.

    calibration : ``none`` (``experiment.calibration`` decides: a rotation at the zenith, nominal values or
        ``experiment.calibration_path``) or the path of a ``calibration.json`` written by an earlier rotation run
        of this compass (per unit: centre volts, volts per decade, polarizer angle in radians; see
        :class:`bionav.polcompass.UnitCalibration`). A file replaces ``experiment.calibration``, is recorded to
        ``run.mcap`` (``/pol_compass/calibration``) and is applied again by ``sensor=replay``.
    """

    port: str = "/dev/ttyUSB0"
    baudrate: int = bounded(115200, ge=50, le=4_000_000)
    timeout_s: float = bounded(0.5, gt=0.0, le=3600.0)
    lines: list[int] = bounded([1, 2, 3], length=(1, 8), item=Range(ge=1, le=8))
    reconnect_attempts: int = bounded(1, ge=0, le=1000)
    reconnect_delay_s: float = bounded(0.5, ge=0.0, le=3600.0)
    calibration: str = "none"


class PolCompassSerial(SerialDeviceMixin, SensorPlugin):
    """Polarized-light compass on a DLP-IO8-G board over a serial port."""

    device_name = "DLP-IO8-G (polarized-light compass)"
    Config = PolCompassSerialConfig
    schema_name = "bionav.PolCompassReading"
    schema = READING_SCHEMA

    def __init__(self, config: PolCompassSerialConfig) -> None:
        super().__init__(config)
        lines = config.lines  # 1..8, declared on PolCompassSerialConfig.lines
        self.lines = lines
        self._link = None
        self.calibration = None
        how = str(config.calibration or "none")
        if how == "auto":
            raise UserError("sensor.calibration=auto is not an option of the serial compass: a rotation calibrates it "
                            "(experiment.calibration=auto or rotation); give sensor.calibration=<calibration.json> or none.")
        if how != "none":
            from bionav.polcompass.calibration import UnitCalibration

            self.calibration = UnitCalibration.load(how, setting="sensor.calibration")
            if len(self.calibration.unit_angles) != len(lines):
                raise UserError(f"sensor.calibration={how} calibrates {len(self.calibration.unit_angles)} units, but "
                                f"sensor.lines={lines} reads {len(lines)}; use the calibration.json of a rotation run "
                                "with the same lines.")

    def _init_device(self) -> None:
        self._link.reset_input()
        self._link.write(b"\\", command="\\ (binary mode)")

    def read_line_count(self, line: int) -> int:
        """One 10-bit count from analog ``line`` (1-8)."""
        if self._link is None:
            self.open()
        cmd = ANALOG_COMMANDS[line - 1 : line]
        name = f"{cmd.decode()} (analog line {line})"

        def exchange():
            self._link.write(cmd, command=name)
            return self._link.read_exact(2, command=name)

        data = self._link.transact(name, exchange)
        count = (data[0] << 8) | data[1]
        if count > 1023:
            raise self._link.error(
                name,
                f"sent garbage {data!r} (count {count} > 1023)",
                "Check that the port is the DLP-IO8-G, not another device, and that nothing else writes to it.",
            )
        return count

    def read(self) -> dict:
        """One reading: the counts of every configured line."""
        return {"counts": [self.read_line_count(v) for v in self.lines], "lines": list(self.lines)}
