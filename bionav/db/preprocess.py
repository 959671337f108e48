"""The config-driven preprocessing chain of thesis 5.2.1 (Butterworth low-pass, edges, equalisation, resize).

The operations themselves live in :mod:`bionav.homing.imageops`; this module
validates a chain of steps from the ``preprocess`` config group and applies
it to a database.

The thesis' presets (``preprocess=`` on the command line, ``bionav/conf/preprocess``):

======  ==========================================================
none    no preprocessing
bw1     Butterworth low-pass, order 1, relative cutoff 0.03
bw2     Butterworth low-pass, order 2, relative cutoff 0.015
bw1e    bw1 followed by the edge filter
bw2e    bw2 followed by the edge filter
he      histogram equalisation
======  ==========================================================

The thesis names the filters "Butterworth 1 with a 0.03 cutoff frequency" and
"Butterworth 2 with a 0.015 cutoff frequency"; bionav reads the digit as the
filter order (the issue asks for orders 1/2/3). Any other combination is a
free list of steps, e.g.
``preprocess.name=bw3e 'preprocess.steps=[{op:butterworth,order:3,cutoff:0.1},{op:edges}]'``.

The thesis does not name its edge detector; bionav uses the Sobel gradient
magnitude (:func:`bionav.homing.imageops.edge_filter`). In the thesis a cutoff of 1.0 "depicts
unfiltered images"; bionav's Butterworth filter with cutoff 1.0 still halves the
power at the Nyquist frequency, so use ``preprocess=none`` for unfiltered images.

Cutoffs relative to the raw camera frame: in the thesis the filters were
applied to the raw camera frame before unfolding, so a cutoff such as bw1's 0.03
is relative to the Nyquist frequency of the *raw* frame (0.5 cycles per raw
pixel) and keeps the same angular detail whatever size the panorama is unfolded
to. Steps with ``relative_to: raw`` (the presets bw1, bw2, bw1e, bw2e) convert
it to the panorama at hand with :func:`panorama_cutoff_from_raw`: on the raw
frame's horizon circle of radius ``r_h`` pixels a raw frequency of ``f`` cycles
per pixel is ``2 pi r_h f`` cycles per revolution, i.e. ``2 pi r_h f / W`` cycles
per panorama pixel, so ``cutoff_panorama = cutoff_raw * 2 pi r_h / W``. ``r_h``
is the database's ``meta["raw_horizon_radius_px"]`` (the stand-ins' mirror
model, :func:`bionav.db.camera.raw_horizon_radius`), else the ultra-wide-view
mirror's. The filter then runs on the panorama (cyclic in azimuth), isotropic
in panorama pixels. Steps without ``relative_to`` (or ``relative_to:
panorama``) keep a cutoff relative to the panorama's own Nyquist frequency.
"""

from __future__ import annotations

from dataclasses import MISSING, dataclass, field, replace
from typing import Any

import numpy as np

from bionav.db.config import MAX_IMAGE_SIDE
from bionav.db.database import ImageDatabase
from bionav.errors import UserError
from bionav.homing.imageops import (
    butterworth_lowpass,
    edge_filter,
    equalize_histogram,
    panorama_cutoff_from_raw,
    resize_images,
)
from bionav.validation import Range, bounded, typed_config

OPS = ("butterworth", "edges", "equalize", "resize")


@dataclass
class PreprocessConfig:
    """A named chain of preprocessing steps (the ``preprocess`` config group).

    ``steps`` is a list of mappings ``{op: <name>, <param>: <value>, ...}``
    with ``op`` one of ``butterworth`` (``order``, ``cutoff``), ``edges``
    (``method``), ``equalize`` (``levels``), ``resize`` (``size: [W, H]``),
    applied in order.
    """

    name: str = "none"
    steps: list[dict[str, Any]] = field(default_factory=list)


# ---------------------------------------------------------------------------
# chains: one typed dataclass per op, each step through bionav.validation.typed_config


@dataclass
class ButterworthStep:
    """``{op: butterworth, order, cutoff, relative_to}``: cutoff relative to the Nyquist frequency of the
    panorama, or of the raw camera frame (``relative_to: raw``, as in the thesis)."""

    cutoff: float = bounded(MISSING, gt=0.0, le=1e6)
    order: int = bounded(1, ge=1, le=100)
    relative_to: str = bounded("panorama", choices=("panorama", "raw"))


@dataclass
class EdgesStep:
    """``{op: edges, method}``."""

    method: str = bounded("sobel", choices=("sobel",))


@dataclass
class EqualizeStep:
    """``{op: equalize, levels}``: grey levels of the histogram equalisation."""

    levels: int = bounded(256, ge=2, le=65536)


@dataclass
class ResizeStep:
    """``{op: resize, size: [W, H]}`` in pixels."""

    size: list[int] = bounded(MISSING, length=2, items=(Range(ge=1, le=MAX_IMAGE_SIDE), Range(ge=1, le=MAX_IMAGE_SIDE)),
                              names=("W", "H"))


#: op -> the dataclass of its parameters
STEPS: dict[str, type] = {"butterworth": ButterworthStep, "edges": EdgesStep, "equalize": EqualizeStep,
                          "resize": ResizeStep}


def _normalise_step(step) -> dict:
    """A step mapping with its ``op`` and every parameter typed and checked (defaults filled)."""
    import dataclasses

    try:
        step = {str(k): v for k, v in dict(step).items()}
    except (TypeError, ValueError):
        raise UserError(f"a preprocessing step must be a mapping like {{op: butterworth, cutoff: 0.03}}, got {step!r}.") from None
    op = step.pop("op", "")
    if op not in OPS:
        raise UserError(f"unknown preprocessing op {op!r}; the ops are {', '.join(OPS)}.")
    typed = typed_config(step, STEPS[op], key="preprocess.step", what=f"the preprocessing op {op!r}")
    return {"op": op, **dataclasses.asdict(typed)}


def preprocess_images(images: np.ndarray, steps, *, raw_horizon_radius_px: float | None = None) -> np.ndarray:
    """Apply a chain of preprocessing steps to a stack of panoramas.

    Parameters
    ----------
    images : ndarray, shape (N, H, W) or (H, W), float32 in [0, 1]
        Canonical panoramas (periodic in x).
    steps : sequence of mapping
        ``[{op: butterworth, order: 1, cutoff: 0.03}, {op: edges}, ...]``
        (see :class:`PreprocessConfig`), applied in order. An empty list
        returns the images unchanged.
    raw_horizon_radius_px : float, optional
        Horizon radius of the raw frame for steps with ``relative_to: raw``
        (default: the ultra-wide-view mirror's, :func:`bionav.db.camera.raw_horizon_radius`).

    Returns
    -------
    ndarray, float32
    """
    out = np.asarray(images, dtype=np.float32)
    for raw_step in steps or []:
        step = _normalise_step(raw_step)
        op = step.pop("op")
        if op == "butterworth":
            cutoff = step["cutoff"]
            if step["relative_to"] == "raw":
                if raw_horizon_radius_px is None:
                    from bionav.db.camera import raw_horizon_radius

                    raw_horizon_radius_px = raw_horizon_radius("ultra-wide")
                cutoff = panorama_cutoff_from_raw(cutoff, width=out.shape[-1],
                                                  raw_horizon_radius_px=raw_horizon_radius_px)
            out = butterworth_lowpass(out, order=step["order"], cutoff=cutoff, clip=(0.0, 1.0))
        elif op == "edges":
            out = edge_filter(out, method=step["method"])
        elif op == "equalize":
            out = equalize_histogram(out, levels=step["levels"])
        else:
            out = resize_images(out, step["size"])
    return out


def _steps_of(preprocess) -> tuple[str, list]:
    if preprocess is None:
        return "none", []
    if isinstance(preprocess, PreprocessConfig):
        return preprocess.name, list(preprocess.steps)
    if hasattr(preprocess, "get") and "steps" in preprocess:
        return str(preprocess.get("name", "custom")), list(preprocess["steps"] or [])
    return "custom", list(preprocess)


def preprocess_database(db: ImageDatabase, preprocess) -> ImageDatabase:
    """A copy of ``db`` with preprocessed images (geometry updated by ``resize`` steps).

    Parameters
    ----------
    db : ImageDatabase
    preprocess : PreprocessConfig, mapping with ``steps``, or list of steps

    Returns
    -------
    ImageDatabase
        Same positions, grid, headings and raw access; ``meta["preprocess"]``
        records the chain's name.
    """
    name, steps = _steps_of(preprocess)
    if not steps:
        return db
    images = preprocess_images(db.images, steps, raw_horizon_radius_px=db.meta.get("raw_horizon_radius_px"))
    geometry = db.geometry
    if images.shape[-2:] != db.images.shape[-2:]:
        geometry = geometry.resized(images.shape[-1], images.shape[-2])
    meta = dict(db.meta)
    meta["preprocess"] = meta.get("preprocess", []) + [name]
    return replace(db, images=images, geometry=geometry, meta=meta)


def resize_database(db: ImageDatabase, size) -> ImageDatabase:
    """A copy of ``db`` resized to ``size = [W, H]`` (``cv2.INTER_AREA``), geometry updated."""
    width, height = (int(v) for v in size)
    if db.images.shape[-2:] == (height, width):
        return db
    images = resize_images(db.images, (width, height))
    return replace(db, images=images, geometry=db.geometry.resized(width, height))
