"""The figure of a sweep: its metric over the swept values (``summary.png`` beside ``summary.md``)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Sequence

#: metrics shown when a sweep has them (thesis names and units), in this order
SWEEP_METRICS = (("aae", "AAE* (rad)"), ("rr", "RR* (fraction of agents home)"), ("mae", "MAE* (rad)"))
FIGURE = "summary.png"


def _number(value: Any) -> float | None:
    try:
        x = float(value)
    except (TypeError, ValueError):
        return None
    return x if math.isfinite(x) else None


def _metrics(rows: Sequence[dict[str, Any]], objective: str | None) -> list[tuple[str, str]]:
    """The metrics to draw: AAE*/RR* where present, else the objective, else the first numeric column."""
    done = [r for r in rows if r.get("status") == "completed"]
    present = [(k, label) for k, label in SWEEP_METRICS if any(_number(r.get(k)) is not None for r in done)][:2]
    if present:
        return present
    keys = [objective] if objective else []
    keys += [k for r in done for k in r if k not in ("job", "status") and _number(r.get(k)) is not None]
    return [(keys[0], keys[0])] if keys else []


def plot_sweep(root: Path, rows: Sequence[dict[str, Any]], override_keys: Sequence[str], *,
               objective: str | None = None) -> Path | None:
    """Draw each metric over the values of the first swept key, one line per combination of the others.

    Swept keys are the overrides with more than one value among the rows; numeric values are placed on
    a numeric axis, others in their order of appearance. Failed jobs are left out and counted in the
    title. Returns the figure's path, or None when nothing varies or no job completed.
    """
    from bionav.report.figures import pyplot, save_figure

    swept = [k for k in override_keys if len({str(r.get(k, "")) for r in rows}) > 1]
    metrics = _metrics(rows, objective)
    done = [r for r in rows if r.get("status") == "completed"]
    if not swept or not metrics or not done:
        return None
    x_key, others = swept[0], swept[1:]
    values = list(dict.fromkeys(str(r.get(x_key, "")) for r in rows))
    numeric = all(_number(v) is not None for v in values)
    position = {v: (_number(v) if numeric else i) for i, v in enumerate(values)}
    plt = pyplot()
    fig, axes = plt.subplots(1, len(metrics), figsize=(5.0 * len(metrics), 3.6), squeeze=False)
    for ax, (key, label) in zip(axes[0], metrics):
        series: dict[str, list[tuple[float, float]]] = {}
        for r in done:
            y = _number(r.get(key))
            if y is not None:
                name = ", ".join(f"{k}={r.get(k, '')}" for k in others) or key
                series.setdefault(name, []).append((position[str(r.get(x_key, ""))], y))
        for name, points in series.items():
            points.sort()
            ax.plot([p[0] for p in points], [p[1] for p in points], marker="o", label=name,
                    linestyle="-" if numeric else "none")  # categories are not joined by lines
        if not numeric:
            ax.set_xticks(range(len(values)), values, rotation=30 if len(values) > 4 else 0, ha="right"
                          if len(values) > 4 else "center")
        ax.set_xlabel(x_key)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        if others:  # one marker colour per combination of the other swept keys
            ax.legend(fontsize=7, title=", ".join(others), title_fontsize=7)
    failed = len(rows) - len(done)
    fig.suptitle(f"{Path(root).name}: {len(done)} completed jobs" + (f", {failed} failed (not drawn)" if failed else ""),
                 fontsize=9)
    path = Path(root) / FIGURE
    save_figure(fig, path, dpi=110)
    return path
