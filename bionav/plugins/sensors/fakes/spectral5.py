"""A fake five-channel sensor board on a pseudo-terminal.

:class:`FakeSpectral5` opens a pty pair (:func:`os.openpty`), serves
:mod:`bionav.spectral.protocol` from a background thread on the master side,
and exposes the slave's device path as :attr:`FakeSpectral5.port`
(pty handling of :class:`~bionav.plugins.sensors.fakes.base.FakeSerialDevice`;
it starts serving when created). The real
driver (``sensor=spectral5_serial sensor.port=<that path>``) talks to it exactly
as it would to the board. Faults can be injected to test the driver's error
handling: ``"garbage"`` (a line of noise instead of readings), ``"short"``
(fewer readings than requested, then ``OK``), ``"truncated"`` (half a line,
then nothing), ``"silent"`` (no reply) and ``"error"`` (``ERR`` line).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from bionav.plugins.sensors.fakes.base import FakeSerialDevice
from bionav.spectral import protocol

FAULTS = ("garbage", "short", "truncated", "silent", "error")


class FakeSpectral5(FakeSerialDevice):
    """Fake ADuC812 sensor board serving the bionav line protocol on a pty.

    Parameters
    ----------
    source : callable, optional
        ``source(n) -> array_like (n, 6)`` of counts ``uv, b, g, r, ir, ref``
        for an ``M<n>`` command (e.g. a simulated sensor pointed at a scene).
        Default: a fixed sky-like reading plus Gaussian noise of 3 counts.
    fault : str or None
        Persistent fault for every measure command (see module docstring).
    seed : int
        Seed of the default source's noise.

    Attributes
    ----------
    port : str
        Device path of the pty's slave end (``/dev/pts/N``).
    next_faults : list of str
        Faults applied to the next measure commands, one per command, before
        ``fault``; lets a test make only one command fail.
    commands : list of bytes
        Every command received (without ``\\r``), for inspection (the
        base class's ``received``).

    Examples
    --------
    >>> with FakeSpectral5() as fake:                       # doctest: +SKIP
    ...     sensor = Spectral5Serial(Spectral5Serial.Config(port=fake.port))
    """

    name = "spectral5"

    def __init__(self, source: Callable[[int], np.ndarray] | None = None, *, fault: str | None = None,
                 seed: int = 0) -> None:
        if fault is not None and fault not in FAULTS:
            raise ValueError(f"unknown fault {fault!r}; choose from {FAULTS}")
        super().__init__()
        self._rng = np.random.default_rng(seed)
        self.source = source or self._default_source
        self.fault = fault
        self.next_faults: list[str] = []
        self.start()

    @property
    def commands(self) -> list[bytes]:
        return self.received

    def _default_source(self, n):
        base = np.array([2900, 2910, 2870, 2700, 2630, 3277], dtype=float)
        noise = self._rng.normal(0, 3, (n, 6))
        noise[:, 5] = 0
        return np.clip(np.rint(base + noise), 0, protocol.FULL_SCALE)

    # -- protocol -------------------------------------------------------------
    def split_commands(self, buffer: bytes) -> tuple[list[bytes], bytes]:
        """Commands end in ``\\r`` (``\\n`` accepted); blank ones are dropped."""
        *lines, rest = buffer.replace(b"\n", b"\r").split(b"\r")
        return [c.strip() for c in lines if c.strip()], rest

    def respond(self, cmd: bytes) -> bytes:
        """Reply to ``cmd``, with this board's own faults (``fault``, ``next_faults``)."""
        if cmd == b"?":
            return (protocol.IDENT + "\r\n").encode("ascii")
        if not cmd.startswith(b"M"):
            return b"ERR bad command\r\n"
        try:
            n = int(cmd[1:])
        except ValueError:
            return b"ERR bad command\r\n"
        if not 1 <= n <= protocol.MAX_READINGS:
            return b"ERR n out of range\r\n"
        fault = self.next_faults.pop(0) if self.next_faults else self.fault
        if fault == "silent":
            return b""
        if fault == "error":
            return b"ERR adc timeout\r\n"
        if fault == "garbage":
            return b"\x13\xfe#~ 2o,x;;\x00zz\r\n"
        lines = [protocol.format_reading(r) for r in np.asarray(self.source(n))]
        if fault == "short":
            return b"".join(lines[: max(n - 1, 0)]) + b"OK\r\n"
        if fault == "truncated":
            return b"".join(lines[:-1]) + lines[-1][: len(lines[-1]) // 2]
        return b"".join(lines) + b"OK\r\n"

    def close(self) -> None:
        """Stop serving and close both ends of the pty (same as :meth:`stop`)."""
        self.stop()
