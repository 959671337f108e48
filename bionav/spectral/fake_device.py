"""A fake five-channel sensor board on a pseudo-terminal.

:class:`FakeSpectral5` opens a pty pair (:func:`os.openpty`), serves
:mod:`bionav.spectral.protocol` from a background thread on the master side,
and exposes the slave's device path as :attr:`FakeSpectral5.port`. The real
driver (``sensor=spectral5_serial sensor.port=<that path>``) talks to it exactly
as it would to the board. Faults can be injected to test the driver's error
handling: ``"garbage"`` (a line of noise instead of readings), ``"short"``
(fewer readings than requested, then ``OK``), ``"truncated"`` (half a line,
then nothing), ``"silent"`` (no reply) and ``"error"`` (``ERR`` line).
"""

from __future__ import annotations

import os
import select
import threading
import tty
from typing import Callable

import numpy as np

from bionav.spectral import protocol

FAULTS = ("garbage", "short", "truncated", "silent", "error")


class FakeSpectral5:
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
        Every command received (without ``\\r``), for inspection.

    Examples
    --------
    >>> with FakeSpectral5() as fake:                       # doctest: +SKIP
    ...     sensor = Spectral5Serial(Spectral5Serial.Config(port=fake.port))
    """

    def __init__(self, source: Callable[[int], np.ndarray] | None = None, *, fault: str | None = None,
                 seed: int = 0) -> None:
        if fault is not None and fault not in FAULTS:
            raise ValueError(f"unknown fault {fault!r}; choose from {FAULTS}")
        self._rng = np.random.default_rng(seed)
        self.source = source or self._default_source
        self.fault = fault
        self.next_faults: list[str] = []
        self.commands: list[bytes] = []
        self._master, self._slave = os.openpty()
        tty.setraw(self._slave)
        self.port = os.ttyname(self._slave)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._serve, name="FakeSpectral5", daemon=True)
        self._thread.start()

    def _default_source(self, n):
        base = np.array([2900, 2910, 2870, 2700, 2630, 3277], dtype=float)
        noise = self._rng.normal(0, 3, (n, 6))
        noise[:, 5] = 0
        return np.clip(np.rint(base + noise), 0, protocol.FULL_SCALE)

    # -- server ---------------------------------------------------------------
    def _write(self, data: bytes) -> None:
        view = memoryview(data)
        while view and not self._stop.is_set():
            try:
                k = os.write(self._master, view)
            except OSError:
                return
            view = view[k:]

    def _handle(self, cmd: bytes) -> None:
        self.commands.append(cmd)
        if cmd == b"?":
            self._write((protocol.IDENT + "\r\n").encode("ascii"))
            return
        if not cmd.startswith(b"M"):
            self._write(b"ERR bad command\r\n")
            return
        try:
            n = int(cmd[1:])
        except ValueError:
            self._write(b"ERR bad command\r\n")
            return
        if not 1 <= n <= protocol.MAX_READINGS:
            self._write(b"ERR n out of range\r\n")
            return
        fault = self.next_faults.pop(0) if self.next_faults else self.fault
        if fault == "silent":
            return
        if fault == "error":
            self._write(b"ERR adc timeout\r\n")
            return
        if fault == "garbage":
            self._write(b"\x13\xfe#~ 2o,x;;\x00zz\r\n")
            return
        readings = np.asarray(self.source(n))
        lines = [protocol.format_reading(r) for r in readings]
        if fault == "short":
            self._write(b"".join(lines[: max(n - 1, 0)]) + b"OK\r\n")
            return
        if fault == "truncated":
            self._write(b"".join(lines[:-1]) + lines[-1][: len(lines[-1]) // 2])
            return
        self._write(b"".join(lines) + b"OK\r\n")

    def _serve(self) -> None:
        buf = b""
        while not self._stop.is_set():
            try:
                ready, _, _ = select.select([self._master], [], [], 0.05)
            except (OSError, ValueError):
                return
            if not ready:
                continue
            try:
                chunk = os.read(self._master, 1024)
            except OSError:
                continue
            buf += chunk.replace(b"\n", b"\r")
            while b"\r" in buf:
                cmd, buf = buf.split(b"\r", 1)
                cmd = cmd.strip()
                if cmd:
                    self._handle(cmd)

    # -- lifecycle ------------------------------------------------------------
    def close(self) -> None:
        """Stop the server thread and close both ends of the pty."""
        if self._stop.is_set():
            return
        self._stop.set()
        self._thread.join(timeout=2.0)
        for fd in (self._master, self._slave):
            try:
                os.close(fd)
            except OSError:
                pass

    def __enter__(self) -> "FakeSpectral5":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def main(argv: list[str] | None = None) -> int:
    """Serve a fake five-channel board and a fake PTU-46 looking into one simulated backyard.

    ``python -m bionav.spectral.fake_device [--time ISO] [--cloud-cover F] [--cloud-optical-depth F]``
    prints the two pseudo-terminal paths; point ``sensor=spectral5_serial sensor.port=...`` and
    ``pantilt=ptu46 pantilt.port=...`` at them to run ``experiment=contrast_scan`` over the real
    drivers. Ctrl-C stops.
    """
    import argparse
    import sys
    import time

    from bionav.plugins.sensors.fakes.ptu46 import FakePTU46
    from bionav.plugins.sensors.spectral5 import Spectral5Sim
    from bionav.spectral.scene import backyard_scene
    from bionav.spectral.sky import CloudField, SkyState

    parser = argparse.ArgumentParser(prog="python -m bionav.spectral.fake_device", description=main.__doc__)
    parser.add_argument("--time", default="2009-06-17T11:27:04+02:00", help="ISO 8601 time with zone")
    parser.add_argument("--cloud-cover", type=float, default=0.6)
    parser.add_argument("--cloud-optical-depth", type=float, default=30.0)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    sky = SkyState.from_time(args.time, clouds=CloudField(cover=args.cloud_cover,
                                                          optical_depth=args.cloud_optical_depth, seed=args.seed))
    scene = backyard_scene(sky, seed=args.seed)
    sim = Spectral5Sim(Spectral5Sim.Config(seed=args.seed))
    sim.attach_simulation(scene, None)
    ptu = FakePTU46(scene.set_pose)
    ptu.start()
    board = FakeSpectral5(source=sim.measure, seed=args.seed)
    print(f"spectral5    sensor=spectral5_serial sensor.port={board.port}", flush=True)
    print(f"{ptu.name:12s} pantilt=ptu46 pantilt.port={ptu.port}", flush=True)
    print("serving; Ctrl-C stops", file=sys.stderr, flush=True)
    try:
        while True:
            time.sleep(1.0)
    except KeyboardInterrupt:
        pass
    finally:
        board.close()
        ptu.stop()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
