"""Test helpers: run the command line in a subprocess."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path


def run_bionav(*args: str, cwd: Path, env: dict | None = None, module: str = "bionav", timeout: float = 600):
    """Run ``python -m <module> args`` and return the CompletedProcess (text mode)."""
    full_env = dict(os.environ)
    full_env.setdefault("BIONAV_CACHE", str(Path(cwd) / "cache"))
    full_env.update(env or {})
    return subprocess.run(
        [sys.executable, "-m", module, *args], cwd=cwd, env=full_env, capture_output=True, text=True, timeout=timeout
    )
