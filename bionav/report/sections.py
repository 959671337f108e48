"""Extra report sections derived from the rows of a sweep (comparisons, rankings)."""

from __future__ import annotations

from pathlib import Path
from typing import Any


def extra_sections(root: Path, rows: list[dict[str, Any]]) -> list[str]:
    """Markdown sections added to summary.md when the runs support them."""
    return []
