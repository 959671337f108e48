"""Fake Directed Perception PTU-46-17.5 pan-tilt unit.

Protocol (9600 baud 8N1): ASCII commands delimited by a space (or CR/LF).
Replies are lines ending ``\\r\\n`` that start with ``*`` (success, in terse
mode ``* <value>``) or ``!`` (error). The unit starts in verbose mode with
echo on; ``FT``/``FV`` select terse/verbose feedback, ``ED``/``EE`` echo
off/on. ``PP<n>``/``TP<n>`` move to absolute positions, ``PP``/``TP`` query
them, ``A`` waits until the move is complete, ``PR``/``TR`` give the
resolution (seconds of arc per position), ``PN PX TN TX`` the position limits.
A move outside the limits answers ``! Maximum/Minimum allowable ...``.

Faults: ``error`` answers ``! Illegal command argument``, ``garbage`` a line
that starts with neither ``*`` nor ``!``, ``short`` half a line without its
terminator, ``silent`` nothing, ``unplug`` closes the pty.
"""

from __future__ import annotations

import re
import time
from typing import Callable

from bionav.plugins.sensors.fakes.base import FakeSerialDevice

RESOLUTION_ARCSEC = 185.1428
_MOVE = re.compile(rb"^([PT])P(-?\d+)$")


class FakePTU46(FakeSerialDevice):
    """A PTU-46-17.5 that reports each reached pose to ``on_move(pan_rad, tilt_rad)``.

    Parameters
    ----------
    on_move : callable, optional
        Called with the pan and tilt angles (radians) whenever the unit moves.
    limits : tuple of 4 int, optional
        ``(PN, PX, TN, TX)`` in positions.
    seconds_per_position : float, optional
        Simulated travel time (``A`` answers once the move would be done).
    """

    name = "PTU-46-17.5"

    def __init__(
        self,
        on_move: Callable[[float, float], None] | None = None,
        *,
        limits=(-3090, 3090, -907, 604),
        seconds_per_position: float = 0.0,
    ) -> None:
        super().__init__()
        self.on_move = on_move
        self.limits = tuple(int(v) for v in limits)
        self.seconds_per_position = float(seconds_per_position)
        self.echo_on = True
        self.terse = False
        self.pan_pos = 0
        self.tilt_pos = 0
        self._busy_until = 0.0

    @staticmethod
    def radians(position: int) -> float:
        """Angle of a position (radians)."""
        import math

        return math.radians(position * RESOLUTION_ARCSEC / 3600.0)

    def echo(self, data: bytes) -> bytes:
        return data if self.echo_on else b""

    def split_commands(self, buffer: bytes):
        parts = re.split(rb"[ \r\n]", buffer)
        rest = parts.pop()  # text after the last delimiter (incomplete)
        return [p for p in parts if p], rest

    def _ok(self, terse_value=None, verbose_text=None) -> bytes:
        if terse_value is None:
            return b"*\r\n"
        text = str(terse_value) if self.terse else (verbose_text or str(terse_value))
        return b"* " + text.encode() + b"\r\n"

    def respond(self, command: bytes) -> bytes:
        cmd = command.upper()
        pn, px, tn, tx = self.limits
        if cmd == b"FT":
            self.terse = True
            return self._ok()
        if cmd == b"FV":
            self.terse = False
            return self._ok()
        if cmd == b"ED":
            self.echo_on = False
            return self._ok()
        if cmd == b"EE":
            self.echo_on = True
            return self._ok()
        if cmd == b"PP":
            return self._ok(self.pan_pos, f"Current Pan position is {self.pan_pos}")
        if cmd == b"TP":
            return self._ok(self.tilt_pos, f"Current Tilt position is {self.tilt_pos}")
        if cmd in (b"PR", b"TR"):
            axis = "Pan" if cmd == b"PR" else "Tilt"
            return self._ok(f"{RESOLUTION_ARCSEC:.4f}", f"{axis} resolution is {RESOLUTION_ARCSEC:.4f} seconds arc per position")
        limits = {
            b"PN": ("Minimum Pan", pn),
            b"PX": ("Maximum Pan", px),
            b"TN": ("Minimum Tilt", tn),
            b"TX": ("Maximum Tilt", tx),
        }
        if cmd in limits:
            label, value = limits[cmd]
            return self._ok(value, f"{label} position is {value}")
        if cmd == b"A":
            wait = self._busy_until - time.monotonic()
            if wait > 0:
                time.sleep(wait)
            return self._ok()
        if cmd == b"R":
            self._set(0, 0)
            return self._ok()
        m = _MOVE.match(cmd)
        if m:
            axis, pos = m.group(1), int(m.group(2))
            lo, hi = (pn, px) if axis == b"P" else (tn, tx)
            name = "Pan" if axis == b"P" else "Tilt"
            if pos > hi:
                return f"! Maximum allowable {name} position is {hi}\r\n".encode()
            if pos < lo:
                return f"! Minimum allowable {name} position is {lo}\r\n".encode()
            if axis == b"P":
                self._set(pos, self.tilt_pos)
            else:
                self._set(self.pan_pos, pos)
            return self._ok()
        return b"! Illegal Command\r\n"

    def _set(self, pan_pos: int, tilt_pos: int) -> None:
        travel = max(abs(pan_pos - self.pan_pos), abs(tilt_pos - self.tilt_pos))
        self._busy_until = time.monotonic() + travel * self.seconds_per_position
        self.pan_pos, self.tilt_pos = pan_pos, tilt_pos
        if self.on_move is not None:
            self.on_move(self.radians(pan_pos), self.radians(tilt_pos))

    def faulty_reply(self, kind: str, command: bytes, reply: bytes) -> bytes:
        if kind == "error":
            return b"! Illegal command argument\r\n"
        if kind == "garbage":
            return b"\x15#%?@\r\n"
        return super().faulty_reply(kind, command, reply)
