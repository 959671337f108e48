"""Extra report sections derived from the rows of a sweep (method comparisons, rankings)."""

from __future__ import annotations

import csv
import itertools
from pathlib import Path
from typing import Any

import numpy as np

from bionav.report.ranking import ranking_sections
from bionav.report.table import markdown_table


def _per_snapshot(run_dir: Path) -> dict[tuple[int, int], tuple[float, float]] | None:
    path = run_dir / "per_snapshot.csv"
    if not path.is_file():
        return None
    with open(path) as f:
        return {(int(r["x"]), int(r["y"])): (float(r["aae_s"]), float(r["rr_s"])) for r in csv.DictReader(f)}


def _method_label(row: dict[str, Any]) -> str:
    label = str(row.get("homing", "?"))
    extras = [f"{k}={v}" for k, v in row.items() if k.startswith(("homing.", "signature", "preprocess")) and k != "homing"]
    return label + (f" ({', '.join(extras)})" if extras else "")


def comparison_rows(root: Path, rows: list[dict[str, Any]], *, n_resamples: int = 2000, seed: int = 0) -> list[dict[str, Any]]:
    """Paired bootstrap comparisons of every two methods evaluated on the same database.

    For each database with several completed grid-homing runs, and for each
    pair of runs, the per-snapshot AAE_s and RR_s are paired over the common
    snapshot positions; the difference of their means (AAE*, RR*) gets a BCa
    95 % interval (B = 2000, thesis 3.3.2), a jackknife standard error
    (thesis 3.3.1), and significance stars at 5/1/0.1 %.
    """
    from bionav.stats.bootstrap import paired_bootstrap_difference
    from bionav.stats.jackknife import jackknife

    rng = np.random.default_rng(seed)
    by_db: dict[str, list[tuple[dict, dict]]] = {}
    for row in rows:
        if row.get("status") != "completed" or row.get("experiment") != "grid_homing":
            continue
        data = _per_snapshot(root / row["job"])
        if data:
            by_db.setdefault(str(row.get("db")), []).append((row, data))
    out = []
    for db, runs in sorted(by_db.items()):
        for (ra, da), (rb, db_) in itertools.combinations(runs, 2):
            common = sorted(set(da) & set(db_))
            if len(common) < 3:
                continue
            a = np.array([da[k] for k in common])
            b = np.array([db_[k] for k in common])
            entry: dict[str, Any] = {"db": db, "A": _method_label(ra), "B": _method_label(rb), "n": len(common)}
            for j, key in enumerate(("AAE*", "RR*")):
                diff = paired_bootstrap_difference(a[:, j], b[:, j], n_resamples=n_resamples, rng=rng)
                lo, hi = diff.ci(0.95)
                se = jackknife(a[:, j] - b[:, j], np.mean).standard_error
                entry[f"d{key} (A-B)"] = f"{diff.estimate:+.4f}"
                entry[f"95% CI {key}"] = f"[{lo:+.4f}, {hi:+.4f}]"
                entry[f"SE {key}"] = f"{se:.4f}"
                entry[f"sig {key}"] = diff.stars or "n.s."
            out.append(entry)
    return out


def extra_sections(root: Path, rows: list[dict[str, Any]]) -> list[str]:
    """Markdown sections added to summary.md when the runs support them."""
    sections = []
    comparisons = comparison_rows(root, rows)
    if comparisons:
        cols = list(comparisons[0])
        sections.append(
            "## Method comparisons (paired bootstrap over snapshot positions, B = 2000, BCa)\n\n"
            "Significance: * 5 %, ** 1 %, *** 0.1 % (the BCa interval of the difference excludes zero).\n\n"
            + markdown_table(comparisons, cols)
        )
    sections += ranking_sections(root, rows)
    return sections
