"""Compiling a run's homing kernels in a second process while the first one renders (the first run's wait).

From empty caches the default ``python -m bionav`` spends most of its time in
numba compiling: the renderer's kernel (needed first), its shadow bins (needed
when the render starts), then the SIFT matcher's row kernel and the return
agent's kernel (needed only after the rendering). numba compiles in one
thread, so :func:`start_warmup` starts ``python -m bionav.experiments.warmup``
beside the run: for a run of a synthetic database it first builds the shadow
bins of a one-light scene (the renderer's second kernel), then it homes with
the run's method on a tiny synthetic 3 x 3 grid, which compiles the same
kernels for the same argument types into numba's on-disk cache, while the run
compiles the render kernel and renders. When the run reaches them it loads
them from the cache. The results do not depend on it (the same compiled code
either way).

A marker file beside numba's cache of the agent kernel records a finished
warm-up per method and code version, so later runs start no process; a run
that ends first stops the warm-up (numba writes its cache files atomically).
"""

from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np

#: the source files whose kernels the warm-up compiles (their sizes and times key the marker)
_KERNEL_SOURCES = ("homing", "evaluation")


def _marker(method: str) -> Path | None:
    """The file recording a finished warm-up of ``method`` for this code and numba (None: numba caches nowhere)."""
    import numba

    from bionav.evaluation import agent

    cache = getattr(agent._agent_success_kernel, "_cache", None)
    folder = getattr(cache, "_cache_path", None)
    if folder is None:
        return None
    package = Path(__file__).resolve().parents[1]
    stamp = [numba.__version__, method, os.environ.get("NUMBA_CPU_NAME", ""), os.environ.get("NUMBA_CPU_FEATURES", "")]
    for room in _KERNEL_SOURCES:
        for path in sorted((package / room).rglob("*.py")):
            st = path.stat()
            stamp.append(f"{path.name}:{st.st_size}:{st.st_mtime_ns}")
    digest = hashlib.sha256("\n".join(stamp).encode()).hexdigest()[:16]
    return Path(folder) / f"bionav-warmup-{method}-{digest}.done"


def _ships_with_bionav(method: str) -> bool:
    """Whether homing method ``method`` is one of bionav's own (its entry point declared by bionav).

    A third-party plugin is never warmed up: its ``home_vector`` may have side effects (files,
    devices, sleeps) that must not run a second time in another process unasked.
    """
    from bionav.registry import entry_points_of

    entry = entry_points_of("homing").get(method)
    return entry is not None and entry.distribution == "bionav" and entry.value.startswith("bionav.")


def start_warmup(cfg: Any, *, used_groups: tuple[str, ...]) -> subprocess.Popen | None:
    """Start compiling ``cfg.homing``'s kernels in a second process, unless done before; the process or None.

    Only for runs that home (``homing`` among ``used_groups``) with one of bionav's own methods
    (:func:`_ships_with_bionav`) built from its config and the images' geometry alone; any problem here just means no warm-up (the run compiles what it needs).
    """
    from omegaconf import OmegaConf

    node = cfg.get("homing") if "homing" in used_groups else None
    if not node or not node.get("name") or os.environ.get("BIONAV_NO_WARMUP"):
        return None
    try:
        if not _ships_with_bionav(str(node.name)):
            return None
        marker = _marker(str(node.name))
        if marker is None or marker.exists():
            return None
        plain = json.dumps(OmegaConf.to_container(node, resolve=True))
        db = cfg.get("db")
        renders = "render" if db is not None and db.get("source") == "synthetic" else "no-render"
        return subprocess.Popen([sys.executable, "-m", "bionav.experiments.warmup", plain, str(marker), renders],
                                stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                env={**os.environ, "BIONAV_NO_WARMUP": "1"})
    except Exception:  # a warm-up is an optimisation: never a reason for a run to fail
        return None


def stop_warmup(proc: subprocess.Popen | None) -> None:
    """End a warm-up that is still running (the run is over)."""
    if proc is not None and proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()


def _tiny_database():
    """A 3 x 3 grid of smooth random panoramas (128 x 32, seeded): texture for every method's features."""
    from scipy.ndimage import gaussian_filter

    from bionav.db.database import ImageDatabase
    from bionav.geometry import PanoramaGeometry

    rng = np.random.default_rng(0)
    images = np.stack([gaussian_filter(rng.random((32, 128)), 1.5, mode=("reflect", "wrap")) for _ in range(9)])
    images = ((images - images.min()) / np.ptp(images)).astype(np.float32)
    positions = np.array([(x, y) for x in range(3) for y in range(3)])
    return ImageDatabase("warmup", images, positions, (3, 3), PanoramaGeometry.square_pixels(128, 32))


def warm(node: dict) -> None:
    """Home with the method of config ``node`` on :func:`_tiny_database` and run its return agents."""
    import inspect

    from bionav.config import plugin_config, register_configs
    from bionav.evaluation.agent import evaluate_agents
    from bionav.evaluation.pairs import home_vector_matrix

    register_configs()
    cls, config = plugin_config("homing", node)
    extra = [p for p in list(inspect.signature(cls.__init__).parameters.values())[2:]
             if p.name != "geometry" and p.default is inspect.Parameter.empty and p.kind != p.VAR_KEYWORD]
    if extra:  # needs more than its config and the geometry (e.g. a signature plugin): not warmed
        return
    db = _tiny_database()
    hv = home_vector_matrix(cls(config, geometry=db.geometry), db, workers=1)
    evaluate_agents(db, hv, step_length=0.5, success_radius=1.0)


def warm_shadow_bins() -> None:
    """Build the shadow bins of one point light over two casters (compiles :func:`build_shadow_bins`), unless cached."""
    from bionav.files import numba_cached
    from bionav.world.shadow_bins import build_shadow_bins

    if numba_cached(build_shadow_bins):
        return
    lights = np.zeros((1, 6))  # one point light (kind 0) at the origin, group 0
    spheres = np.array([[1.0, 0.0, 0.0, 0.5], [0.0, 2.0, 0.0, 0.5]])
    build_shadow_bins(lights, spheres, np.arange(2, dtype=np.int64))


def main(argv: list[str]) -> int:
    node, marker = json.loads(argv[0]), Path(argv[1])
    if argv[2:] == ["render"]:
        warm_shadow_bins()
    warm(node)
    marker.parent.mkdir(parents=True, exist_ok=True)
    marker.write_text("compiled\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
