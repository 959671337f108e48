"""Plain-text and Markdown tables of run metrics."""

from __future__ import annotations

import math
from typing import Any, Iterable, Mapping, Sequence

#: metrics shown first (in this order) when present
PREFERRED = ("status", "aae", "mae", "rr", "compass_aae", "n_images", "n_pairs", "ms_per_home_vector")


def format_cell(value: Any) -> str:
    """Format one cell: floats with 4 significant decimals, None as empty."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        return f"{value:.4f}" if abs(value) < 1e5 else f"{value:.4g}"
    return str(value)


def flatten(metrics: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """Flatten nested metric objects to ``a.b`` keys (lists are dropped)."""
    out: dict[str, Any] = {}
    for key, value in metrics.items():
        name = f"{prefix}{key}"
        if isinstance(value, Mapping):
            out.update(flatten(value, f"{name}."))
        elif not isinstance(value, (list, tuple)):
            out[name] = value
    return out


def _cell(text: str) -> str:
    """Markdown table cell text: ``|`` escaped, line breaks as ``<br>`` (an error message stays in its cell)."""
    return text.replace("\\", "\\\\").replace("|", "\\|").replace("\r\n", "\n").replace("\n", "<br>")


def markdown_table(rows: Sequence[Mapping[str, Any]], columns: Sequence[str]) -> str:
    """A GitHub-flavoured Markdown table (cells with ``|`` or line breaks escaped)."""
    head = "| " + " | ".join(_cell(str(c)) for c in columns) + " |"
    sep = "|" + "|".join("---" for _ in columns) + "|"
    body = ["| " + " | ".join(_cell(format_cell(r.get(c))) for c in columns) + " |" for r in rows]
    return "\n".join([head, sep, *body])


def ordered_columns(rows: Iterable[Mapping[str, Any]], first: Sequence[str] = ()) -> list[str]:
    """Columns: ``first``, then preferred metrics, then the rest in first-seen order."""
    seen: list[str] = []
    for r in rows:
        for k in r:
            if k not in seen:
                seen.append(k)
    cols = [c for c in first if c in seen]
    cols += [c for c in PREFERRED if c in seen and c not in cols]
    cols += [c for c in seen if c not in cols]
    return cols


#: what a metric is called in the thesis (3.2) and the docs, with its unit, by its metrics.json key
LABELS = {
    "aae": "AAE* (rad)",
    "mae": "MAE* (rad)",
    "rr": "RR* (fraction of agents home)",
    "compass_aae": "compass AAE* (rad)",
    "n_images": "images",
    "n_pairs": "snapshot/current-view pairs",
    "ms_per_home_vector": "time per home vector (ms)",
    "keypoints_per_image": "SIFT keys per image",
    "wall_time_s": "wall time (s)",
}


def format_metrics(metrics: Mapping[str, Any]) -> str:
    """The results table a single run prints (Markdown, one metric per row).

    Columns: the metric as the thesis and the docs name it, with its unit
    (:data:`LABELS`: ``AAE* (rad)``, ``MAE* (rad)``, ``RR* (fraction of agents home)``, ...), its value,
    and its key in metrics.json.
    """
    flat = flatten(metrics)
    keys = [k for k in ordered_columns([flat]) if k != "wall_time_s"] + (["wall_time_s"] if "wall_time_s" in flat else [])
    rows = [{"metric": LABELS.get(k, k), "value": flat[k], "metrics.json": k} for k in keys]
    return markdown_table(rows, ["metric", "value", "metrics.json"])
