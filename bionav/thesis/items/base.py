"""Item machinery and the helpers every chapter uses: contexts, the registry, run specs, tables, plots."""

from __future__ import annotations

import csv
import math
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from bionav.thesis.databases import db_meta  # noqa: F401  (its home is thesis/databases.py; the chapters use it from here)
from bionav.thesis.outcome import Check, Outcome, Row, fmt
from bionav.thesis.presets import Preset
from bionav.thesis.runs import RunResult, RunSpec

THESIS_DBS = ("original", "hall1", "moeller1", "roeben1", "uni")
TOL_ANGLE = 0.10  # rad, AAE* and MAE*
TOL_RR = 0.10


# ---------------------------------------------------------------------------
# item machinery
# ---------------------------------------------------------------------------
@dataclass
class Context:
    """What an item's evaluation sees."""

    preset: Preset
    out: Path
    ref: Mapping[str, Any]
    results: Mapping[str, RunResult]
    ref_id: str = ""

    def result(self, spec: RunSpec) -> RunResult:
        return self.results.get(spec.key) or RunResult(spec, None, None, "not run")

    def figure(self, name: str) -> Path:
        return self.out / name


@dataclass(frozen=True)
class Item:
    """One thesis table or figure.

    Attributes
    ----------
    id : str
        File stem and ``--only`` name (``table5_3``, ``fig5_4``).
    label : str
        The thesis' numbering (``Table 5.3``).
    rule : str
        How the verdict is computed, in words (printed in the report).
    runs : callable
        ``runs(preset) -> list[RunSpec]``.
    evaluate : callable
        ``evaluate(ctx, specs) -> Outcome``.
    aliases : tuple of str
        Other ``--only`` names (``5.3``, ``B.1``).
    """

    id: str
    label: str
    rule: str
    runs: Callable[[Preset], list[RunSpec]]
    evaluate: Callable[[Context, list[RunSpec]], Outcome]
    aliases: tuple[str, ...] = ()


REGISTRY: dict[str, Item] = {}


def item(id: str, label: str, rule: str, *, aliases: Sequence[str] = ()):
    """Register ``runs`` and ``evaluate`` functions as one item (decorates a pair)."""

    def deco(cls):
        REGISTRY[id] = Item(id, label, rule, cls.runs, cls.evaluate, tuple(aliases))
        return cls

    return deco


def select_items(only: str | None) -> list[Item]:
    """Items named by ``--only`` (ids, thesis numbers like ``5.3``, ``B.1``, ``6.10-6.15``), in order."""
    from bionav.errors import UserError

    items = list(REGISTRY.values())
    if only is None:
        return items
    words = [w.strip() for w in only.split(",") if w.strip()]
    if not words:
        raise UserError(
            f"--only {only!r} names no item; give comma-separated items such as --only 5.3,B.1 "
            f"(items: {', '.join(it.id for it in items)}), or leave --only out to run every item."
        )
    chosen: list[Item] = []
    for word in words:
        hits = [it for it in items if word == it.id or word in it.aliases]
        if not hits:
            raise UserError(
                f"--only names an unknown item {word!r}. Items: {', '.join(it.id for it in items)} "
                f"(thesis numbers such as 5.3, B.1 or 6.26 work too)."
            )
        chosen += [h for h in hits if h not in chosen]
    return [it for it in items if it in chosen]


# ---------------------------------------------------------------------------
# helpers: run specs
# ---------------------------------------------------------------------------
def snapshot_list(db: str, k: int | None) -> list[int] | None:
    """``k`` snapshot indices spread evenly over a database's images (None: all).

    Databases may miss cells, so the indices stay within 85 % of the grid's cell
    count (a grid missing more than 15 % of its cells would need fewer).
    """
    if k is None:
        return None
    nx, ny = db_meta(db)["grid_shape"]
    n = max(1, int(nx * ny * 0.85))
    return sorted({int(round(v)) for v in np.linspace(0, n - 1, k)})


def size_arg(size: Sequence[int] | None) -> list[str]:
    return [] if size is None else [f"db.image_size=[{int(size[0])},{int(size[1])}]"]


def grid_spec(db: str, *, homing: str = "sift", size=None, preprocess: Sequence[str] = (),
              snapshots: int | None = None, extra: Sequence[str] = (), blocks: Mapping[str, int] | None = None
              ) -> RunSpec:
    """A grid-homing run (``experiment=grid_homing``), split into ``blocks[homing]`` tasks (default 1)."""
    ov = ["experiment=grid_homing", f"db={db}", f"homing={homing}", *size_arg(size), *preprocess]
    snaps = snapshot_list(db, snapshots)
    if snaps is not None:
        ov.append(f"experiment.snapshots=[{','.join(map(str, snaps))}]")
    nx, ny = db_meta(db)["grid_shape"]
    most = len(snaps) if snaps is not None else max(1, int(nx * ny * 0.85))  # never a block without a snapshot
    return RunSpec(tuple([*ov, *extra]), group="grid_homing", blocks=min(int((blocks or {}).get(homing, 1)), most))


def cutoff_preprocess(cutoff: float, *, equalize: bool = True) -> list[str]:
    """Preprocessing of fig. 5.4: Butterworth (order 3) at ``cutoff`` then histogram equalisation.

    Cutoff 1.0 means unfiltered (thesis 5.1.4), i.e. equalisation only.
    """
    if cutoff >= 1.0:
        return ["preprocess=he"] if equalize else []
    steps = f"{{op:butterworth,order:3,cutoff:{cutoff:g}}}" + (",{op:equalize,levels:256}" if equalize else "")
    return ["preprocess=he", f"preprocess.name=bw3_{cutoff:g}{'_he' if equalize else ''}", f"preprocess.steps=[{steps}]"]


def metric(res: RunResult, key: str) -> Any:
    return None if not res.ok else res.metrics.get(key)


def why_missing(res: RunResult) -> str:
    if res.dir is None and res.error:
        return f"`{' '.join(res.spec.overrides)}`: {res.error}"
    return f"`{' '.join(res.spec.overrides)}` did not complete: {res.error or 'no metrics.json'} (run directory {res.dir})"


def spearman(a: Sequence[float], b: Sequence[float]) -> float | None:
    """Spearman's rank correlation of two equally long sequences (None if undefined)."""
    from scipy.stats import spearmanr

    pairs = [(x, y) for x, y in zip(a, b) if x is not None and y is not None
             and math.isfinite(float(x)) and math.isfinite(float(y))]
    if len(pairs) < 2:
        return None
    x, y = zip(*pairs)
    if len(set(x)) < 2 or len(set(y)) < 2:
        return None
    rho = spearmanr(x, y).statistic
    return None if not math.isfinite(rho) else float(rho)


#: fewest values an ordering check compares: over two values Spearman's rho is +-1 by construction (a sign,
#: not an ordering), so a two-point "ordering" would pass or fail on one comparison
MIN_ORDERING_VALUES = 3


def rho_check(what: str, thesis: Sequence, bionav: Sequence, *, threshold: float = 0.8) -> Check:
    """The thesis' ordering claim over all values; not evaluable (None) when a bionav value is missing.

    An ordering of five databases is not checked on the three whose runs
    completed: a missing run makes the claim unevaluated, never failed. Fewer
    than :data:`MIN_ORDERING_VALUES` values are not evaluated either (rho is
    +-1 by construction). The threshold 0.8 is bionav's choice (the thesis
    states no tolerance for its orderings): over five values it allows two
    swaps of neighbours, over four one, over three none.
    """
    rule = f"ordering of {what} equal to the thesis' (Spearman rho >= {threshold})"
    missing = sum(b is None for b in bionav)
    if missing:
        return Check(rule, None, f"not evaluable: {missing} of {len(bionav)} values missing (runs not completed)")
    if len(bionav) < MIN_ORDERING_VALUES:
        return Check(rule, None, f"not evaluable: {len(bionav)} values (rho over two values is +-1 by construction; "
                                 f"an ordering needs at least {MIN_ORDERING_VALUES})")
    rho = spearman(thesis, bionav)
    # rho is a ratio of integers computed in floating point: one swap over four values gives 0.7999999999999999
    return Check(rule, None if rho is None else rho >= threshold - 1e-9,
                 "not evaluable (fewer than two values or ties)" if rho is None else f"rho = {rho:.2f}")


def copy_plot(ctx: Context, res: RunResult, rel: str, name: str, out: Outcome) -> None:
    """Copy a run's plot to ``OUT/<name>`` (named by item)."""
    if res.dir is None or not (res.dir / rel).is_file():
        out.missing.append(f"figure {name}: the run wrote no {rel}" + ("" if res.ok else f" ({why_missing(res)})"))
        return
    shutil.copyfile(res.dir / rel, ctx.figure(name))
    out.figures.append(name)


def read_csv(path: Path) -> list[dict[str, str]]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def markdown(header: Sequence[str], rows: Sequence[Sequence[Any]]) -> str:
    """A Markdown table; text cells keep their asterisks (``AAE*``, ``***``) and pipes escaped."""
    from bionav.thesis.report import md_text

    def cell(v: Any) -> str:
        return md_text(fmt(v) if not isinstance(v, str) else v).replace("|", "\\|")

    lines = ["| " + " | ".join(map(str, header)) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(cell(v) for v in r) + " |" for r in rows]
    return "\n".join(lines) + "\n"


def write_table(ctx: Context, out: Outcome, name: str, title: str, rows: Sequence[Row]) -> None:
    """A markdown table of ``rows``; a ``note`` column is added when any row has a note (e.g. per-draw values)."""
    head = ["quantity", "thesis", "bionav", "difference", "tolerance", "verdict"]
    body_rows = [[r.quantity, fmt(r.thesis), fmt(r.bionav), fmt(r.difference), fmt(r.tolerance), r.verdict]
                 for r in rows]
    if any(r.note for r in rows):
        head.append("note")
        body_rows = [b + [r.note] for b, r in zip(body_rows, rows)]
    body = markdown(head, body_rows)
    (ctx.out / name).write_text(f"# {title}\n\n{body}")
    out.tables.append(name)


def compare_bars(path: Path, labels: Sequence[str], series: Mapping[str, Sequence[Any]], *, title: str,
                 ylabel: str) -> None:
    """Grouped bars (thesis vs bionav values) per label; ``ylabel`` names the quantity and its unit."""
    from bionav.report.figures import pyplot, save_figure

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(max(5.0, 0.7 * len(labels) * len(series)), 3.6))
    width = 0.8 / max(1, len(series))
    for k, (name, values) in enumerate(series.items()):
        vals = [np.nan if v is None else float(v) for v in values]
        ax.bar(np.arange(len(labels)) + (k - (len(series) - 1) / 2) * width, vals, width, label=name)
    ax.set_xticks(range(len(labels)), labels, rotation=30, ha="right", fontsize=8)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))  # beside the bars, covering none
    save_figure(fig, path, dpi=100)
