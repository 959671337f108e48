"""Collecting the runs below a directory into one table (sweeps, or any tree of runs)."""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Any

from bionav.report.table import flatten, markdown_table, ordered_columns


def _overrides(job_dir: Path) -> dict[str, str]:
    path = job_dir / ".hydra" / "overrides.yaml"
    if not path.is_file():
        return {}
    import yaml

    out = {}
    for item in yaml.safe_load(path.read_text()) or []:
        key, _, value = str(item).partition("=")
        out[key.lstrip("+~")] = value
    return out


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
        try:
            metrics = json.loads((run_dir / "metrics.json").read_text())
        except (OSError, ValueError):
            metrics = {"status": "failed", "error": "no metrics.json (the job died before finishing)"}
        row.update(flatten(metrics))
        rows.append(row)
    return rows, override_keys


def write_summary(root: Path) -> tuple[Path, Path, list[dict[str, Any]]]:
    """Write ``summary.csv`` and ``summary.md`` into ``root``; return their paths and the rows."""
    root = Path(root)
    rows, override_keys = collect_rows(root)
    columns = ordered_columns(rows, first=["job", *override_keys, "status"])
    csv_path, md_path = root / "summary.csv", root / "summary.md"
    with open(csv_path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=columns, extrasaction="ignore")
        writer.writeheader()
        for row in rows:
            writer.writerow({c: row.get(c, "") for c in columns})
    n_failed = sum(1 for r in rows if r.get("status") != "completed")
    text = [f"# Summary of {root}", "", f"{len(rows)} runs, {n_failed} failed.", "", markdown_table(rows, columns), ""]
    md_path.write_text("\n".join(text))
    return csv_path, md_path, rows
