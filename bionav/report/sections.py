"""Extra report sections derived from the rows of a sweep (comparisons, rankings)."""

from __future__ import annotations

from pathlib import Path
from typing import Any


def extra_sections(root: Path, rows: list[dict[str, Any]]) -> list[str]:
    """Markdown sections added to summary.md when the runs support them."""
    sections: list[str] = []
    if any(r.get("experiment") == "param_sweep" for r in rows):
        from bionav.report.ranking import write_parameter_report

        sections += write_parameter_report(root)
    return sections
