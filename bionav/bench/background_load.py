"""``--background-load N``: busy processes that load the machine while a benchmark measures."""

from __future__ import annotations

import subprocess
import sys


def start_load(n: int) -> list[subprocess.Popen]:
    """Start ``n`` busy Python processes (each ends by itself after an hour at the latest)."""
    code = "import time\nend = time.monotonic() + 3600\nx = 0\nwhile time.monotonic() < end:\n    x += 1\n"
    return [subprocess.Popen([sys.executable, "-c", code]) for _ in range(n)]


def stop_load(procs: list[subprocess.Popen]) -> None:
    """Stop the processes of :func:`start_load` (terminate, then kill after 5 s)."""
    for p in procs:
        p.terminate()
    for p in procs:
        try:
            p.wait(timeout=5)
        except subprocess.TimeoutExpired:  # pragma: no cover
            p.kill()
