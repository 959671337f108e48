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

Deviation from the thesis: there, the filters were applied to the raw camera
frame before unfolding. bionav filters the panorama at its native resolution
(cyclic in azimuth) with the cutoff relative to the panorama's Nyquist
frequency; at the databases' native 1122 pixels per 360 degrees a cutoff of
0.03 keeps about 17 cycles per revolution, close to what the same relative
cutoff keeps on a raw frame with a horizon circle of about 200 pixels radius.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from bionav.db.database import ImageDatabase
from bionav.errors import UserError
from bionav.homing.imageops import (
    butterworth_lowpass,
    check_image_size,
    edge_filter,
    equalize_histogram,
    resize_images,
)

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
# chains

_PARAMS = {
    "butterworth": {"order", "cutoff"},
    "edges": {"method"},
    "equalize": {"levels"},
    "resize": {"size"},
}


def _normalise_step(step) -> dict:
    try:
        step = {str(k): v for k, v in dict(step).items()}
    except (TypeError, ValueError):
        raise UserError(f"a preprocessing step must be a mapping like {{op: butterworth, cutoff: 0.03}}, got {step!r}.") from None
    op = str(step.pop("op", "")).strip().lower()
    if op not in OPS:
        raise UserError(f"unknown preprocessing op {op!r}; the ops are {', '.join(OPS)}.")
    unknown = set(step) - _PARAMS[op]
    if unknown:
        raise UserError(
            f"preprocessing op {op!r} has no parameter(s) {', '.join(sorted(unknown))}; "
            f"it takes {', '.join(sorted(_PARAMS[op]))}."
        )
    if op == "butterworth":
        if "cutoff" not in step:
            raise UserError("preprocessing op 'butterworth' needs a cutoff (relative to the Nyquist frequency).")
        order, cutoff = int(step.get("order", 1)), float(step["cutoff"])
        if order < 1 or not cutoff > 0:
            raise UserError(f"butterworth needs order >= 1 and cutoff > 0 (got order={order}, cutoff={cutoff}).")
    if op == "resize":
        if "size" not in step or len(list(step["size"])) != 2:
            raise UserError("preprocessing op 'resize' needs size: [W, H].")
        step["size"] = list(check_image_size(step["size"], name="resize size"))
    return {"op": op, **step}


def preprocess_images(images: np.ndarray, steps) -> np.ndarray:
    """Apply a chain of preprocessing steps to a stack of panoramas.

    Parameters
    ----------
    images : ndarray, shape (N, H, W) or (H, W), float32 in [0, 1]
        Canonical panoramas (periodic in x).
    steps : sequence of mapping
        ``[{op: butterworth, order: 1, cutoff: 0.03}, {op: edges}, ...]``
        (see :class:`PreprocessConfig`), applied in order. An empty list
        returns the images unchanged.

    Returns
    -------
    ndarray, float32
    """
    out = np.asarray(images, dtype=np.float32)
    for raw_step in steps or []:
        step = _normalise_step(raw_step)
        op = step.pop("op")
        if op == "butterworth":
            out = butterworth_lowpass(out, order=int(step.get("order", 1)), cutoff=float(step["cutoff"]), clip=(0.0, 1.0))
        elif op == "edges":
            out = edge_filter(out, method=str(step.get("method", "sobel")))
        elif op == "equalize":
            out = equalize_histogram(out, levels=int(step.get("levels", 256)))
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
    images = preprocess_images(db.images, steps)
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
