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
