"""Test helpers: run the command line in a subprocess; write tiny Vardy-named databases."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import time
from pathlib import Path

#: the checkout this test suite belongs to
REPO = Path(__file__).resolve().parents[1]


#: seconds a refused command may take: Python, Hydra and the config composition only (a loaded 2-core machine)
REFUSAL_S = 120


def run_tiny(tiny: Path, *args: str, cwd: Path, env: dict | None = None):
    """``python -m bionav homing=mfdid db=folder db.path=<tiny> args``: a grid-homing run of seconds."""
    return run_bionav("homing=mfdid", "db=folder", f"db.path={tiny}", *args, cwd=cwd, env=env)


def run_bionav(*args: str, cwd: Path, env: dict | None = None, module: str = "bionav", timeout: float = 600):
    """Run ``python -m <module> args`` and return the CompletedProcess (text mode), with ``.seconds`` (wall time)."""
    full_env = dict(os.environ)
    full_env.setdefault("BIONAV_CACHE", str(Path(cwd) / "cache"))
    full_env.update(env or {})
    started = time.monotonic()
    proc = subprocess.run(
        [sys.executable, "-m", module, *args], cwd=cwd, env=full_env, capture_output=True, text=True, timeout=timeout
    )
    proc.seconds = time.monotonic() - started
    return proc


def assert_fails_cleanly(proc, *needles: str, code: int | None = None, max_seconds: float | None = None,
                         absent: tuple[str, ...] = ()) -> str:
    """The one "fails cleanly" check of the hostile suites (issue 28): returns the error paragraph.

    A non-zero exit status (``code`` if given), no Python traceback on stdout or stderr, exactly one
    paragraph (one line, ``<prog>: error: ...``) on stderr, not an internal error, that contains every
    needle (the problem and the fix named) and none of ``absent`` (anywhere on stderr), and, with
    ``max_seconds``, a bounded wall time (``proc.seconds`` from :func:`run_bionav`).
    """
    out, err = proc.stdout or "", proc.stderr or ""
    assert proc.returncode != 0, f"exit status 0\n{out}\n{err}"
    if code is not None:
        assert proc.returncode == code, f"exit status {proc.returncode}, expected {code}\n{err}"
    assert "Traceback" not in err and "Traceback" not in out, err or out
    errors = [line for line in err.splitlines() if re.match(r"^[\w.]+: error: ", line)]
    assert len(errors) == 1, f"expected one error paragraph on stderr:\n{err}"
    message = errors[0]
    assert "internal error" not in message, message
    for needle in needles:
        assert needle in message, f"{needle!r} not in the error paragraph:\n{message}"
    for needle in absent:
        assert needle not in err, err
    if max_seconds is not None:
        assert proc.seconds <= max_seconds, f"took {proc.seconds:.1f} s (bound {max_seconds} s)"
    return message


def install_plugin_dist(site: Path, dist: str, entry_points: dict, modules: dict) -> Path:
    """A real ``.dist-info`` (with entry points) and modules in folder ``site``, found by importlib.metadata
    once ``site`` is on PYTHONPATH: a third-party plugin installed without pip."""
    import textwrap

    info = site / f"{dist.replace('-', '_')}-1.0.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {dist}\nVersion: 1.0\n")
    lines = []
    for group, eps in entry_points.items():
        lines.append(f"[{group}]")
        lines += [f"{name} = {target}" for name, target in eps.items()]
    (info / "entry_points.txt").write_text("\n".join(lines) + "\n")
    for name, source in modules.items():
        (site / f"{name}.py").write_text(textwrap.dedent(source))
    return site


def pythonpath_with(site: Path) -> dict:
    """Environment additions putting ``site`` first on PYTHONPATH."""
    return {"PYTHONPATH": os.pathsep.join([str(site), os.environ.get("PYTHONPATH", "")]).rstrip(os.pathsep)}


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


def run_into_closed_pipe(*args: str, module: str, cwd: Path, timeout: float = 300):
    """``python -m <module> args`` with stdout a pipe whose reader has gone (``... | head -1`` once head exited).

    The read end is closed before the command starts, so its first write fails (EPIPE) whatever its timing.
    Returns the CompletedProcess (``stdout`` empty, ``stderr`` text).
    """
    read_end, write_end = os.pipe()
    os.close(read_end)
    try:
        proc = subprocess.run([sys.executable, "-m", module, *args], cwd=cwd, stdout=write_end, stderr=subprocess.PIPE,
                              text=True, timeout=timeout, env=dict(os.environ))
    finally:
        os.close(write_end)
    proc.stdout = ""
    return proc


def source_copy(src: Path, dst: Path) -> Path:
    """A copy of the source tree ``src`` in ``dst``, to build or install from without writing into the checkout.

    pip builds a local directory in place (``build/``, ``*.egg-info``); tests build the copy instead.
    Version-control files, virtual environments and caches are left out.
    """
    import shutil

    ignore = shutil.ignore_patterns(".git", ".venv", ".ci-venv", "venv", "build", "*.egg-info", "__pycache__",
                                    ".pytest_cache", ".ruff_cache", ".ci-cache", "outputs", "multirun", "dist")
    shutil.copytree(src, dst, ignore=ignore, symlinks=True)
    return Path(dst)


#: a fenced block holding a file of a package shown in the docs: ```python file=<package folder>/<path>
DOCS_FILE_BLOCK = re.compile(r"^```\w+ file=(\S+)\n(.*?)^```", re.M | re.S)


def docs_packages() -> dict[str, dict[str, str]]:
    """Packages written out in README.md and docs/*.md as ``file=`` blocks: folder -> {path in it: text}."""
    out: dict[str, dict[str, str]] = {}
    for doc in [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]:
        for path, text in DOCS_FILE_BLOCK.findall(doc.read_text()):
            folder, _, rel = path.partition("/")
            out.setdefault(folder, {})[rel] = text
    return out


def write_docs_package(folder: str, dst: Path) -> Path:
    """The docs' package ``folder`` (:func:`docs_packages`) written under ``dst / folder``."""
    root = Path(dst) / folder
    for rel, text in docs_packages()[folder].items():
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_text(text)
    return root


def external_data() -> Path:
    """Real data written by others: ``$BIONAV_EXTERNAL_DATA``, else ``../shared/data`` beside the checkout."""
    env = os.environ.get("BIONAV_EXTERNAL_DATA")
    return Path(env) if env else REPO.parent / "shared" / "data"


def cleaning_config(controller: str, **experiment):
    """experiment=cleaning on 3 lanes of 1.2 m, oracle vision, 2 runs, seed 0, as a plain config."""
    from omegaconf import OmegaConf

    conf = REPO / "bionav" / "conf"
    exp = OmegaConf.load(conf / "experiment" / "cleaning.yaml")
    del exp["defaults"]
    layout = OmegaConf.load(conf / "layout" / "long_lanes.yaml")
    layout.n_lanes, layout.lane_length = 3, 1.2
    cfg = OmegaConf.merge(exp, {"layout": layout, "controller": {"name": controller}, "seed": 0, "runs": 2,
                                "experiment": {"vision": "oracle", **experiment}})
    return cfg


def round_room(grid_shape=(5, 4), missing=((2, 1),), width=72, height=12):
    """Panoramas in a round room (radius 6 cells) with a textured wall, floor and ceiling: real parallax."""
    import numpy as np

    from bionav.db.database import ImageDatabase
    from bionav.geometry import PanoramaGeometry

    geometry = PanoramaGeometry.square_pixels(width, height)
    theta = geometry.column_azimuths()
    elev = geometry.row_elevations()
    centre = np.array([(grid_shape[0] - 1) / 2, (grid_shape[1] - 1) / 2])
    cells = [(x, y) for x in range(grid_shape[0]) for y in range(grid_shape[1]) if (x, y) not in missing]
    images = []
    for cell in cells:
        p = np.asarray(cell, float) - centre
        d = np.stack([np.cos(theta), np.sin(theta)], 1)
        b = d @ p
        t = -b + np.sqrt(b * b - (p @ p - 36.0))  # distance to the wall along each column
        hit = p + t[:, None] * d
        phi = np.arctan2(hit[:, 1], hit[:, 0])
        wall = 0.5 + 0.25 * np.sin(5 * phi) + 0.12 * np.sin(13 * phi + 1.0)
        z = np.tan(elev)[:, None] * t[None, :]  # height of the hit point relative to the camera
        img = np.where(z > 1.5, 0.9, np.where(z < -0.8, 0.15, wall[None, :]))
        images.append(np.rint(img * 255) / 255)
    return ImageDatabase("round_room", np.asarray(images, np.float32), cells, grid_shape, geometry, spacing_m=0.3)
