"""Ranking tables of the parameter-homing sweep (thesis tables 5.5-5.7, figs. 5.9-5.11).

Input rows are the per-configuration records ``experiment=param_sweep`` writes
to ``param_sweep.jsonl`` (one JSON object per line: ``db``, ``signature``,
``rings``, ``n_coeffs``, ``image_size``, ``preprocess``,
``rotation_invariant``, ``rr``, ``aae`` and per-snapshot ``positions``,
``aae_s``, ``rr_s``, ``grid_shape``).

For each database, each signature's best configuration is the one with the
highest RR*, ties broken by the lower AAE* (the thesis ranks "by the quality of
the return ratio"); signatures are then ranked by that RR*.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from types import MappingProxyType
from typing import Any, Iterable, Mapping, Sequence

from bionav.files import write_csv_atomic
from bionav.report.figures import capped_colorbar, capped_colormap, pyplot
from bionav.report.table import markdown_table

ROWS_FILE = "param_sweep.jsonl"

#: columns of a ranking table (the thesis' columns, in its order)
RANKING_COLUMNS = (
    "rank", "parameter", "rr", "aae", "rings", "n_coeffs", "image_size", "preprocess", "rot_invariant",
)  # fmt: skip
#: extra columns when the database is one of the thesis' (or its ``sim_`` stand-in)
THESIS_COLUMNS = ("thesis_rank", "thesis_rr", "thesis_aae")

#: thesis tables 5.5-5.7 (after Fischer 2006): signature -> (rank, RR*, AAE*) per database
THESIS_RANKINGS: Mapping[str, Mapping[str, tuple[int, float, float]]] = MappingProxyType(
    {
        db: MappingProxyType({name: (i + 1, rr, aae) for i, (name, rr, aae) in enumerate(table)})
        for db, table in {
            "original": (
                ("image", 0.9483, 0.4626), ("fc", 0.9460, 0.4437), ("mffc_phase", 0.9120, 0.4403),
                ("mean_fft", 0.8405, 0.5966), ("cog", 0.8195, 0.6935), ("std_fft", 0.8108, 0.6497),
                ("mffc_abs", 0.7748, 0.7763), ("cog_fft", 0.7473, 0.7650), ("fc_abs", 0.6611, 0.8033),
                ("mean", 0.5411, 0.8343), ("std_fft_abs", 0.5161, 0.9967), ("hist", 0.5102, 0.9740),
                ("std", 0.4574, 0.9970), ("cog_fft_abs", 0.4201, 1.2405), ("cog_l", 0.4131, 1.1323),
                ("mean_fft_abs", 0.4062, 1.1046), ("skew", 0.3565, 1.2477), ("kurt", 0.3197, 1.0319),
                ("ent", 0.2994, 1.3158),
            ),
            "hall1": (
                ("mffc_phase", 0.9988, 0.2420), ("mffc_abs", 0.8793, 0.4956), ("fc", 0.8367, 0.5468),
                ("image", 0.7880, 0.6446), ("cog", 0.6792, 0.7060), ("std_fft", 0.6216, 0.8101),
                ("mean_fft", 0.6075, 0.7862), ("cog_fft", 0.5857, 0.8938), ("fc_abs", 0.5511, 0.7890),
                ("hist", 0.4347, 1.0096), ("mean_fft_abs", 0.4271, 0.8894), ("std_fft_abs", 0.4157, 0.9723),
                ("mean", 0.3850, 1.0238), ("std", 0.3695, 1.0255), ("cog_l", 0.3592, 1.3129),
                ("skew", 0.2936, 1.2260), ("cog_fft_abs", 0.2902, 1.3268), ("ent", 0.2689, 1.1081),
                ("kurt", 0.2598, 1.2821),
            ),
            "uni": (
                ("mffc_phase", 0.7989, 0.5143), ("mffc_abs", 0.4852, 0.8952), ("fc", 0.4381, 0.8564),
                ("image", 0.4251, 0.8538), ("mean_fft", 0.3474, 1.0714), ("fc_abs", 0.3370, 1.1633),
                ("std_fft", 0.2858, 1.1519), ("cog_fft", 0.2508, 1.3073), ("cog", 0.2448, 1.0606),
                ("mean_fft_abs", 0.2222, 1.2833), ("kurt", 0.2141, 1.2318), ("std", 0.2040, 1.2167),
                ("mean", 0.1953, 1.1981), ("std_fft_abs", 0.1843, 1.3328), ("skew", 0.1763, 1.2603),
                ("hist", 0.1750, 1.2461), ("ent", 0.1704, 1.2485), ("cog_l", 0.1684, 1.2235),
                ("cog_fft_abs", 0.1664, 1.3743),
            ),
        }.items()
    }
)  # fmt: skip


def thesis_ranking(db: str) -> Mapping[str, tuple[int, float, float]] | None:
    """The thesis' ranking (tables 5.5-5.7) for ``db`` or its ``sim_`` stand-in, else ``None``."""
    return THESIS_RANKINGS.get(db.removeprefix("sim_"))


def load_sweep_rows(root: Path) -> list[dict[str, Any]]:
    """Every configuration record (``param_sweep.jsonl``) below ``root``.

    Unreadable lines (a job killed mid-write) are skipped.
    """
    rows = []
    for path in sorted(Path(root).rglob(ROWS_FILE)):
        for line in path.read_text().splitlines():
            try:
                rows.append(json.loads(line))
            except ValueError:
                continue
    return rows


def _key(row: Mapping[str, Any]) -> tuple[float, float]:
    rr = row.get("rr")
    aae = row.get("aae")
    rr = -math.inf if rr is None or not math.isfinite(rr) else rr
    aae = math.inf if aae is None or not math.isfinite(aae) else aae
    return (rr, -aae)


def best_configurations(rows: Iterable[Mapping[str, Any]]) -> dict[str, dict[str, list[Mapping[str, Any]]]]:
    """Best configuration per database and signature, ranked.

    Returns
    -------
    dict
        ``{db: [row, ...]}`` with one row per signature (its best
        configuration by RR*, ties by AAE*), sorted best first.
    """
    best: dict[str, dict[str, Mapping[str, Any]]] = {}
    for row in rows:
        db = str(row.get("db", "?"))
        sig = str(row["signature"])
        current = best.setdefault(db, {}).get(sig)
        if current is None or _key(row) > _key(current):
            best[db][sig] = row
    return {db: sorted(sigs.values(), key=_key, reverse=True) for db, sigs in sorted(best.items())}


def ranking_table(rows: Iterable[Mapping[str, Any]], *, db: str | None = None) -> list[dict[str, Any]]:
    """The thesis' ranking table (5.5-5.7) for one database.

    Parameters
    ----------
    rows : iterable of mapping
        Configuration records (see the module docstring).
    db : str, optional
        Database to rank; required when ``rows`` hold several.

    Returns
    -------
    list of dict
        One row per signature with :data:`RANKING_COLUMNS`: ``rank`` (1 = best),
        ``parameter`` (``[name]``), ``rr`` (RR*), ``aae`` (AAE*, radians),
        ``rings`` / ``n_coeffs`` (``-`` when not a parameter of the signature),
        ``image_size`` (``WxH``), ``preprocess``, ``rot_invariant`` (``y``/``n``);
        plus :data:`THESIS_COLUMNS` (the thesis' rank, RR*, AAE* of the same
        signature) when ``db`` is a thesis database or its ``sim_`` stand-in.
    """
    ranked = best_configurations(rows)
    if db is None:
        if len(ranked) > 1:
            raise ValueError(f"rows hold several databases ({', '.join(ranked)}); pass db=")
        db = next(iter(ranked), None)
    thesis = thesis_ranking(str(db)) if db is not None else None
    out = []
    for i, row in enumerate(ranked.get(db, []), start=1):
        out.append(
            {
                "rank": i,
                "parameter": f"[{row['signature']}]",
                "rr": row["rr"],
                "aae": row["aae"],
                "rings": "-" if row.get("rings") is None else int(row["rings"]),
                "n_coeffs": "-" if row.get("n_coeffs") is None else int(row["n_coeffs"]),
                "image_size": row.get("image_size", ""),
                "preprocess": row.get("preprocess", ""),
                "rot_invariant": "y" if row.get("rotation_invariant") else "n",
            }
        )
        if thesis is not None:
            rank, rr, aae = thesis.get(str(row["signature"]), ("-", "-", "-"))
            out[-1].update({"thesis_rank": rank, "thesis_rr": rr, "thesis_aae": aae})
    return out


def ranking_markdown(table: Sequence[Mapping[str, Any]], *, db: str) -> str:
    """A ranking table as a Markdown section (heading, table)."""
    head = f"## Parameter homing ranking: {db}\n\nBest configuration per signature by RR* (AAE* in radians)"
    columns = list(RANKING_COLUMNS)
    if table and "thesis_rank" in table[0]:
        columns += THESIS_COLUMNS
        head += f"; thesis_*: the thesis' table for {db.removeprefix('sim_')} (tables 5.5-5.7)"
    return head + ".\n\n" + markdown_table(table, columns)


def plot_per_snapshot(path: Path, ranked: Sequence[Mapping[str, Any]], *, db: str, top: int = 8) -> None:
    """RR_s and AAE_s heatmaps over the grid for the ``top`` ranked signatures (figs. 5.9-5.11).

    Parameters
    ----------
    path : Path
        PNG to write.
    ranked : sequence of mapping
        Best configurations of one database, best first (:func:`best_configurations`).
    db : str
        Database name for the title.
    top : int
        How many signatures to show.
    """
    plt = pyplot()
    import numpy as np

    shown = [r for r in ranked[:top] if r.get("positions")]
    if not shown:
        return
    nx, ny = shown[0]["grid_shape"]
    fig, axes = plt.subplots(2, len(shown), figsize=(len(shown) * (0.22 * nx + 0.9), 2 * (0.22 * ny + 0.9)), squeeze=False)
    images = [None, None]
    for col, row in enumerate(shown):
        pos = np.asarray(row["positions"], dtype=int)
        panels = (("rr_s", "RR$_s$", "viridis", 1.0), ("aae_s", "AAE$_s$ (rad)", "magma_r", np.pi / 2))
        for r, (key, label, cmap, vmax) in enumerate(panels):
            m = np.full((ny, nx), np.nan)
            m[pos[:, 1], pos[:, 0]] = [np.nan if v is None else v for v in row[key]]
            ax = axes[r, col]
            images[r] = ax.imshow(m, origin="lower", cmap=capped_colormap(cmap) if key == "aae_s" else cmap,
                                  vmin=0, vmax=vmax)
            ax.set_xticks([])
            ax.set_yticks([])
            if r == 0:
                ax.set_title(f"{col + 1}. [{row['signature']}]\nRR*={row['rr']:.3f}", fontsize=8)
            else:
                ax.set_title(f"AAE*={row['aae']:.3f}", fontsize=8)
            if col == 0:
                ax.set_ylabel(label)
    fig.colorbar(images[0], ax=axes[0, :].tolist(), shrink=0.9, label="RR$_s$")
    # AAE_s beyond pi/2 (worse than a guess) in the over colour, marked on the bar
    capped_colorbar(fig, images[1], ax=axes[1, :].tolist(), label="AAE$_s$ (rad)", shrink=0.9)
    fig.suptitle(f"Parameter homing on {db}: RR$_s$ and AAE$_s$ per snapshot position (best {len(shown)})", fontsize=9)
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)


def write_parameter_report(root: Path, *, top: int = 8) -> list[str]:
    """Write ranking tables and figures for every database swept below ``root``.

    Writes ``ranking_<db>.csv``, ``ranking_<db>.md`` and ``plots/ranking_<db>.png``
    into ``root``.

    Returns
    -------
    list of str
        One Markdown section per database (empty when ``root`` holds no parameter sweep).
    """

    root = Path(root)
    rows = load_sweep_rows(root)
    if not rows:
        return []
    sections = []
    for db, ranked in best_configurations(rows).items():
        table = ranking_table(rows, db=db)
        header = list(table[0]) if table else list(RANKING_COLUMNS)
        write_csv_atomic(root / f"ranking_{db}.csv", header, ([row.get(c, "") for c in header] for row in table))
        text = ranking_markdown(table, db=db)
        (root / f"ranking_{db}.md").write_text(text + "\n")
        (root / "plots").mkdir(exist_ok=True)
        plot_per_snapshot(root / "plots" / f"ranking_{db}.png", ranked, db=db, top=top)
        sections.append(text)
    return sections


def ranking_sections(root: Path, rows: Sequence[Mapping[str, Any]]) -> list[str]:
    """Report hook: the parameter-homing ranking sections when ``rows`` hold ``param_sweep`` runs.

    Parameters
    ----------
    root : Path
        The sweep (or run tree) directory; ranking files are written into it
        (:func:`write_parameter_report`).
    rows : sequence of mapping
        The summary rows of the runs below ``root`` (``experiment`` per run).
    """
    if not any(r.get("experiment") == "param_sweep" for r in rows):
        return []
    return write_parameter_report(root)
