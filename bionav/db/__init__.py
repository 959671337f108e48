"""Image databases: loaders, synthetic stand-ins, preprocessing.

:class:`ImageDatabase` is imported on first use (PEP 562): config schemas in
:mod:`bionav.db.config` are read at start-up (TAB completion, ``--help``)
without NumPy.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from bionav.db.database import ImageDatabase

__all__ = ["ImageDatabase"]


def __getattr__(name: str) -> Any:
    if name == "ImageDatabase":
        from bionav.db.database import ImageDatabase

        return ImageDatabase
    raise AttributeError(f"module 'bionav.db' has no attribute {name!r}")
