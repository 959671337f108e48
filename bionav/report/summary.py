"""Collecting the runs below a directory into one table (sweeps, or any tree of runs)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from bionav.files import write_csv_atomic
from bionav.report.table import flatten, markdown_table, ordered_columns


def _overrides(job_dir: Path) -> dict[str, str]:
    path = job_dir / ".hydra" / "overrides.yaml"
    if not path.is_file():
        return {}
    import yaml

    try:
        items = yaml.safe_load(path.read_text()) or []
    except (OSError, ValueError, yaml.YAMLError):
        return {}
    if not isinstance(items, list):  # not written by Hydra
        return {}
    out = {}
    for item in items:
        key, _, value = str(item).partition("=")
        out[key.lstrip("+~")] = value
    return out


def _read_metrics(path: Path) -> dict[str, Any]:
    """A run's metrics.json as a dict; a ``failed`` row's values when missing, not a file, unreadable or not an object."""
    from bionav.files import not_a_regular_file

    problem = not_a_regular_file(path)  # a FIFO named metrics.json must not block the report
    if problem == "does not exist":
        return {"status": "failed", "error": "no metrics.json (the job died before finishing)"}
    if problem is not None:
        return {"status": "failed", "error": f"metrics.json {problem}"}
    try:
        metrics = json.loads(path.read_text())
    except (OSError, ValueError) as exc:
        return {"status": "failed", "error": f"metrics.json cannot be read ({type(exc).__name__})"}
    if not isinstance(metrics, dict):
        return {"status": "failed", "error": f"metrics.json holds a JSON {type(metrics).__name__}, not an object"}
    return metrics


def find_runs(root: Path) -> list[Path]:
    """Run directories below ``root``: those with metrics.json or a Hydra job record."""
    root = Path(root)
    found = {p.parent for p in root.rglob("metrics.json")}
    found |= {p.parent.parent for p in root.rglob(".hydra/overrides.yaml")}
    return sorted(found, key=lambda p: (len(p.relative_to(root).parts), _natural(p.relative_to(root))))


def _natural(path: Path) -> tuple:
    return tuple(int(part) if part.isdigit() else part for part in path.parts)


def collect_rows(root: Path) -> tuple[list[dict[str, Any]], list[str]]:
    """One row per run: ``job`` (relative dir), the overrides, status and metrics.

    A job directory without a readable metrics.json is a ``failed`` row
    ("no metrics.json"), never silently missing.

    Returns
    -------
    rows, override_keys
    """
    root = Path(root)
    rows, override_keys = [], []
    for run_dir in find_runs(root):
        rel = run_dir.relative_to(root).as_posix() or "."
        row: dict[str, Any] = {"job": rel}
        overrides = _overrides(run_dir)
        for k in overrides:
            if k not in override_keys:
                override_keys.append(k)
        row.update(overrides)
        metrics = _read_metrics(run_dir / "metrics.json")
        row.update(flatten(metrics))
        rows.append(row)
    return rows, override_keys


def write_summary(root: Path, *, objective: str | None = None) -> tuple[Path, Path, list[dict[str, Any]]]:
    """Write ``summary.csv``, ``summary.md`` and the figure of the metric over the swept values
    (``summary.png``, :func:`bionav.report.sweep_figure.plot_sweep`) into ``root``; return the paths and rows."""
    from bionav.report.sweep_figure import plot_sweep

    root = Path(root)
    rows, override_keys = collect_rows(root)
    columns = ordered_columns(rows, first=["job", *override_keys, "status"])
    csv_path, md_path = root / "summary.csv", root / "summary.md"
    write_csv_atomic(csv_path, columns, ([row.get(c, "") for c in columns] for row in rows))
    n_failed = sum(1 for r in rows if r.get("status") != "completed")
    figure = plot_sweep(root, rows, override_keys, objective=objective) if rows else None
    text = [f"# Summary of {root}", "", f"{len(rows)} runs, {n_failed} failed.", "", markdown_table(rows, columns), ""]
    if figure is not None:
        text += [f"![the metric over the swept values]({figure.name})", ""]
    md_path.write_text("\n".join(text))
    return csv_path, md_path, rows
