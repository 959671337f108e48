"""A serial link that turns every failure into a :class:`~bionav.errors.DeviceError`.

Every read and write has a timeout; every error message names the device, the
port and the command that was being served, says what went wrong (missing or
busy port, silent device, short reply, lost connection) and how to fix it.
On a lost connection the link tries to reopen the port a configurable number
of times (a USB adapter that was re-plugged), calls the driver's
re-initialisation hook and repeats the command once; otherwise it aborts
cleanly (port closed, :class:`DeviceError` raised).
"""

from __future__ import annotations

import errno
import time
from typing import Callable

import serial

from bionav.errors import DeviceError

try:  # POSIX: tcdrain() on a vanished device raises termios.error, not OSError
    import termios

    _LOST_ERRORS: tuple = (serial.SerialException, OSError, termios.error)
except ImportError:  # Windows
    _LOST_ERRORS = (serial.SerialException, OSError)


class ConnectionLost(DeviceError):
    """The device vanished mid-command (unplugged); :meth:`SerialLink.transact` may reconnect."""


def _available_ports() -> str:
    try:
        from serial.tools import list_ports

        names = sorted(p.device for p in list_ports.comports())
    except Exception:  # listing ports is a courtesy in an error message only
        names = []
    return ", ".join(names) if names else "none found"


class SerialLink:
    """One open serial port of one device.

    Parameters
    ----------
    port : str
        Device path (``/dev/ttyUSB0``, ``COM3``, a pseudo-terminal).
    baudrate : int
        Line speed; 8 data bits, no parity, 1 stop bit.
    timeout : float
        Seconds to wait for each reply.
    device : str
        Human name of the device for messages (``"DLP-IO8-G"``).
    config_key : str
        The config key that sets the port (``"sensor.port"``), for messages.
    write_timeout : float, optional
        Seconds a write may block; defaults to ``timeout``.
    reconnect_attempts : int, optional
        How often to try reopening the port after the connection was lost.
    reconnect_delay : float, optional
        Seconds between reconnection attempts.
    exclusive : bool, optional
        Lock the port so a second program cannot open it (POSIX).
    """

    def __init__(
        self,
        port: str,
        *,
        baudrate: int,
        timeout: float,
        device: str,
        config_key: str = "sensor.port",
        write_timeout: float | None = None,
        reconnect_attempts: int = 0,
        reconnect_delay: float = 0.5,
        exclusive: bool = True,
    ) -> None:
        self.port = str(port)
        self.baudrate = int(baudrate)
        self.timeout = float(timeout)
        self.device = device
        self.config_key = config_key
        self.write_timeout = float(timeout if write_timeout is None else write_timeout)
        self.reconnect_attempts = int(reconnect_attempts)
        self.reconnect_delay = float(reconnect_delay)
        self.exclusive = exclusive
        self.on_reconnect: Callable[[], None] | None = None
        self._serial: serial.Serial | None = None

    # -- opening and closing ------------------------------------------------
    def open(self) -> None:
        """Open the port (8N1, timeouts set); raise :class:`DeviceError` on failure."""
        if self._serial is not None:
            return
        try:
            self._serial = serial.Serial(
                port=self.port,
                baudrate=self.baudrate,
                bytesize=serial.EIGHTBITS,
                parity=serial.PARITY_NONE,
                stopbits=serial.STOPBITS_ONE,
                timeout=self.timeout,
                write_timeout=self.write_timeout,
                exclusive=self.exclusive,
            )
        except (serial.SerialException, OSError, ValueError) as exc:
            raise self._open_error(exc) from None

    def _open_error(self, exc: Exception) -> DeviceError:
        code = getattr(exc, "errno", None)
        text = str(exc)
        if code == errno.ENOENT or "No such file" in text:
            return DeviceError(
                f"The {self.device} port {self.port} does not exist. Plug the device in and set "
                f"{self.config_key}=<port> to its serial port (available ports: {_available_ports()})."
            )
        if code in (errno.EBUSY, errno.EAGAIN) or "exclusively lock" in text or "busy" in text.lower():
            return DeviceError(
                f"The {self.device} port {self.port} is busy: another program holds it open. "
                "Close that program (terminal, another bionav run) and try again."
            )
        if code == errno.EACCES or "Permission denied" in text:
            return DeviceError(
                f"No permission to open the {self.device} port {self.port}. Add your user to the "
                "group that owns it (usually 'dialout': sudo usermod -aG dialout $USER, then log in again)."
            )
        return DeviceError(
            f"Cannot open the {self.device} port {self.port} ({text}). Check the cable and "
            f"{self.config_key}; available ports: {_available_ports()}."
        )

    def close(self) -> None:
        """Close the port (idempotent, never raises)."""
        s, self._serial = self._serial, None
        if s is not None:
            try:
                s.close()
            except Exception:  # closing a vanished device may fail; the port is gone either way
                pass

    @property
    def is_open(self) -> bool:
        """Whether the port is open."""
        return self._serial is not None

    def __enter__(self) -> "SerialLink":
        self.open()
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # -- messages -----------------------------------------------------------
    def error(self, command, problem: str, fix: str) -> DeviceError:
        """A :class:`DeviceError` naming device, port and command."""
        return DeviceError(f"The {self.device} on {self.port} {problem} (command {command!r}). {fix}")

    def _silent(self, command) -> DeviceError:
        return self.error(
            command,
            f"did not answer within {self.timeout:g} s",
            f"Check that the device is powered and connected to {self.port}, that it runs at "
            f"{self.baudrate} baud 8N1, and that {self.config_key} names the right port.",
        )

    def _lost(self, command, exc: Exception) -> DeviceError:
        return self.error(
            command,
            f"stopped responding: the connection was lost ({exc})",
            "The device was probably unplugged; reconnect it and resume or replay the run from run.mcap "
            "(readings taken so far are in the log).",
        )

    # -- I/O ----------------------------------------------------------------
    def _require_open(self, command) -> serial.Serial:
        if self._serial is None:
            raise self.error(command, "is not open", "Open the device before using it (a driver bug, please report).")
        return self._serial

    def _reconnect(self) -> bool:
        self.close()
        for _ in range(self.reconnect_attempts):
            time.sleep(self.reconnect_delay)
            try:
                self.open()
                if self.on_reconnect is not None:
                    self.on_reconnect()
            except DeviceError:
                self.close()
                continue
            return True
        return False

    def _io(self, command, action):
        """Run one pyserial call; a lost connection becomes :class:`ConnectionLost`."""
        s = self._require_open(command)
        try:
            return action(s)
        except serial.SerialTimeoutException:
            raise self.error(
                command, f"did not accept data within {self.write_timeout:g} s", "Check the cable and flow control."
            ) from None
        except _LOST_ERRORS as exc:
            self.close()
            raise ConnectionLost(str(self._lost(command, exc))) from None

    def transact(self, command, exchange: Callable[[], object]):
        """Run ``exchange`` (writes and reads of one command); after a lost
        connection reopen the port (``reconnect_attempts`` times) and repeat it once.

        Parameters
        ----------
        command : str
            Name of the command, for messages.
        exchange : callable
            Performs the I/O with :meth:`write`, :meth:`read_exact`,
            :meth:`read_line` and returns the result.
        """
        try:
            return exchange()
        except ConnectionLost:
            if not self._reconnect():
                raise
        return exchange()

    def write(self, data: bytes, *, command=None) -> None:
        """Write bytes; ``command`` (default: ``data``) is named in errors."""
        command = data if command is None else command

        def action(s):
            s.write(data)
            s.flush()

        self._io(command, action)

    def read_exact(self, n: int, *, command) -> bytes:
        """Read exactly ``n`` bytes or raise (silent device / short reply)."""
        data = self._io(command, lambda s: s.read(n))
        if len(data) == 0:
            raise self._silent(command)
        if len(data) < n:
            raise self.error(
                command,
                f"sent a short reply ({len(data)} of {n} bytes: {data!r})",
                "Check the baud rate and the cable; a loose connection drops bytes.",
            )
        return data

    def read_line(self, *, command, terminator: bytes = b"\n", max_length: int = 512, timeout: float | None = None) -> bytes:
        """Read up to and including ``terminator``; raise on timeout or a line without terminator.

        ``timeout`` (seconds) overrides the link's timeout for this line.
        """
        wait = self.timeout if timeout is None else float(timeout)

        def action(s):
            old = s.timeout
            s.timeout = wait
            try:
                return s.read_until(terminator, max_length)
            finally:
                s.timeout = old

        data = self._io(command, action)
        if len(data) == 0:
            raise self.error(
                command,
                f"did not answer within {wait:g} s",
                f"Check that the device is powered and connected to {self.port}, that it runs at "
                f"{self.baudrate} baud 8N1, and that {self.config_key} names the right port.",
            )
        if not data.endswith(terminator):
            raise self.error(
                command,
                f"sent an incomplete line {data!r} (no terminator {terminator!r} within {wait:g} s)",
                "Check the baud rate and the cable.",
            )
        return data

    def drain(self, *, quiet: float = 0.05, limit: float = 1.0) -> bytes:
        """Read and discard input until the line is quiet for ``quiet`` seconds (at most ``limit`` s)."""

        def action(s):
            old = s.timeout
            s.timeout = quiet
            got = b""
            end = time.monotonic() + limit
            try:
                while time.monotonic() < end:
                    chunk = s.read(4096)
                    if not chunk:
                        break
                    got += chunk
            finally:
                s.timeout = old
            return got

        return self._io("drain input", action)

    def reset_input(self) -> None:
        """Discard unread input."""
        self._io("reset input", lambda s: s.reset_input_buffer())
