"""The process umask, read without changing it (for files created by :func:`tempfile.mkstemp`)."""

from __future__ import annotations

import os
import threading

_lock = threading.Lock()


def shared_file_mode() -> int:
    """``0o666`` minus the umask: the mode ``open(path, "w")`` would give a new file.

    :func:`tempfile.mkstemp` creates files with mode ``0o600``; files moved
    into place from such a temporary (metrics.json, caches) are chmod'ed to
    this mode so colleagues on a shared disk can read them when the umask
    allows.
    """
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("Umask:"):
                    return 0o666 & ~int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    with _lock:  # no /proc: the classic set-and-restore (briefly changes the umask)
        mask = os.umask(0o022)
        os.umask(mask)
    return 0o666 & ~mask
