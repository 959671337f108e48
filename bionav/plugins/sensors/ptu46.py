"""``pantilt=ptu46``: Directed Perception PTU-46-17.5 pan-tilt unit over a serial port.

Protocol (9600 baud 8N1): ASCII commands terminated by a space; every command
answers one line starting with ``*`` (success; in terse mode ``* <value>``)
or ``!`` (error). On opening the driver switches echo off (``ED``) and terse
feedback on (``FT``), drains the port, then reads the resolution (``PR``,
``TR``; 185.1428 seconds of arc per position on the 17.5 model) and the
position limits (``PN PX TN TX``). A move sends ``PP<n> `` and ``TP<n> ``
(absolute positions), waits with ``A `` and reads the reached positions back
(``PP ``, ``TP ``).

Angles: pan positive counter-clockwise seen from above; tilt 0 = the payload
looks at the zenith (mount the compass so), positive towards the pan
direction's forward axis. Every failure (missing/busy port, silent unit,
garbage or short reply, ``!`` error, a move outside the limits, unplugged
cable) raises :class:`~bionav.errors.DeviceError` naming port and command.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from bionav.plugins.sensors.base import PanTiltPlugin, SerialDeviceMixin
from bionav.validation import bounded


@dataclass
class PTU46Config:
    """Parameters of ``pantilt=ptu46``."""

    port: str = "/dev/ttyUSB1"
    baudrate: int = bounded(9600, ge=50, le=4_000_000)
    timeout_s: float = bounded(1.0, gt=0.0, le=3600.0)
    await_timeout_s: float = bounded(30.0, gt=0.0, le=36000.0)  # longest move
    settle_s: float = bounded(0.1, ge=0.0, le=60.0)  # quiet time when draining the port at start-up
    reconnect_attempts: int = bounded(1, ge=0, le=1000)
    reconnect_delay_s: float = bounded(0.5, ge=0.0, le=3600.0)


class PTU46(SerialDeviceMixin, PanTiltPlugin):
    """Directed Perception PTU-46-17.5."""

    device_name = "PTU-46 pan-tilt unit"
    Config = PTU46Config
    config_group = "pantilt"

    def __init__(self, config: PTU46Config) -> None:
        super().__init__(config)
        self._link = None
        self._res = (None, None)
        self._limits = None

    # -- life cycle ---------------------------------------------------------
    def _init_device(self) -> None:
        link = self._link
        link.write(b"ED ", command="ED ")
        link.write(b"FT ", command="FT ")
        link.drain(quiet=self.config.settle_s, limit=5 * self.config.settle_s + 1.0)
        self._res = (self._query_float("PR "), self._query_float("TR "))
        self._limits = tuple(self._query_int(c) for c in ("PN ", "PX ", "TN ", "TX "))

    # -- protocol -----------------------------------------------------------
    def _command(self, text: str, *, timeout: float | None = None) -> str:
        """Send one command, return the text after ``*``; raise on ``!`` or garbage."""
        link = self._link
        if link is None:
            self.open()
            link = self._link
        data = text.encode("ascii")

        def exchange():
            link.write(data, command=text)
            return link.read_line(command=text, terminator=b"\n", timeout=timeout)

        line = link.transact(text, exchange).decode("ascii", errors="replace").strip()
        if line.startswith("!"):
            raise link.error(
                text,
                f"reported an error: {line!r}",
                "Check the command's range and the unit's state (power, stalled axis); "
                "the readings taken so far are in run.mcap.",
            )
        if not line.startswith("*"):
            raise link.error(
                text,
                f"sent garbage {line!r} (expected '*' or '!')",
                "Check the baud rate (9600 8N1) and that the port is the pan-tilt unit.",
            )
        return line[1:].strip()

    def _query_float(self, text: str) -> float:
        value = self._command(text)
        try:
            return float(value.split()[-1])
        except (ValueError, IndexError):
            raise self._link.error(text, f"sent an unreadable value {value!r}", "Check the baud rate and the cable.") from None

    def _query_int(self, text: str) -> int:
        value = self._command(text)
        try:
            return int(value.split()[-1])
        except (ValueError, IndexError):
            raise self._link.error(text, f"sent an unreadable value {value!r}", "Check the baud rate and the cable.") from None

    # -- pan-tilt API -------------------------------------------------------
    def resolution(self) -> tuple[float, float]:
        if self._link is None:
            self.open()
        return tuple(math.radians(r / 3600.0) for r in self._res)

    def limits(self) -> tuple[float, float, float, float]:
        pan_res, tilt_res = self.resolution()
        pn, px, tn, tx = self._limits
        return pn * pan_res, px * pan_res, tn * tilt_res, tx * tilt_res

    def move_to(self, pan: float, tilt: float) -> dict:
        pan_res, tilt_res = self.resolution()
        pn, px, tn, tx = self._limits
        pan_pos = int(round(pan / pan_res))
        tilt_pos = int(round(tilt / tilt_res))
        for axis, pos, lo, hi, res, cmd in (
            ("pan", pan_pos, pn, px, pan_res, f"PP{pan_pos} "),
            ("tilt", tilt_pos, tn, tx, tilt_res, f"TP{tilt_pos} "),
        ):
            if not lo <= pos <= hi:
                raise self._link.error(
                    cmd,
                    f"cannot move: {axis} {math.degrees(pos * res):.2f} deg (position {pos}) is outside its limits "
                    f"[{math.degrees(lo * res):.2f}, {math.degrees(hi * res):.2f}] deg",
                    "Keep the experiment's pan/tilt range within the unit's limits.",
                )
        self._command(f"PP{pan_pos} ")
        self._command(f"TP{tilt_pos} ")
        self._command("A ", timeout=self.config.await_timeout_s)
        got_pan = self._query_int("PP ")
        got_tilt = self._query_int("TP ")
        return {
            "pan_pos": got_pan,
            "tilt_pos": got_tilt,
            "pan": got_pan * pan_res,
            "tilt": got_tilt * tilt_res,
            "pan_cmd": float(pan),
            "tilt_cmd": float(tilt),
        }
