"""Fake PNI TCM2 electronic compass.

Protocol (9600 baud 8N1): commands end with CR (LF tolerated). ``s?`` answers
one output word, ``go`` starts continuous output (one word per tick), ``h``
halts it, ``sdo=t`` / ``sdo=n`` select the standard or NMEA format
(:mod:`bionav.plugins.sensors.tcm2_protocol`).

Faults: ``checksum`` flips the checksum, ``garbage`` sends a line that is not
an output word, ``short`` half a line, ``silent`` nothing, ``unplug`` closes
the pty.
"""

from __future__ import annotations

import re
from typing import Callable

from bionav.plugins.sensors.fakes.base import FakeSerialDevice
from bionav.plugins.sensors.tcm2_protocol import format_nmea, format_standard


class FakeTCM2(FakeSerialDevice):
    """A TCM2 reporting ``attitude() -> (heading_deg, pitch_deg, roll_deg)``."""

    name = "TCM2"

    def __init__(self, attitude: Callable[[], tuple[float, float, float]], *, nmea: bool = False) -> None:
        super().__init__()
        self.attitude = attitude
        self.nmea = nmea
        self.streaming = False

    def split_commands(self, buffer: bytes):
        parts = re.split(rb"[\r\n]", buffer)
        rest = parts.pop()
        return [p.strip() for p in parts if p.strip()], rest

    def word(self) -> bytes:
        heading, pitch, roll = self.attitude()
        heading %= 360.0
        if round(heading, 1) >= 360.0:
            heading = 0.0
        if self.nmea:
            return format_nmea(heading_deg=heading).encode()
        return format_standard(heading_deg=heading, pitch_deg=pitch, roll_deg=roll).encode()

    def respond(self, command: bytes) -> bytes:
        cmd = command.lower()
        if cmd == b"s?":
            return self.word()
        if cmd == b"go":
            self.streaming = True
            return b""
        if cmd == b"h":
            self.streaming = False
            return b""
        if cmd == b"sdo=n":
            self.nmea = True
            return b""
        if cmd == b"sdo=t":
            self.nmea = False
            return b""
        return b"E004\r\n"  # unknown command

    def tick(self) -> None:
        if self.streaming:
            self.send(self.word())

    def faulty_reply(self, kind: str, command: bytes, reply: bytes) -> bytes:
        if kind == "checksum" and reply.startswith(b"$"):
            star = reply.rindex(b"*")
            value = int(reply[star + 1 : star + 3], 16) ^ 0x5A
            return reply[: star + 1] + f"{value:02X}".encode() + b"\r\n"
        if kind == "garbage":
            return b"#@!%TCM?\r\n"
        return super().faulty_reply(kind, command, reply)
