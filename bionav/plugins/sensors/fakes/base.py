"""Fake serial devices on pseudo-terminals.

A fake opens a pseudo-terminal pair (``os.openpty``), puts it in raw mode and
serves the device side from a thread; the driver under test opens
:attr:`FakeSerialDevice.port` (``/dev/pts/N``) like any serial port and never
knows it talks to a fake. Subclasses implement the protocol
(:meth:`split_commands`, :meth:`respond`) and how each fault looks on the
wire. Faults are queued with :meth:`inject` and hit the next commands:

``silent``   no reply at all (the driver times out)
``garbage``  a reply that violates the protocol
``short``    a truncated reply
``checksum`` a reply with a wrong checksum (checksummed protocols)
``error``    the device's own error reply (e.g. the PTU's ``!``)
``unplug``   the device disappears: both ends of the pty are closed
"""

from __future__ import annotations

import os
import select
import threading
import tty
from collections import deque

FAULTS = ("silent", "garbage", "short", "checksum", "error", "unplug")


class FakeSerialDevice:
    """Base class: a protocol served on the master side of a pty.

    Attributes
    ----------
    port : str
        Path of the slave side, to be opened by the driver.
    received : list of bytes
        Every command received, in order (for tests).
    """

    name = "fake device"

    def __init__(self) -> None:
        self._master, self._slave = os.openpty()
        tty.setraw(self._slave)
        tty.setraw(self._master)
        self.port = os.ttyname(self._slave)
        self.received: list[bytes] = []
        self._faults: deque = deque()
        self._buffer = b""
        self._stop = threading.Event()
        self._unplugged = threading.Event()
        self._lock = threading.Lock()
        self._thread: threading.Thread | None = None

    # -- life cycle ---------------------------------------------------------
    def start(self) -> "FakeSerialDevice":
        """Start serving in a daemon thread."""
        if self._thread is None:
            self._thread = threading.Thread(target=self._serve, name=f"fake-{self.name}", daemon=True)
            self._thread.start()
        return self

    def stop(self) -> None:
        """Stop serving and close the pty."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=2.0)
            self._thread = None
        self._close_fds()

    def __enter__(self) -> "FakeSerialDevice":
        return self.start()

    def __exit__(self, *exc) -> None:
        self.stop()

    @property
    def unplugged(self) -> bool:
        """True once the device was unplugged."""
        return self._unplugged.is_set()

    def _close_fds(self) -> None:
        with self._lock:
            for name in ("_master", "_slave"):
                fd = getattr(self, name)
                if fd is not None:
                    try:
                        os.close(fd)
                    except OSError:
                        pass
                    setattr(self, name, None)

    # -- faults -------------------------------------------------------------
    def inject(self, kind: str, *, on: bytes | None = None, after: int = 0, count: int = 1) -> None:
        """Let ``count`` commands suffer fault ``kind``.

        Parameters
        ----------
        kind : str
            One of :data:`FAULTS`.
        on : bytes, optional
            Only commands equal to this count (default: every command).
        after : int, optional
            Let this many (matching) commands pass unharmed first.
        count : int, optional
            How many (matching) commands are hit.
        """
        if kind not in FAULTS:
            raise ValueError(f"unknown fault {kind!r}; choose from {FAULTS}")
        with self._lock:
            self._faults.append([kind, on, int(after), int(count)])

    def _next_fault(self, command: bytes):
        with self._lock:
            if not self._faults:
                return None
            entry = self._faults[0]
            kind, on, after, count = entry
            if on is not None and command != on:
                return None
            if after > 0:
                entry[2] -= 1
                return None
            entry[3] -= 1
            if entry[3] <= 0:
                self._faults.popleft()
            return kind

    # -- protocol hooks -----------------------------------------------------
    def split_commands(self, buffer: bytes) -> tuple[list[bytes], bytes]:
        """Split the input buffer into complete commands and the unparsed rest."""
        raise NotImplementedError

    def respond(self, command: bytes) -> bytes:
        """The normal reply to ``command`` (may be empty)."""
        raise NotImplementedError

    def echo(self, data: bytes) -> bytes:
        """Bytes echoed for raw input (default: none)."""
        return b""

    def faulty_reply(self, kind: str, command: bytes, reply: bytes) -> bytes:
        """How fault ``kind`` changes ``reply`` (override per protocol)."""
        if kind == "silent":
            return b""
        if kind == "garbage":
            return b"\xfe\x80#?garbage\xff"
        if kind == "short":
            return reply[: len(reply) // 2]
        return reply

    # -- serving ------------------------------------------------------------
    def _write(self, data: bytes) -> None:
        view = memoryview(data)
        while view and not self._stop.is_set():
            try:
                n = os.write(self._master, view)
            except BlockingIOError:
                continue
            view = view[n:]

    def _serve(self) -> None:
        while not self._stop.is_set() and not self._unplugged.is_set():
            try:
                ready, _, _ = select.select([self._master], [], [], 0.02)
            except (OSError, ValueError, TypeError):
                return
            self.tick()
            if not ready:
                continue
            try:
                data = os.read(self._master, 4096)
            except OSError:
                continue  # no reader on the slave side yet
            if not data:
                continue
            echoed = self.echo(data)
            if echoed:
                self._write(echoed)
            self._buffer += data
            commands, self._buffer = self.split_commands(self._buffer)
            for command in commands:
                self.received.append(command)
                fault = self._next_fault(command)
                if fault == "unplug":
                    self._unplugged.set()
                    self._close_fds()
                    return
                reply = self.respond(command)
                if fault is not None:
                    reply = self.faulty_reply(fault, command, reply)
                if reply:
                    self._write(reply)

    def tick(self) -> None:
        """Called about every 20 ms (streaming devices send from here)."""

    def send(self, data: bytes) -> None:
        """Write unsolicited bytes to the driver (from :meth:`tick`)."""
        self._write(data)
