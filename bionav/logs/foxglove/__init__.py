"""Foxglove's own JSON schemas (vendored, MIT; see LICENSE in this folder).

A channel whose schema name is a Foxglove name (``foxglove.RawImage``,
``foxglove.PoseInFrame``, ...) is written with Foxglove's schema for it, so
the Foxglove app and other readers see exactly the contract they expect.
"""

from __future__ import annotations

import functools
import json
from importlib.resources import files
from typing import Any

#: the 32FC1-style raw image encodings Foxglove's Image panel understands (foxglove.RawImage ``data``)
RAW_IMAGE_ENCODINGS = (
    "rgb8", "rgba8", "bgr8", "8UC3", "bgra8", "32FC1", "mono8", "8UC1", "mono16", "16UC1",
    "yuv422", "uyvy", "yuv422_yuy2", "yuyv", "nv12", "bayer_rggb8", "bayer_bggr8", "bayer_gbrg8", "bayer_grbg8",
)


@functools.cache
def _all() -> dict[str, Any]:
    return json.loads(files(__name__).joinpath("jsonschemas.json").read_text())


def foxglove_schema(name: str) -> dict[str, Any]:
    """Foxglove's JSON schema for ``name`` (e.g. ``foxglove.PoseInFrame``), a fresh copy.

    Raises
    ------
    KeyError
        If Foxglove defines no schema of that name.
    """
    schemas = _all()
    if name not in schemas:
        raise KeyError(f"Foxglove defines no schema {name!r}; known: {', '.join(sorted(schemas))}")
    return json.loads(json.dumps(schemas[name]))


def foxglove_schema_names() -> list[str]:
    """Every schema name Foxglove defines (``foxglove.<Name>``)."""
    return sorted(_all())


def foxglove_time(ns: int) -> dict[str, int]:
    """A ``foxglove.Timestamp`` (``{"sec", "nsec"}``) of nanoseconds since the Unix epoch."""
    return {"sec": int(ns // 1_000_000_000), "nsec": int(ns % 1_000_000_000)}


def poses_in_frame(xy, yaw, *, timestamp_ns: int, frame_id: str) -> dict[str, Any]:
    """A ``foxglove.PosesInFrame`` message: planar poses (the 3D panel draws each as an arrow).

    Parameters
    ----------
    xy : array_like, shape (N, 2)
        Positions in metres in ``frame_id`` (z = 0).
    yaw : array_like, shape (N,)
        Headings, radians counter-clockwise about +z from the frame's +x; rows with a
        non-finite position or heading are left out (Foxglove's schema takes numbers only).
    timestamp_ns : int
        Nanoseconds since the Unix epoch.
    frame_id : str

    Returns
    -------
    dict
        ``{"timestamp", "frame_id", "poses": [{"position", "orientation"}, ...]}``.
    """
    import math

    poses = []
    for (x, y), h in zip(xy, yaw):
        x, y, h = float(x), float(y), float(h)
        if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(h)):
            continue
        poses.append({"position": {"x": x, "y": y, "z": 0.0},
                      "orientation": {"x": 0.0, "y": 0.0, "z": math.sin(h / 2.0), "w": math.cos(h / 2.0)}})
    return {"timestamp": foxglove_time(timestamp_ns), "frame_id": frame_id, "poses": poses}


#: the Foxglove layouts the package ships (``layouts/<name>.json``)
LAYOUTS = ("grid_homing", "compass")


def foxglove_layout(name: str) -> str:
    """The text of a shipped Foxglove layout (``grid_homing``: the 3D grid with home vectors, the views and the
    rows; ``compass``: pan, reference bearing and POL-OP readings of ``experiment=pol_compass``).

    Raises
    ------
    KeyError
        For a name not in :data:`LAYOUTS`.
    """
    if name not in LAYOUTS:
        raise KeyError(f"no layout {name!r}; shipped: {', '.join(LAYOUTS)}")
    return files(__name__).joinpath("layouts", f"{name}.json").read_text()
