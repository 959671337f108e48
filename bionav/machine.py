"""What this process may use of the machine it runs on."""

from __future__ import annotations

import os
import platform


def usable_cpus() -> int:
    """CPUs this process may run on: its affinity mask (e.g. a SLURM allocation or ``taskset``),
    ``os.cpu_count()`` on platforms without one; at least 1."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):  # pragma: no cover - platforms without affinity
        return max(1, os.cpu_count() or 1)


def cpu_model() -> str:
    """The CPU's model name (``/proc/cpuinfo``'s ``model name`` on Linux, else ``platform.processor()``),
    e.g. ``"Intel(R) Xeon(R) Processor"``; ``"unknown CPU"`` where neither says."""
    try:
        with open("/proc/cpuinfo", encoding="utf-8", errors="replace") as f:
            for line in f:
                key, _, value = line.partition(":")
                if key.strip() in ("model name", "Model", "cpu model") and value.strip():
                    return value.strip()
    except OSError:
        pass
    return platform.processor() or platform.machine() or "unknown CPU"


def machine_label() -> str:
    """The machine as benchmark records name it: architecture and CPU count, e.g. ``"x86_64 16 cpus"``."""
    return f"{platform.machine()} {os.cpu_count()} cpus"


__all__ = ["cpu_model", "machine_label", "usable_cpus"]
