"""The thesis' reference values (``reference.yaml``, shipped in the package)."""

from __future__ import annotations

from functools import lru_cache
from importlib import resources
from typing import Any

import yaml

#: the one-day series of 17 June 2009 (thesis appendix D.3, figs. D.7-D.10), local time (CEST)
DAY_TIMES = (
    "2009-06-17T11:27:04+02:00", "2009-06-17T12:06:19+02:00", "2009-06-17T12:46:02+02:00",
    "2009-06-17T13:25:05+02:00", "2009-06-17T14:07:52+02:00", "2009-06-17T14:47:21+02:00",
    "2009-06-17T15:26:36+02:00", "2009-06-17T16:07:15+02:00", "2009-06-17T16:46:10+02:00",
    "2009-06-17T17:26:10+02:00", "2009-06-17T18:44:09+02:00", "2009-06-17T19:24:41+02:00",
    "2009-06-17T20:03:57+02:00", "2009-06-17T20:43:36+02:00",
)


@lru_cache(maxsize=1)
def load_reference() -> dict[str, Any]:
    """Every item's thesis values and claims, keyed by item id (see reference.yaml)."""
    text = resources.files("bionav.thesis").joinpath("reference.yaml").read_text(encoding="utf-8")
    return yaml.safe_load(text)
