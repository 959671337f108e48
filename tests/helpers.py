"""Test helpers: run the command line in a subprocess; write tiny Vardy-named databases."""

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


def write_tiny_folder(folder: Path, *, shape: tuple[int, int] = (16, 64), sigma: float = 2.0) -> Path:
    """A 3 x 3 Vardy-named database (``<x>_<y>.png``) of smooth random panoramas, seeded (0).

    ``shape`` is (H, W) in pixels, ``sigma`` the Gaussian blur in pixels.
    """
    import cv2
    import numpy as np

    folder.mkdir()
    rng = np.random.default_rng(0)
    for x in range(3):
        for y in range(3):
            img = cv2.GaussianBlur(rng.random(shape).astype(np.float32), (0, 0), sigma)
            cv2.imwrite(str(folder / f"{x}_{y}.png"), np.uint8(255 * img / img.max()))
    return folder
