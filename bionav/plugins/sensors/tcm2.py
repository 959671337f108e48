"""``sensor=tcm2``: the PNI TCM2 electronic (magnetic) compass over a serial port.

The thesis' reference compass (section 4.2.2). 9600 baud 8N1; the driver
halts continuous output (``h``), selects the output format (``sdo=t``
standard or ``sdo=n`` NMEA, or leaves it), and per reading sends ``s?`` and
reads one output word (``$C<heading>P<pitch>R<roll>...*hh`` or
``$HCHDM,<heading>,M*hh``, see :mod:`bionav.plugins.sensors.tcm2_protocol`),
skipping blank and ``:`` prompt lines. A checksum mismatch, garbage, a short
or missing line, or an unplugged cable raise
:class:`~bionav.errors.DeviceError` naming port and command.

A reading is ``{"line": <the output word>, "format": ..., "heading_deg": ...,
[pitch_deg, roll_deg, temperature_c, ...]}``; heading is the compass bearing
clockwise from magnetic north.
"""

from __future__ import annotations

from dataclasses import dataclass

from bionav.plugins.sensors.base import SensorPlugin, SerialDeviceMixin
from bionav.validation import bounded

READING_SCHEMA = {
    "type": "object",
    "title": "TCM2 output word",
    "properties": {
        "line": {"type": "string", "description": "the output word as received, without CR LF"},
        "format": {"type": "string", "enum": ["standard", "nmea"]},
        "heading_deg": {"type": "number", "description": "bearing clockwise from magnetic north, degrees"},
        "pitch_deg": {"type": "number"},
        "roll_deg": {"type": "number"},
        "temperature_c": {"type": "number"},
    },
    "required": ["line", "format", "heading_deg"],
}


@dataclass
class TCM2Config:
    """Parameters of ``sensor=tcm2``."""

    port: str = "/dev/ttyUSB2"
    baudrate: int = bounded(9600, ge=50, le=4_000_000)
    timeout_s: float = bounded(1.0, gt=0.0, le=3600.0)
    output: str = bounded("standard", choices=("standard", "nmea", "keep"))  # standard | nmea | keep (leave the device's setting)
    reconnect_attempts: int = bounded(1, ge=0, le=1000)
    reconnect_delay_s: float = bounded(0.5, ge=0.0, le=3600.0)


class TCM2(SerialDeviceMixin, SensorPlugin):
    """PNI TCM2 electronic compass."""

    device_name = "TCM2 compass"
    Config = TCM2Config
    schema_name = "bionav.TCM2Reading"
    schema = READING_SCHEMA

    def __init__(self, config: TCM2Config) -> None:
        super().__init__(config)
        self._link = None

    def _init_device(self) -> None:
        self._link.write(b"h\r", command="h")
        if self.config.output != "keep":
            cmd = "sdo=t" if self.config.output == "standard" else "sdo=n"
            self._link.write(cmd.encode() + b"\r", command=cmd)
        self._link.drain(quiet=0.05, limit=1.0)

    def read(self) -> dict:
        from bionav.plugins.sensors.tcm2_protocol import TCM2FormatError, parse_line

        if self._link is None:
            self.open()
        link = self._link

        def exchange():
            link.reset_input()
            link.write(b"s?\r", command="s?")
            for _ in range(4):
                raw = link.read_line(command="s?", terminator=b"\n")
                text = raw.decode("ascii", errors="replace").strip()
                if text and text != ":":
                    return text
            raise link.error("s?", "sent only blank or prompt lines", "Check the TCM2's output settings.")

        text = link.transact("s?", exchange)
        try:
            parsed = parse_line(text)
        except TCM2FormatError as exc:
            problem = "sent a line with a wrong checksum" if exc.kind == "checksum" else "sent garbage"
            raise link.error("s?", f"{problem}: {exc}", "Check the cable and the baud rate (9600 8N1).") from None
        return {"line": text, **parsed}
