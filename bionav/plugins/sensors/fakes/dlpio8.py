"""Fake DLP-IO8-G data-acquisition board (the polarized-light compass' ADC).

Protocol (DLP Design DLP-IO8-G, 115200 baud 8N1): one-byte commands.
``\\`` selects binary replies, ``` ` ``` ASCII replies; ``Z X C V B N M ,``
read the analog voltage of lines 1-8: in binary mode the reply is two bytes,
most significant first, of a 10-bit count (``V = count * 5 / 1023``); in ASCII
mode the voltage as text, ``"2.47V\\n\\r"``. Other bytes are ignored.

Faults: ``garbage`` answers ``0xFF 0xFF`` (a count above 1023), ``short`` one
byte, ``silent`` nothing, ``unplug`` closes the pty.
"""

from __future__ import annotations

from typing import Callable

from bionav.plugins.sensors.fakes.base import FakeSerialDevice

ANALOG_COMMANDS = b"ZXCVBNM,"


class FakeDLPIO8(FakeSerialDevice):
    """A DLP-IO8-G whose analog lines read ``counts(line)`` (line 1-8 -> 0..1023)."""

    name = "DLP-IO8-G"

    def __init__(self, counts: Callable[[int], int]) -> None:
        super().__init__()
        self.counts = counts
        self.binary = False

    def split_commands(self, buffer: bytes):
        return [bytes([b]) for b in buffer], b""

    def respond(self, command: bytes) -> bytes:
        if command == b"\\":
            self.binary = True
            return b""
        if command == b"`":
            self.binary = False
            return b""
        idx = ANALOG_COMMANDS.find(command)
        if idx < 0 or len(command) != 1:
            return b""
        count = int(self.counts(idx + 1))
        if self.binary:
            return bytes([(count >> 8) & 0xFF, count & 0xFF])
        return f"{count * 5.0 / 1023.0:.2f}V\n\r".encode()

    def faulty_reply(self, kind: str, command: bytes, reply: bytes) -> bytes:
        if kind == "garbage" and reply:
            return b"\xff\xff"
        return super().faulty_reply(kind, command, reply)


class CompassCounts:
    """Count source for :class:`FakeDLPIO8` driven by the compass simulation.

    Parameters
    ----------
    hardware : SimulatedCompassHardware
    scene : CompassScene
    rng : numpy.random.Generator
        Noise source.
    lines : sequence of int
        DLP lines carrying units 0, 1, 2 (default 1, 2, 3); other lines read 0.
    """

    def __init__(self, hardware, scene, rng, lines=(1, 2, 3)) -> None:
        self.hardware = hardware
        self.scene = scene
        self.rng = rng
        self.lines = tuple(int(v) for v in lines)

    def __call__(self, line: int) -> int:
        if line not in self.lines:
            return 0
        counts = self.hardware.counts(self.scene, self.rng)[0]
        return int(counts[self.lines.index(line)])
