"""The registry of thesis items: the runs each needs, its quantities, figures and verdict rule.

Every item declares (per preset) the ``python -m bionav`` runs it needs, and
turns the files those runs write (``metrics.json``, ``per_snapshot.csv``,
``cross_db.csv``, ``ranking_<db>.csv``, ``significance_<criterion>.csv``,
``stability.csv``, plots) into rows (thesis value, bionav value, difference,
tolerance), claim checks stated in words, and figures named after the item.
Nothing here imports an experiment: items depend only on the command line and
the files runs write.
"""

from __future__ import annotations

import csv
import math
import shutil
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence

import numpy as np

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
@lru_cache(maxsize=None)
def db_meta(db: str) -> dict:
    """Grid shape, spacing and the other settings of a database preset (composed through Hydra)."""
    from omegaconf import OmegaConf

    from bionav.config import compose

    cfg = compose([f"db={db}"])
    node = OmegaConf.to_container(cfg.db, resolve=False)
    return {k: node.get(k) for k in ("name", "grid_shape", "spacing_m", "horizon_row", "image_size", "source")}


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


def rho_check(what: str, thesis: Sequence, bionav: Sequence, *, threshold: float = 0.8) -> Check:
    """The thesis' ordering claim over all values; not evaluable (None) when a bionav value is missing.

    An ordering of five databases is not checked on the three whose runs
    completed: a missing run makes the claim unevaluated, never failed.
    """
    rule = f"ordering of {what} equal to the thesis' (Spearman rho >= {threshold})"
    missing = sum(b is None for b in bionav)
    if missing:
        return Check(rule, None, f"not evaluable: {missing} of {len(bionav)} values missing (runs not completed)")
    rho = spearman(thesis, bionav)
    return Check(rule, None if rho is None else rho >= threshold,
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


# ---------------------------------------------------------------------------
# chapter 3
# ---------------------------------------------------------------------------
STANDIN = {"screen": "sim_screen"}


@item("table3_1", "Table 3.1",
      "per database: grid size and spacing equal to the thesis' (checks), #images equal where a grid-homing run "
      "of the database is in this report (n_images of its metrics); area and mirror are shown, not checked",
      aliases=("3.1",))
class _Table31:
    @staticmethod
    def runs(preset: Preset) -> list[RunSpec]:
        return []

    @staticmethod
    def evaluate(ctx: Context, specs: list[RunSpec]) -> Outcome:
        out = Outcome()
        n_images: dict[str, int] = {}
        for res in ctx.results.values():
            if res.ok and res.metrics.get("experiment") == "grid_homing" and "n_images" in res.metrics:
                n_images.setdefault(str(res.metrics.get("db")), int(res.metrics["n_images"]))
        table = []
        for name, (nx, ny, ax, ay, spacing, n, mirror) in ctx.ref["databases"].items():
            sim = STANDIN.get(name, f"sim_{name}")
            try:
                meta = db_meta(sim)
            except Exception as exc:  # a stand-in that does not exist
                out.missing.append(f"{name}: no stand-in {sim} ({exc})")
                continue
            gx, gy = meta["grid_shape"]
            sp = float(meta["spacing_m"])
            out.rows.append(Row(f"{name}: grid nx", nx, int(gx), 0))
            out.rows.append(Row(f"{name}: grid ny", ny, int(gy), 0))
            out.rows.append(Row(f"{name}: spacing (m)", spacing, sp, 1e-9))
            got = n_images.get(sim)
            out.rows.append(Row(f"{name}: #images", n, got, 0 if got is not None else None,
                                "" if got is not None else "no grid-homing run of this stand-in in this report"))
            table.append([f"{name} ({sim})", f"{nx}x{ny}", f"{gx}x{gy}", f"{ax}m x {ay}m",
                          f"{(gx - 1) * sp:.1f}m x {(gy - 1) * sp:.1f}m", spacing, sp, n,
                          "n/a" if got is None else got, mirror,
                          "normal-view (horizon above the middle row)" if meta.get("horizon_row") is not None
                          else "ultra-wide (horizon in the middle row)"])
        text = markdown(["database", "grid (thesis)", "grid (bionav)", "area (thesis)", "area (bionav)",
                         "spacing (thesis)", "spacing (bionav)", "#images (thesis)", "#images (bionav)",
                         "mirror (thesis)", "stand-in camera"], table)
        (ctx.out / "table3_1.md").write_text("# Table 3.1: characteristics of the image databases\n\n" + text)
        out.tables.append("table3_1.md")
        out.notes += list(ctx.ref.get("notes", []))
        return out


# ---------------------------------------------------------------------------
# chapter 5: SIFT homing and warping
# ---------------------------------------------------------------------------
def _grid_table(ctx: Context, out: Outcome, specs: list[RunSpec], dbs: Sequence[str], ref: Mapping,
                label: str, *, draws: Sequence[int] = ()) -> dict[str, list]:
    """Rows of one grid-homing table; with ``draws``, ``specs`` holds one run per database and draw.

    With several pose-error draws (``db.pose_error.seed``) a database's value
    is the mean over its draws (None if any draw is missing); the row's note
    lists every draw and the spread (sample standard deviation) across them.
    """
    n = max(1, len(draws))
    values = {"aae": [], "mae": [], "rr": []}
    for d, db in enumerate(dbs):
        results = _results(ctx, out, specs[d * n:(d + 1) * n], f"{label} on {db}")
        for key, tol in (("aae", TOL_ANGLE), ("mae", TOL_ANGLE), ("rr", TOL_RR)):
            thesis = ref[key][list(ref["databases"]).index(db)]
            got, note = _mean_over_draws(results, key, draws)
            values[key].append(got)
            out.rows.append(Row(f"{label} {key.upper()}* {db}", thesis, got, tol, note))
    return values


def _results(ctx: Context, out: Outcome, specs: Sequence[RunSpec], what: str) -> list[RunResult]:
    """The results of ``specs``; each run that did not complete is listed in ``out.missing`` as ``what``."""
    results = [ctx.result(spec) for spec in specs]
    for res in results:
        if not res.ok:
            out.missing.append(f"{what}: {why_missing(res)}")
    return results


def _mean_over_draws(results: Sequence[RunResult], key: str, draws: Sequence[int]) -> tuple[Any, str]:
    """A metric over the runs of one configuration, one run per pose-error draw, and its note.

    One run: its value and no note. Several: the mean (None if any draw is
    missing) and a note listing every draw and the spread (sample standard
    deviation) across them.
    """
    got_all = [metric(res, key) for res in results]
    if len(results) == 1:
        return got_all[0], ""
    got = None if any(g is None for g in got_all) else float(np.mean(got_all))
    note = (f"mean of {len(results)} pose-error draws (db.pose_error.seed="
            + ", ".join(f"{s}: {fmt(g, 3)}" for s, g in zip(draws, got_all))
            + ("" if got is None else f"; spread (std) {float(np.std(got_all, ddof=1)):.3f}") + ")")
    return got, note


def _draw_args(preset: Preset) -> list[list[str]]:
    """Overrides of each pose-error draw of the preset's SIFT table (one empty entry: the config's draw)."""
    return [[f"db.pose_error.seed={int(s)}"] for s in preset.pose_draws] or [[]]


@item("table5_3", "Table 5.3",
      f"per database and measure: |bionav - thesis| <= {TOL_ANGLE} rad (AAE*, MAE*) or {TOL_RR} (RR*); "
      "ordering of RR* and of AAE* across the five databases equal (Spearman rho >= 0.8)", aliases=("5.3",))
class _Table53:
    @staticmethod
    def runs(preset: Preset) -> list[RunSpec]:
        return [grid_spec(f"sim_{db}", size=preset.sift_size, snapshots=preset.snapshots, extra=extra,
                          blocks=preset.grid_blocks)
                for db in THESIS_DBS for extra in _draw_args(preset)]

    @staticmethod
    def evaluate(ctx: Context, specs: list[RunSpec]) -> Outcome:
        out = Outcome()
        ref = ctx.ref
        v = _grid_table(ctx, out, specs, THESIS_DBS, ref, "SIFT", draws=ctx.preset.pose_draws)
        out.checks.append(rho_check("RR* across databases", ref["rr"], v["rr"]))
        out.checks.append(rho_check("AAE* across databases", ref["aae"], v["aae"]))
        write_table(ctx, out, "table5_3.md", ref["title"], out.rows)
        compare_bars(ctx.figure("table5_3.png"), [f"{m} {d}" for m in ("AAE*", "RR*") for d in THESIS_DBS],
                     {"thesis": [*ref["aae"], *ref["rr"]], "bionav": [*v["aae"], *v["rr"]]}, title=ref["title"],
                     ylabel="AAE* (rad) | RR* (fraction of agents home)")
        out.figures.append("table5_3.png")
        return out


@item("table5_4", "Table 5.4",
      f"per method, database and measure: |bionav - thesis| <= {TOL_ANGLE} rad (AAE*, MAE*) or {TOL_RR} (RR*); "
      "per method: ordering of RR* across databases equal (Spearman rho >= 0.8); the thesis' comparison with "
      "SIFT homing (table 5.3 runs): SIFT's RR* higher on original, warping's RR* at least SIFT's on the other four",
      aliases=("5.4",))
class _Table54:
    @staticmethod
    def runs(preset: Preset) -> list[RunSpec]:
        specs = [grid_spec(f"sim_{db}", homing=h, size=preset.warping_size, snapshots=preset.warping_snapshots,
                           blocks=preset.grid_blocks)
                 for h in preset.warping for db in THESIS_DBS]
        return specs + _Table53.runs(preset)

    @staticmethod
    def evaluate(ctx: Context, specs: list[RunSpec]) -> Outcome:
        out = Outcome()
        ref = ctx.ref
        n = len(THESIS_DBS)
        methods = ctx.preset.warping
        sift = _grid_table(ctx, Outcome(), specs[len(methods) * n:], THESIS_DBS, ref, "SIFT",
                           draws=ctx.preset.pose_draws)["rr"]
        series = {"thesis RR*": ref["rr"]}
        for k, h in enumerate(methods):
            v = _grid_table(ctx, out, specs[k * n:(k + 1) * n], THESIS_DBS, ref, h)
            out.checks.append(rho_check(f"RR* across databases ({h})", ref["rr"], v["rr"]))
            series[f"{h} RR*"] = v["rr"]
            if sift[0] is not None and v["rr"][0] is not None:
                out.checks.append(Check(f"{h}: SIFT homing's RR* on original higher than the warping method's",
                                        sift[0] > v["rr"][0], f"SIFT {sift[0]:.3f}, {h} {v['rr'][0]:.3f}"))
            pairs = [(s, w) for s, w in zip(sift[1:], v["rr"][1:]) if s is not None and w is not None]
            if pairs:
                out.checks.append(Check(f"{h}: RR* at least SIFT homing's on hall1, moeller1, roeben1, uni",
                                        all(w >= s for s, w in pairs),
                                        ", ".join(f"{d}: {w:.3f} vs {s:.3f}" for d, (s, w) in zip(THESIS_DBS[1:], pairs))))
        series["SIFT RR* (table 5.3 runs)"] = sift
        write_table(ctx, out, "table5_4.md", ref["title"], out.rows)
        compare_bars(ctx.figure("table5_4.png"), list(THESIS_DBS), series, title=ref["title"], ylabel="RR*")
        out.figures.append("table5_4.png")
        out.notes += list(ref.get("notes", []))
        return out


def _fig54_runs(preset: Preset) -> list[RunSpec]:
    return [grid_spec("sim_original", size=s, preprocess=cutoff_preprocess(c), snapshots=preset.snapshots,
                      blocks=preset.grid_blocks)
            for s in preset.fig54_sizes for c in preset.fig54_cutoffs]


@item("fig5_4", "Fig. 5.4",
      "four claims of 5.1.5, each one check: (1) the lowest AAE* is at a cutoff below 1.0 for the smallest size "
      "and at 1.0 (within 0.01 rad) for the larger sizes; (2) for cutoffs below 0.1 RR* < 0.98 at every size; "
      "(3) at the smallest size RR* <= 0.98 at every cutoff; (4) unfiltered (1.0) RR* >= 0.995 for sizes >= 561 x 81",
      aliases=("5.4",))
class _Fig54:
    runs = staticmethod(_fig54_runs)

    @staticmethod
    def evaluate(ctx: Context, specs: list[RunSpec]) -> Outcome:
        from bionav.report.figures import pyplot, save_figure

        out = Outcome()
        p = ctx.preset
        sizes, cuts = p.fig54_sizes, p.fig54_cutoffs
        vals = {k: np.full((len(sizes), len(cuts)), np.nan) for k in ("aae", "mae", "rr")}
        for i, s in enumerate(sizes):
            for j, c in enumerate(cuts):
                res = ctx.result(specs[i * len(cuts) + j])
                if not res.ok:
                    out.missing.append(f"{s[0]}x{s[1]}, cutoff {c}: {why_missing(res)}")
                    continue
                for k in vals:
                    vals[k][i, j] = float(res.metrics[k])
                out.rows.append(Row(f"AAE* {s[0]}x{s[1]} cutoff {c:g}", None, vals["aae"][i, j]))
                out.rows.append(Row(f"RR* {s[0]}x{s[1]} cutoff {c:g}", None, vals["rr"][i, j]))
        plt = pyplot()
        fig, axes = plt.subplots(1, 3, figsize=(13, 3.6))
        for ax, (k, lab) in zip(axes, (("aae", "AAE* (rad)"), ("mae", "MAE* (rad)"), ("rr", "RR*"))):
            for i, s in enumerate(sizes):
                ax.plot(cuts, vals[k][i], "o-", label=f"{s[0]} x {s[1]}")
            ax.set_xscale("log")
            ax.set_xlabel("Butterworth cutoff (1.0 = unfiltered)")
            ax.set_ylabel(lab)
            ax.legend(fontsize=7)
        fig.suptitle("SIFT homing on sim_original with histogram equalisation (thesis fig. 5.4)", fontsize=9)
        save_figure(fig, ctx.figure("fig5_4.png"), dpi=100)
        out.figures.append("fig5_4.png")
        cuts_a = np.asarray(cuts)
        unf = np.flatnonzero(cuts_a >= 1.0)
        filt = np.flatnonzero(cuts_a < 1.0)
        aae, rr = vals["aae"], vals["rr"]
        if len(unf) and len(filt) and np.isfinite(aae).all():
            small = int(np.argmin([w * h for w, h in sizes]))
            ok_small = aae[small, filt].min() < aae[small, unf[0]]
            ok_large = all(aae[i, unf[0]] <= aae[i, filt].min() + 0.01 for i in range(len(sizes)) if i != small)
            out.checks.append(Check("filtering lowers AAE* only at the smallest size", bool(ok_small and ok_large),
                                    "; ".join(f"{s[0]}x{s[1]}: best cutoff {cuts[int(np.argmin(aae[i]))]:g}"
                                              for i, s in enumerate(sizes))))
        else:
            out.checks.append(Check("filtering lowers AAE* only at the smallest size", None,
                                    "needs cutoff 1.0, a filtered cutoff and every run"))
        low = np.flatnonzero(cuts_a < 0.1)
        out.checks.append(Check("RR* < 0.98 for every cutoff below 0.1 at every size",
                                None if not len(low) or np.isnan(rr[:, low]).any() else bool((rr[:, low] < 0.98).all()),
                                "no cutoff below 0.1 in this preset" if not len(low) else
                                f"max RR* below 0.1: {np.nanmax(rr[:, low]):.3f}"))
        small = int(np.argmin([w * h for w, h in sizes]))
        out.checks.append(Check(f"RR* <= 0.98 at {sizes[small][0]}x{sizes[small][1]} for every cutoff",
                                None if np.isnan(rr[small]).all() else bool(np.nanmax(rr[small]) <= 0.98),
                                f"max {np.nanmax(rr[small]):.3f}" if not np.isnan(rr[small]).all() else ""))
        big = [i for i, s in enumerate(sizes) if s[0] * s[1] >= 561 * 81]
        if big and len(unf) and not np.isnan(rr[big, unf[0]]).any():
            out.checks.append(Check("unfiltered RR* >= 0.995 for sizes >= 561 x 81",
                                    bool((rr[big, unf[0]] >= 0.995).all()),
                                    ", ".join(f"{sizes[i][0]}x{sizes[i][1]}: {rr[i, unf[0]]:.3f}" for i in big)))
        else:
            out.checks.append(Check("unfiltered RR* >= 0.995 for sizes >= 561 x 81", None, "no such run"))
        out.notes.append("Butterworth order 3 (the thesis gives the order only for min-warping), applied before the "
                         "histogram equalisation; the stand-in is rendered at each size directly.")
        return out


def _per_snapshot(res: RunResult):
    rows = read_csv(res.dir / "per_snapshot.csv")
    return [(int(r["x"]), int(r["y"]), float(r["aae_s"]), float(r["rr_s"])) for r in rows]


@item("fig5_5", "Fig. 5.5",
      "claims of 5.1.5, each one check per preprocessing (none, he): AAE* falls and RR* does not fall as the "
      "image grows; the best AAE* at the largest size; histogram equalisation raises AAE* at every size",
      aliases=("5.5",))
class _Fig55:
    @staticmethod
    def runs(preset: Preset) -> list[RunSpec]:
        return [grid_spec("sim_original", size=s, preprocess=cutoff_preprocess(1.0, equalize=eq),
                          snapshots=preset.snapshots, blocks=preset.grid_blocks)
                for eq in (False, True) for s in preset.fig55_sizes]

    @staticmethod
    def evaluate(ctx: Context, specs: list[RunSpec]) -> Outcome:
        from bionav.report.figures import grid_cell_axes, pyplot, save_figure

        out = Outcome()
        sizes = ctx.preset.fig55_sizes
        plt = pyplot()
        fig, axes = plt.subplots(4, len(sizes), figsize=(3.2 * len(sizes), 10), squeeze=False)
        aae = np.full((2, len(sizes)), np.nan)
        rr = np.full((2, len(sizes)), np.nan)
        for e, eq in enumerate(("none", "he")):
            for i, s in enumerate(sizes):
                res = ctx.result(specs[e * len(sizes) + i])
                if not res.ok:
                    out.missing.append(f"{s[0]}x{s[1]} {eq}: {why_missing(res)}")
                    for r in range(2):
                        axes[2 * e + r, i].text(0.5, 0.5, f"{s[0]}x{s[1]}, {eq}:\nno completed run", ha="center",
                                                va="center", transform=axes[2 * e + r, i].transAxes)
                        axes[2 * e + r, i].set_axis_off()
                    continue
                aae[e, i], rr[e, i] = res.metrics["aae"], res.metrics["rr"]
                out.rows.append(Row(f"AAE* {s[0]}x{s[1]} {eq}", None, aae[e, i]))
                out.rows.append(Row(f"RR* {s[0]}x{s[1]} {eq}", None, rr[e, i]))
                snaps = _per_snapshot(res)
                nx, ny = db_meta("sim_original")["grid_shape"]
                for r, (col, lab) in enumerate(((2, "AAE_s"), (3, "RR_s"))):
                    grid = np.full((ny, nx), np.nan)
                    for sn in snaps:
                        grid[sn[1], sn[0]] = sn[col]
                    ax = axes[2 * e + r, i]
                    im = ax.imshow(grid, origin="lower", cmap="viridis", vmin=0, vmax=1 if col == 3 else None)
                    ax.set_title(f"{lab}, {s[0]}x{s[1]}, {eq}", fontsize=8)
                    grid_cell_axes(ax, fontsize=7)
                    fig.colorbar(im, ax=ax, shrink=0.7, label="AAE_s (rad)" if col == 2 else "RR_s")
        fig.suptitle("SIFT homing on sim_original: per-snapshot AAE_s and RR_s (thesis fig. 5.5)", fontsize=9)
        save_figure(fig, ctx.figure("fig5_5.png"), dpi=90)
        out.figures.append("fig5_5.png")
        order = np.argsort([w * h for w, h in sizes])
        for e, eq in enumerate(("none", "he")):
            a, r = aae[e, order], rr[e, order]
            ok = not np.isnan(a).any() and len(sizes) > 1
            out.checks.append(Check(f"{eq}: AAE* falls as the image grows", bool(np.all(np.diff(a) < 0)) if ok else None,
                                    ", ".join(f"{x:.3f}" for x in a)))
            out.checks.append(Check(f"{eq}: RR* does not fall as the image grows",
                                    bool(np.all(np.diff(r) >= 0)) if ok else None, ", ".join(f"{x:.3f}" for x in r)))
        ok = not np.isnan(aae).any()
        out.checks.append(Check("best AAE* at the largest size (with and without equalisation)",
                                bool(all(np.argmin(aae[e]) == order[-1] for e in range(2))) if ok else None))
        out.checks.append(Check("histogram equalisation raises AAE* at every size",
                                bool((aae[1] > aae[0]).all()) if ok else None,
                                ", ".join(f"{s[0]}x{s[1]}: {aae[0, i]:.3f} -> {aae[1, i]:.3f}" for i, s in enumerate(sizes))))
        return out


def _cross_spec(preset: Preset, homing: str) -> RunSpec:
    ov = ["experiment=cross_db", f"homing={homing}", f"experiment.family=[{','.join(preset.cross_db_family)}]",
          f"experiment.snapshot_stride={preset.cross_db_stride}", *size_arg(preset.cross_db_size)]
    nx, ny = db_meta(preset.cross_db_family[0])["grid_shape"]
    stride = preset.cross_db_stride
    cells = max(1, int(-(-nx // stride) * -(-ny // stride) * 0.85))  # snapshots, never a block without one
    return RunSpec(tuple(ov), group="cross_db", blocks=min(int(preset.cross_db_blocks.get(homing, 1)), cells))


def _cross_matrix(res: RunResult, measure: str) -> tuple[list[str], np.ndarray]:
    rows = [r for r in read_csv(res.dir / "cross_db.csv") if r["measure"] == measure]
    names = [k for k in rows[0] if k not in ("measure", "snapshot_db")]
    return names, np.array([[float(r[n]) for n in names] for r in rows])


def _column_means(m: np.ndarray) -> np.ndarray:
    off = ~np.eye(len(m), dtype=bool)
    return np.array([m[:, j][off[:, j]].mean() for j in range(len(m))])


@item("fig5_6", "Fig. 5.6",
      "the claims of 5.1.5 on RR* averaged over the snapshot databases (off-diagonal) per current-view database, "
      "each one check: 2D-warping's RR* with winlit and doorlit current views below the mean of the other "
      "databases; SIFT's not below that mean minus 0.05; for both methods screen's RR* below arboreal's and chairs'",
      aliases=("5.6",))
class _Fig56:
    @staticmethod
    def runs(preset: Preset) -> list[RunSpec]:
        return [_cross_spec(preset, h) for h in preset.cross_db_homing]

    @staticmethod
    def evaluate(ctx: Context, specs: list[RunSpec]) -> Outcome:
        out = Outcome()
        for spec, homing in zip(specs, ctx.preset.cross_db_homing):
            res = ctx.result(spec)
            if not res.ok:
                out.missing.append(f"{homing}: {why_missing(res)}")
                continue
            names, rr = _cross_matrix(res, "rr")
            cols = _column_means(rr)
            short = [n.removeprefix("sim_") for n in names]
            for n, v in zip(short, cols):
                out.rows.append(Row(f"{homing}: mean RR* with current views from {n}", None, v))
            copy_plot(ctx, res, "plots/cross_db.png", f"fig5_6_{homing}.png", out)
            ix = {n: k for k, n in enumerate(short)}
            lit = [ix[n] for n in ("winlit", "doorlit") if n in ix]
            other = [k for k in range(len(short)) if k not in lit]
            if lit and other:
                lit_m, other_m = cols[lit].mean(), cols[other].mean()
                if homing.startswith("warping2d"):
                    out.checks.append(Check(f"{homing}: RR* with winlit/doorlit current views below the others' mean",
                                            bool(lit_m < other_m), f"{lit_m:.3f} vs {other_m:.3f}"))
                elif homing == "sift":
                    out.checks.append(Check("sift: RR* with winlit/doorlit current views not below the others' mean - 0.05",
                                            bool(lit_m >= other_m - 0.05), f"{lit_m:.3f} vs {other_m:.3f}"))
            if all(n in ix for n in ("screen", "arboreal", "chairs")):
                s, a, c = cols[ix["screen"]], cols[ix["arboreal"]], cols[ix["chairs"]]
                out.checks.append(Check(f"{homing}: screen's RR* below arboreal's and chairs'", bool(s < min(a, c)),
                                        f"screen {s:.3f}, arboreal {a:.3f}, chairs {c:.3f}"))
            with open(ctx.out / f"fig5_6_{homing}.md", "w") as f:
                f.write(f"# Fig. 5.6, {homing}: RR* (rows: snapshot database, columns: current-view database)\n\n")
                f.write(markdown(["snapshot \\ current", *short], [[n, *row] for n, row in zip(short, rr)]))
            out.tables.append(f"fig5_6_{homing}.md")
        return out


# ---------------------------------------------------------------------------
# parameter homing (tables 5.5-5.7, figs. 5.9-5.11)
# ---------------------------------------------------------------------------
def _param_spec(preset: Preset, db: str) -> RunSpec:
    return RunSpec(("experiment=param_sweep", f"db=sim_{db}", f"experiment.grid={preset.param_grid}"),
                   multirun=True, group="param_sweep")


def _ranking_csv(res: RunResult) -> Path | None:
    if res.dir is None:
        return None
    found = sorted(res.dir.glob("ranking_*.csv"))
    if not found:  # rebuild through the documented command
        import subprocess
        import sys

        subprocess.run([sys.executable, "-m", "bionav.report", str(res.dir)], capture_output=True)
        found = sorted(res.dir.glob("ranking_*.csv"))
    return found[0] if found else None


def _param_item(table: str, fig: str, db: str):
    class _P:
        @staticmethod
        def runs(preset: Preset) -> list[RunSpec]:
            return [_param_spec(preset, db)]

        @staticmethod
        def evaluate(ctx: Context, specs: list[RunSpec]) -> Outcome:
            out = Outcome()
            res = ctx.result(specs[0])
            path = _ranking_csv(res) if res.dir is not None else None
            if path is None:
                out.missing.append(f"no ranking table: {why_missing(res)}")
                return out
            got = {r["parameter"].strip("[]"): r for r in read_csv(path)}
            ref = ctx.ref["ranking"]
            t_rank, b_rank = [], []
            for rank, sig, rr, aae, *_ in ref:
                g = got.get(sig)
                b_rr = None if g is None or g.get("rr") in (None, "") else float(g["rr"])
                out.rows.append(Row(f"[{sig}] RR*", rr, b_rr, TOL_RR))
                out.rows.append(Row(f"[{sig}] rank", rank, None if g is None else int(g["rank"])))
                out.rows.append(Row(f"[{sig}] AAE*", aae, None if g is None or g.get("aae") in (None, "") else float(g["aae"])))
                if g is not None:
                    t_rank.append(rank)
                    b_rank.append(int(g["rank"]))
            out.checks.append(rho_check("the 19 signatures by RR*", t_rank, b_rank))
            best = min(got.values(), key=lambda r: int(r["rank"]))["parameter"].strip("[]") if got else None
            out.checks.append(Check(f"best signature is [{ref[0][1]}] as in the thesis",
                                    None if best is None else best == ref[0][1], f"bionav's best: [{best}]"))
            if db == "original":
                low = [g for g in got.values() if int(g["rank"]) > 8]
                inv = [str(g.get("rot_invariant", "")).lower() in ("j", "y", "yes", "true", "1") for g in low]
                out.checks.append(Check("all signatures ranked below eight are rotation invariant",
                                        all(inv) if low else None,
                                        ", ".join(f"[{g['parameter'].strip('[]')}]" for g, i in zip(low, inv) if not i)
                                        or "all invariant"))
            else:
                top2 = [g["parameter"].strip("[]") for g in sorted(got.values(), key=lambda r: int(r["rank"]))[:2]]
                out.checks.append(Check("[mffc_phase] then [mffc_abs] at ranks 1 and 2",
                                        top2 == ["mffc_phase", "mffc_abs"], f"bionav: {top2}"))
            md = path.with_suffix(".md")
            if md.is_file():
                shutil.copyfile(md, ctx.out / f"{table}.md")
                out.tables.append(f"{table}.md")
            copy_plot(ctx, res, f"plots/{path.stem}.png", f"{fig}.png", out)
            fig_name = fig.replace('fig', 'fig. ').replace('_', '.')
            out.notes.append(f"sweep grid experiment.grid={ctx.preset.param_grid}; figure {fig_name}: "
                             "per-snapshot RR and AAE of the eight best signatures.")
            return out

    return _P


for _table, _fig, _db in (("table5_5", "fig5_9", "original"), ("table5_6", "fig5_10", "hall1"),
                          ("table5_7", "fig5_11", "uni")):
    item(_table, f"Table {_table[5]}.{_table[7]} / Fig. {_fig[3]}.{_fig[5:]}",
         f"per signature: |RR* bionav - thesis| <= {TOL_RR}; ordering of the 19 signatures equal (Spearman rho of the "
         "ranks >= 0.8); the same best signature; the thesis' claim about the top ranks (one check)",
         aliases=(f"{_table[5]}.{_table[7]}", f"{_fig[3]}.{_fig[5:]}", _fig))(_param_item(_table, _fig, _db))


# ---------------------------------------------------------------------------
# appendix B
# ---------------------------------------------------------------------------
def _b_runs(table: str):
    def runs(preset: Preset) -> list[RunSpec]:
        from bionav.thesis.reference import load_reference

        ref = load_reference()[table]
        extra = [] if ref["combine"] == "average" else ["homing.combine=max"]
        return [grid_spec(f"sim_{db}", size=s, snapshots=preset.snapshots, extra=extra,
                          blocks=preset.grid_blocks)
                for db in ref["dbs"] for s in preset.b_sizes]

    return runs


def _b_evaluate(ctx: Context, specs: list[RunSpec]) -> Outcome:
    out = Outcome()
    ref = ctx.ref
    sizes = [tuple(s) for s in ref["image_sizes"]]
    k = 0
    series_t, series_b, labels = [], [], []
    for db, vals in ref["dbs"].items():
        aae_t, aae_b, keys_b = [], [], []
        for s in ctx.preset.b_sizes:
            res = ctx.result(specs[k])
            k += 1
            if not res.ok:
                out.missing.append(f"{db} {s[0]}x{s[1]}: {why_missing(res)}")
            t = sizes.index(tuple(s)) if tuple(s) in sizes else None

            def th(key, t=t, vals=vals):
                return None if t is None else vals[key][t]

            keys = metric(res, "keypoints_per_image")
            out.rows.append(Row(f"{db} {s[0]}x{s[1]} keys", th("keys"), keys, None,
                                "" if keys is not None else "bionav's metrics report no keypoint count"))
            out.rows.append(Row(f"{db} {s[0]}x{s[1]} AAE*", th("aae"), metric(res, "aae"), TOL_ANGLE if t is not None else None))
            out.rows.append(Row(f"{db} {s[0]}x{s[1]} RR*", th("rr"), metric(res, "rr"), TOL_RR if t is not None else None))
            aae_t.append(th("aae"))
            aae_b.append(metric(res, "aae"))
            keys_b.append(keys)
            labels.append(f"{db} {s[0]}x{s[1]}")
            series_t.append(th("aae"))
            series_b.append(metric(res, "aae"))
        out.checks.append(rho_check(f"AAE* across image sizes on {db}", aae_t, aae_b))
        area = [w * h for w, h in ctx.preset.b_sizes]
        if all(x is not None for x in keys_b) and len(keys_b) > 1:
            out.checks.append(Check(f"{db}: the number of keys grows with the image size",
                                    bool(spearman(area, keys_b) == 1.0), ", ".join(f"{x:.0f}" for x in keys_b)))
    compare_bars(ctx.figure(f"{ctx.ref_id}.png"), labels, {"thesis AAE*": series_t, "bionav AAE*": series_b},
                 title=ref["title"], ylabel="AAE* (rad)")
    out.figures.append(f"{ctx.ref_id}.png")
    write_table(ctx, out, f"{ctx.ref_id}.md", ref["title"], out.rows)
    return out


for _t in ("tableB_1", "tableB_2", "tableB_3", "tableB_4"):
    _cls = type(_t, (), {"runs": staticmethod(_b_runs(_t)), "evaluate": staticmethod(_b_evaluate)})
    item(_t, f"Table B.{_t[-1]}",
         f"per database and image size: |bionav - thesis| <= {TOL_ANGLE} rad (AAE*) or {TOL_RR} (RR*) where the "
         "thesis has the size; per database: ordering of AAE* across image sizes equal (Spearman rho >= 0.8) and, "
         "where bionav reports keypoint counts, keys growing with the image size",
         aliases=(f"B.{_t[-1]}",))(_cls)


# ---------------------------------------------------------------------------
# chapter 4: polarized-light compass
# ---------------------------------------------------------------------------
def _pol(mode: str, *extra: str) -> RunSpec:
    return RunSpec(("experiment=pol_compass", f"mode={mode}", *extra), group="pol_compass")


def _pol_filter(p: Preset) -> RunSpec:
    return _pol("filter_test", f"experiment.samples_per_step={p.pol_samples}")


def _pol_vs_em(p: Preset) -> RunSpec:
    return _pol("vs_em_compass", f"experiment.vs_em.samples={p.pol_vs_em_samples}")


def _pol_rotation(p: Preset) -> RunSpec:
    return _pol("rotation", f"experiment.samples_per_step={p.pol_samples}")


@item("fig4_2", "Fig. 4.2",
      "one check (indirect, bionav keeps the unit voltages only in run.mcap and the plot): the compass' "
      "axial output follows the filter angle (heading MAE <= 5 deg), which needs the three units' outputs "
      "shifted by 60 degrees as built", aliases=("4.2",))
class _Fig42:
    @staticmethod
    def runs(p: Preset) -> list[RunSpec]:
        return [_pol_filter(p)]

    @staticmethod
    def evaluate(ctx: Context, specs: list[RunSpec]) -> Outcome:
        out = Outcome()
        res = ctx.result(specs[0])
        mae = metric(res, "heading_mae_deg")
        out.rows.append(Row("heading MAE against the filter angle (deg)", None, mae))
        out.checks.append(Check("axial heading MAE against the filter angle <= 5 deg",
                                None if mae is None else mae <= 5.0, "" if mae is None else f"{mae:.2f} deg"))
        copy_plot(ctx, res, "plots/fig4_2_unit_voltages.png", "fig4_2.png", out)
        return out


@item("fig4_4", "Fig. 4.4",
      "the thesis gives no number ('works as expected'); check: the averaged axial RMSE against the "
      "electromagnetic compass <= 10 deg", aliases=("4.4",))
class _Fig44:
    @staticmethod
    def runs(p: Preset) -> list[RunSpec]:
        return [_pol_vs_em(p)]

    @staticmethod
    def evaluate(ctx: Context, specs: list[RunSpec]) -> Outcome:
        out = Outcome()
        res = ctx.result(specs[0])
        v = metric(res, "averaged_rmse_deg")
        out.rows.append(Row("averaged axial RMSE against the TCM2 (deg)", None, v))
        out.rows.append(Row("raw axial RMSE against the TCM2 (deg)", None, metric(res, "heading_rmse_deg")))
        out.checks.append(Check("averaged RMSE <= 10 deg", None if v is None else v <= 10.0))
        copy_plot(ctx, res, "plots/fig4_4_averaged.png", "fig4_4.png", out)
        return out


@item("fig4_5", "Fig. 4.5",
      "the compass cannot tell 0 from 180 degrees at the zenith: in a rotation at tilt 0 the error function "
      "resolves the candidate pair of eq. 4.6 for at most 5 % of the samples (resolved_fraction); the figure "
      "plots the raw first candidate against the electromagnetic compass", aliases=("4.5",))
class _Fig45:
    @staticmethod
    def runs(p: Preset) -> list[RunSpec]:
        return [_pol_vs_em(p), _pol_rotation(p)]

    @staticmethod
    def evaluate(ctx: Context, specs: list[RunSpec]) -> Outcome:
        out = Outcome()
        vs, rot = ctx.result(specs[0]), ctx.result(specs[1])
        frac = metric(rot, "resolved_fraction")
        out.rows.append(Row("resolved fraction of the candidate pair, rotation at tilt 0", None, frac))
        out.rows.append(Row("axial heading MAE of the rotation (deg)", None, metric(rot, "heading_mae_deg")))
        out.checks.append(Check("the pair (phi, phi + pi) stays unresolved (resolved fraction <= 0.05)",
                                None if frac is None else frac <= 0.05))
        copy_plot(ctx, vs, "plots/fig4_5_raw.png", "fig4_5.png", out)
        copy_plot(ctx, rot, "plots/heading_vs_pan.png", "fig4_5_rotation.png", out)
        return out


@item("fig4_6", "Fig. 4.6",
      "a clear and a cloudy sky scanned: the residual of the measured e-vectors against the sky model "
      "(heading_rmse_deg of the scan) is larger under clouds (scattered orientations) than under a clear sky",
      aliases=("4.6",))
class _Fig46:
    @staticmethod
    def runs(p: Preset) -> list[RunSpec]:
        return [_pol("evector_scan", "experiment.sky.cloud_cover=0.0"),
                _pol("evector_scan", "experiment.sky.cloud_cover=0.6")]

    @staticmethod
    def evaluate(ctx: Context, specs: list[RunSpec]) -> Outcome:
        out = Outcome()
        clear, cloudy = ctx.result(specs[0]), ctx.result(specs[1])
        a, b = metric(clear, "heading_rmse_deg"), metric(cloudy, "heading_rmse_deg")
        out.rows.append(Row("e-vector residual RMSE, clear sky (deg)", None, a))
        out.rows.append(Row("e-vector residual RMSE, cloud cover 0.6 (deg)", None, b))
        out.rows.append(Row("mean degree of polarization, clear sky", None, metric(clear, "mean_degree")))
        out.rows.append(Row("mean degree of polarization, cloud cover 0.6", None, metric(cloudy, "mean_degree")))
        out.checks.append(Check("clouds scatter the e-vectors (residual larger than under a clear sky)",
                                None if a is None or b is None else b > a))
        copy_plot(ctx, clear, "plots/fig4_6_evector_field.png", "fig4_6_clear.png", out)
        copy_plot(ctx, cloudy, "plots/fig4_6_evector_field.png", "fig4_6_cloudy.png", out)
        out.notes.append("Simulated skies (the thesis' recordings of 29 July and 4 August 2009 are not available).")
        return out


# ---------------------------------------------------------------------------
# chapter 6: spectral contrasts
# ---------------------------------------------------------------------------
FEATURES = ("UV", "B", "G", "R", "IR", "all", "UV-B", "UV-G", "UV-R", "UV-IR", "B-G", "B-R", "B-IR", "G-R", "G-IR", "R-IR")
DUALS = tuple(f for f in FEATURES if "-" in f)
SINGLES = ("UV", "B", "G", "R", "IR")
TOL_J = 0.5
TOL_NF = 15.0  # per mille


def _lda_spec(p: Preset, data: str) -> RunSpec:
    return RunSpec(("experiment=contrast_lda", f"data={data}", f"experiment.n_resamples={p.lda_resamples}"),
                   group="contrast_lda")


def _lda_values(res: RunResult) -> dict[str, dict[str, float]] | None:
    if not res.ok:
        return None
    m = res.metrics
    return {"J": m.get("J", {}), "J_sigma": m.get("J_sigma", {}),
            "n_f": {k: 1000.0 * v for k, v in (m.get("n_f") or {}).items()}}


def _lda_item(table: str, data: str):
    class _L:
        @staticmethod
        def runs(p: Preset) -> list[RunSpec]:
            return [_lda_spec(p, data)]

        @staticmethod
        def evaluate(ctx: Context, specs: list[RunSpec]) -> Outcome:
            out = Outcome()
            res = ctx.result(specs[0])
            got = _lda_values(res)
            if got is None:
                out.missing.append(why_missing(res))
                return out
            ref = ctx.ref
            for crit, key, tol in (("J", "J", TOL_J), ("J_sigma", "J_sigma", TOL_J), ("n_f", "n_f_permille", TOL_NF)):
                for f in FEATURES:
                    out.rows.append(Row(f"{crit} {f}" + (" (per mille)" if crit == "n_f" else ""),
                                        ref[key].get(f), got[crit].get(f), tol))
            for crit in ("J", "J_sigma"):
                out.checks.append(rho_check(f"{crit} over the 16 features", [ref[crit][f] for f in FEATURES],
                                            [got[crit].get(f) for f in FEATURES]))
            best = max(DUALS, key=lambda f: got["J"].get(f, -np.inf))
            t_best = max(DUALS, key=lambda f: ref["J"][f])
            for crit in ("J", "J_sigma"):
                order = sorted(DUALS, key=lambda f: -got[crit].get(f, -np.inf))
                t_order = sorted(DUALS, key=lambda f: -ref[crit][f])
                out.rows.append(Row(f"rank of {t_best} among the 10 dual contrasts in {crit}",
                                    t_order.index(t_best) + 1, order.index(t_best) + 1))
            out.checks.append(Check(f"best dual-channel contrast in J is {t_best}", best == t_best, f"bionav: {best}"))
            if data == "sim_natural":
                few = min(DUALS, key=lambda f: got["n_f"].get(f, np.inf))
                out.checks.append(Check("fewest misclassified points with B-IR", few == "B-IR", f"bionav: {few}"))
            else:
                top4 = sorted(DUALS, key=lambda f: -got["J"].get(f, -np.inf))[:4]
                out.checks.append(Check("the four UV contrasts are the four best dual contrasts in J",
                                        set(top4) == {"UV-B", "UV-G", "UV-R", "UV-IR"}, f"bionav: {top4}"))
            out.checks.append(Check("UV is the best single channel in J",
                                    max(SINGLES, key=lambda f: got["J"].get(f, -np.inf)) == "UV"))
            copy = ctx.out / f"{table}.md"
            if (res.dir / "lda_table.md").is_file():
                shutil.copyfile(res.dir / "lda_table.md", copy)
                out.tables.append(copy.name)
            compare_bars(ctx.figure(f"{table}.png"), list(FEATURES),
                         {"thesis J": [ref["J"][f] for f in FEATURES], "bionav J": [got["J"].get(f) for f in FEATURES],
                          "thesis J_sigma": [ref["J_sigma"][f] for f in FEATURES],
                          "bionav J_sigma": [got["J_sigma"].get(f) for f in FEATURES]}, title=ref["title"],
                         ylabel="J, J_sigma (Fisher criterion, dimensionless)")
            out.figures.append(f"{table}.png")
            out.notes.append(f"Simulated samples (data={data}); the thesis' measured samples are not available.")
            return out

    return _L


item("table6_2", "Table 6.2",
     f"per feature: |J|, |J_sigma| differences <= {TOL_J}, n_f within {TOL_NF:g} per mille; ordering of J and of "
     "J_sigma over the 16 features equal (Spearman rho >= 0.8); UV-IR the best dual contrast in J; B-IR the fewest "
     "misclassifications; UV the best single channel", aliases=("6.2",))(_lda_item("table6_2", "sim_natural"))
item("table6_4", "Table 6.4",
     f"per feature: |J|, |J_sigma| differences <= {TOL_J}, n_f within {TOL_NF:g} per mille; ordering of J and of "
     "J_sigma equal (Spearman rho >= 0.8); UV-IR the best dual contrast; the UV contrasts the four best; UV the "
     "best single channel", aliases=("6.4",))(_lda_item("table6_4", "sim_artificial"))

SIG_MARK = {"0.001": "***", "0.01": "**", "0.05": "*", "": "o"}


def _significance(res: RunResult, crit: str) -> dict[tuple[str, str], str] | None:
    path = None if res.dir is None else res.dir / f"significance_{crit}.csv"
    if path is None or not path.is_file():
        return None
    out = {}
    for r in read_csv(path):
        a = r[crit]
        for b, v in r.items():
            if b != crit:
                out[(a, b)] = SIG_MARK.get(v.strip(), v.strip())
    return out


def _not_different(sig: dict[tuple[str, str], str], group: Sequence[str], crit: str) -> Check:
    """The thesis' claim that the features of ``group`` do not differ significantly (no mark at 5 %) in ``crit``."""
    pairs = [(a, b) for i, a in enumerate(group) for b in group[i + 1:]]
    marks = {f"{a}/{b}": sig.get((a, b), "?") for a, b in pairs}
    return Check(f"{', '.join(group)} do not differ significantly in {crit}", all(m == "o" for m in marks.values()),
                 ", ".join(f"{k}: {v}" for k, v in marks.items()))


@item("table6_3", "Table 6.3",
      "the table is not in the transcribed text: the claims of the discussion 6.2.4 are checked on bionav's "
      "bootstrap (each a check): pairs named 'not significantly different' in J have no mark at 5 %",
      aliases=("6.3",))
class _Table63:
    @staticmethod
    def runs(p: Preset) -> list[RunSpec]:
        return [_lda_spec(p, "sim_natural")]

    @staticmethod
    def evaluate(ctx: Context, specs: list[RunSpec]) -> Outcome:
        out = Outcome()
        res = ctx.result(specs[0])
        sig = _significance(res, "J")
        if sig is None:
            out.missing.append("no significance_J.csv: " + why_missing(res) if not res.ok else
                               "the run wrote no significance_J.csv (experiment.n_resamples=0?)")
            return out
        for g in [("UV-IR", "B-IR"), ("UV-G", "B-R", "G-IR"), ("UV-B", "B-G", "G-R", "R-IR"), SINGLES]:
            out.checks.append(_not_different(sig, g, "J"))
        if (res.dir / "significance.md").is_file():
            shutil.copyfile(res.dir / "significance.md", ctx.out / "table6_3.md")
            out.tables.append("table6_3.md")
        return out


# thesis 6.3.4: groups of contrasts of the artificial samples that "do not differ significantly", per criterion
_DISCUSSION_6_3_4 = {"J": [("UV-IR", "UV-B")], "J_sigma": [("UV-G", "UV-B")],
                     "n_f": [("UV-B", "UV-G", "UV-R", "UV-IR"), ("B-G", "B-R", "B-IR")]}


@item("table6_5", "Table 6.5",
      "per criterion and feature: bionav's significance mark of the difference to 'All' equals the thesis' "
      "(***, **, *, o); one check each; and the claims of the discussion 6.3.4 (UV-IR and UV-B do not differ in J, "
      "UV-IR differs from every other contrast in J, UV-G and UV-B do not differ in J_sigma, the UV contrasts and "
      "the B contrasts do not differ among themselves in n_f)", aliases=("6.5",))
class _Table65:
    @staticmethod
    def runs(p: Preset) -> list[RunSpec]:
        return [_lda_spec(p, "sim_artificial")]

    @staticmethod
    def evaluate(ctx: Context, specs: list[RunSpec]) -> Outcome:
        out = Outcome()
        res = ctx.result(specs[0])
        ref = ctx.ref
        for crit in ("J", "J_sigma", "n_f"):
            sig = _significance(res, crit)
            if sig is None:
                out.missing.append(f"no significance_{crit}.csv ({why_missing(res) if not res.ok else 'bootstrap skipped'})")
                continue
            for f, mark in ref[crit].items():
                got = sig.get(("all", f))
                out.checks.append(Check(f"{crit}: {f} vs All marked {mark}", None if got is None else got == mark,
                                        f"bionav: {got}"))
                out.rows.append(Row(f"{crit}: {f} vs All", mark, got))
            for group in _DISCUSSION_6_3_4.get(crit, ()):
                out.checks.append(_not_different(sig, group, crit))
            if crit == "J":
                others = [f for f in FEATURES if f not in ("UV-IR", "UV-B")]
                marks = {f: sig.get(("UV-IR", f), "?") for f in others}
                out.checks.append(Check("UV-IR differs significantly (at 5 %) from every contrast but UV-B in J",
                                        all(m not in ("o", "?") for m in marks.values()),
                                        "not significant: " + (", ".join(f for f, m in marks.items() if m == "o")
                                                               or "none")))
        if res.dir is not None and (res.dir / "significance.md").is_file():
            shutil.copyfile(res.dir / "significance.md", ctx.out / "table6_5.md")
            out.tables.append("table6_5.md")
        out.notes += list(ref.get("notes", []))
        return out


def _lda_fig(fig: str, data: str, plot: str, rule_fn):
    class _F:
        @staticmethod
        def runs(p: Preset) -> list[RunSpec]:
            return [_lda_spec(p, data)]

        @staticmethod
        def evaluate(ctx: Context, specs: list[RunSpec]) -> Outcome:
            out = Outcome()
            res = ctx.result(specs[0])
            copy_plot(ctx, res, f"plots/{plot}", f"{fig}.png", out)
            got = _lda_values(res)
            if got is None:
                out.missing.append(why_missing(res))
            else:
                rule_fn(out, got)
            return out

    return _F


def _fig63_rule(out: Outcome, got) -> None:
    for f in ("UV-G", "UV-IR"):
        v = got["n_f"].get(f)
        out.rows.append(Row(f"n_f {f} (per mille)", None, v))
        out.checks.append(Check(f"{f} separates sky and objects well (n_f <= 50 per mille)", None if v is None else v <= 50))


def _fig64_rule(out: Outcome, got) -> None:
    v = got["n_f"].get("R-IR")
    out.rows.append(Row("n_f R-IR (per mille)", 55, v))
    out.checks.append(Check("even R-IR (close wavelengths) is separable (n_f <= 100 per mille)", None if v is None else v <= 100))


def _fig65_rule(out: Outcome, got) -> None:
    singles = sorted(SINGLES, key=lambda f: -got["J"].get(f, -np.inf))
    out.checks.append(Check("UV is by far the best single channel (J at least twice the second's)",
                            got["J"][singles[0]] >= 2 * got["J"][singles[1]] and singles[0] == "UV",
                            f"{singles[0]} {got['J'][singles[0]]:.2f}, {singles[1]} {got['J'][singles[1]]:.2f}"))
    top = sorted(DUALS, key=lambda f: -got["J"].get(f, -np.inf))[:4]
    out.checks.append(Check("the UV contrasts perform best (the four best dual contrasts in J)",
                            set(top) == {"UV-B", "UV-G", "UV-R", "UV-IR"}, f"bionav: {top}"))


item("fig6_3", "Fig. 6.3", "UV-G and UV-IR each separate sky and objects with n_f <= 50 per mille (thesis: 42 and 15)",
     aliases=("6.3",))(_lda_fig("fig6_3", "sim_natural", "uv_g_uv_ir.png", _fig63_rule))
item("fig6_4", "Fig. 6.4", "R-IR (close wavelengths) separable: n_f <= 100 per mille (thesis: 55)",
     aliases=("6.4",))(_lda_fig("fig6_4", "sim_natural", "pairs.png", _fig64_rule))
item("fig6_5", "Fig. 6.5", "artificial objects: UV far the best single channel (J >= 2x the second) and the UV "
     "contrasts the four best dual contrasts", aliases=("6.5",))(_lda_fig("fig6_5", "sim_artificial", "pairs.png", _fig65_rule))


def _scan_spec(p: Preset) -> RunSpec:
    ov = ["experiment=contrast_scan", *(f"{k}={v}" for k, v in p.scan.items())]
    if p.scan_times < 14:
        from bionav.thesis.reference import DAY_TIMES

        ov += [f"experiment.times=[{','.join(DAY_TIMES[:p.scan_times])}]", "experiment.cloud_cover=0.8",
               "experiment.cloud_optical_depth=30"]
    return RunSpec(tuple(ov), group="contrast_scan")


MEASURE_OF = {"fig6_10": ("logNRMSD", False), "fig6_11": ("logMSEstd", False), "fig6_12": ("logMSEvar", False),
              "fig6_13": ("logNRMSD", True), "fig6_14": ("logMSEstd", True), "fig6_15": ("logMSEvar", True)}


def _stability(res: RunResult) -> dict[tuple[str, bool], list[tuple[float, dict[str, float]]]] | None:
    if res.dir is None or not (res.dir / "stability.csv").is_file():
        return None
    rows = read_csv(res.dir / "stability.csv")
    out: dict = {}
    for r in rows:
        out.setdefault((r["feature"], r["separated"] == "True"), []).append(r)
    return out


def _series(stab, feature: str, separated: bool, measure: str) -> np.ndarray:
    vals = [float(r[measure]) for r in stab.get((feature, separated), [])]
    return np.array([v for v in vals if math.isfinite(v)])


def _stability_item(fig: str):
    measure, separated = MEASURE_OF[fig]

    class _S:
        @staticmethod
        def runs(p: Preset) -> list[RunSpec]:
            return [_scan_spec(p)]

        @staticmethod
        def evaluate(ctx: Context, specs: list[RunSpec]) -> Outcome:
            from bionav.report.figures import pyplot, save_figure

            out = Outcome()
            res = ctx.result(specs[0])
            stab = _stability(res)
            if stab is None:
                out.missing.append(why_missing(res))
                return out
            plt = pyplot()
            fig_, ax = plt.subplots(figsize=(8, 4.2))
            means = {}
            for f in (*SINGLES, *DUALS):
                rows = stab.get((f, separated), [])
                y = np.array([float(r[measure]) for r in rows])
                if not len(rows):
                    continue
                ax.plot(np.arange(1, len(rows) + 1), y, "--" if f in SINGLES else "-", label=f)
                fin = y[np.isfinite(y)]
                means[f] = float(fin.mean()) if len(fin) else None
                out.rows.append(Row(f"mean {measure} {f}" + (" (separated)" if separated else ""), None, means[f]))
            ax.set_xlabel("scan after the reference (one-day series)")
            ax.set_ylabel(measure)
            ax.legend(fontsize=6, ncol=4)
            fig_name = fig.replace('fig', 'fig. ').replace('_', '.')
            ax.set_title(f"{measure}{' after skyline separation' if separated else ''} (thesis {fig_name})", fontsize=9)
            save_figure(fig_, ctx.figure(f"{fig}.png"), dpi=100)
            out.figures.append(f"{fig}.png")
            ok = {k: v for k, v in means.items() if v is not None}
            uv = [ok.get(f) for f in ("UV-B", "UV-G", "UV-R", "UV-IR")]
            if fig == "fig6_10":
                s = [ok[f] for f in SINGLES if f in ok]
                d = [ok[f] for f in DUALS if f in ok]
                out.checks.append(Check("every single channel above every dual contrast (time means)",
                                        bool(s and d and min(s) > max(d)) if s and d else None,
                                        f"min single {min(s):.2f}, max dual {max(d):.2f}" if s and d else ""))
            elif fig in ("fig6_11", "fig6_12"):
                for first in ("UV", "B", "G"):
                    fam = [f for f in DUALS if f.startswith(first + "-")]
                    vals = [ok.get(f) for f in fam]
                    rho = spearman(list(range(len(fam))), vals) if len(fam) > 2 else (
                        None if None in vals or len(fam) < 2 else (1.0 if vals[1] > vals[0] else -1.0))
                    out.checks.append(Check(f"{first} contrasts ordered by wavelength difference (|rho| = 1)",
                                            None if rho is None else abs(rho) > 0.999,
                                            ", ".join(f"{f} {fmt(v, 2)}" for f, v in zip(fam, vals))))
            elif fig == "fig6_13":
                spread = [float(np.ptp(_series(stab, f, True, measure))) for f in DUALS
                          if len(_series(stab, f, True, measure)) > 1]
                out.checks.append(Check("dual contrasts nearly constant over time after separation "
                                        "(max - min over the day <= 0.5 for every contrast)",
                                        bool(max(spread) <= 0.5) if spread else None,
                                        f"largest range {max(spread):.2f}" if spread else "no finite values"))
            else:
                raw = _stability_means(stab, measure, False)
                uv_raw = [raw.get(f) for f in ("UV-B", "UV-G", "UV-R", "UV-IR")]
                r1 = spearman([0, 1, 2, 3], uv_raw)
                r2 = spearman([0, 1, 2, 3], uv)
                out.checks.append(Check("order of UV-B, UV-G, UV-R, UV-IR reversed by the separation",
                                        None if r1 is None or r2 is None else bool(abs(r1) > 0.999 and r2 == -r1),
                                        f"rho before {fmt(r1, 2)}, after {fmt(r2, 2)}"))
            return out

    return _S


def _stability_means(stab, measure: str, separated: bool) -> dict[str, float]:
    out = {}
    for f in (*SINGLES, *DUALS):
        s = _series(stab, f, separated, measure)
        if len(s):
            out[f] = float(s.mean())
    return out


_STAB_RULES = {
    "fig6_10": "logNRMSD averaged over the day: every single channel above every dual-channel contrast",
    "fig6_11": "logMSEstd averaged over the day: the contrasts with first channel UV, B, G each ordered by their "
               "wavelength difference (|Spearman rho| = 1), one check per first channel",
    "fig6_12": "as fig. 6.11 for logMSEvar",
    "fig6_13": "logNRMSD after separation: every dual contrast nearly constant (max - min over the day <= 0.5)",
    "fig6_14": "logMSEstd: the order of UV-B, UV-G, UV-R, UV-IR (day means) is monotone before separation and "
               "reversed after it",
    "fig6_15": "as fig. 6.14 for logMSEvar",
}
for _f, _rule in _STAB_RULES.items():
    item(_f, f"Fig. {_f[3]}.{_f[5:]}", _rule, aliases=(f"{_f[3]}.{_f[5:]}",))(_stability_item(_f))


@item("fig6_16", "Figs. 6.16-6.25",
      "the J_sigma line of the natural samples separates sky from objects in every dual-channel contrast image of "
      "both example datasets: sky_accuracy (fraction of correctly classified pixels, simulated truth) >= 0.9 per "
      "contrast and dataset", aliases=tuple(f"6.{k}" for k in range(16, 26)))
class _Fig616:
    @staticmethod
    def runs(p: Preset) -> list[RunSpec]:
        from bionav.thesis.reference import load_reference

        ref = load_reference()["fig6_16"]
        return [RunSpec(("experiment=contrast_scan", f"experiment.times=[{t}]", "experiment.cloud_cover=0.9",
                         "experiment.cloud_optical_depth=30",
                         *(f"{k}={v}" for k, v in p.example_scan.items())), group="contrast_scan")
                for t in ref["times"]]

    @staticmethod
    def evaluate(ctx: Context, specs: list[RunSpec]) -> Outcome:
        out = Outcome()
        for n, spec in enumerate(specs, 1):
            res = ctx.result(spec)
            acc = metric(res, "sky_accuracy")
            if acc is None:
                out.missing.append(f"dataset {n}: {why_missing(res)}")
                continue
            for f in DUALS:
                v = acc.get(f)
                out.rows.append(Row(f"dataset {n}: sky accuracy {f}", None, v))
                out.checks.append(Check(f"dataset {n}: {f} separates sky and objects (accuracy >= 0.9)",
                                        None if v is None else v >= 0.9))
            first = 16 if n == 1 else 17
            copy_plot(ctx, res, "plots/separated_uv_ir_first.png", f"fig6_{first}.png", out)
            copy_plot(ctx, res, "plots/separation_first.png",
                      "fig6_18-21.png" if n == 1 else "fig6_22-25.png", out)
        out.notes.append("Simulated scans of a backyard scene under 0.9 cloud cover at the thesis' times (24 Oct 2008, "
                         "11:20 and 11:50); fig. 6.16/6.17 show UV-IR only (the thesis: all contrasts).")
        return out


@item("fig6_26", "Figs. 6.26/6.27",
      "square test (2 m, four corners, SIFT homing): bionav's AAE over all dual-channel contrasts (same light) "
      "within 0.2 rad of the thesis' 1.3427 rad", aliases=("6.26", "6.27", "fig6_27"))
class _Fig626:
    @staticmethod
    def runs(p: Preset) -> list[RunSpec]:
        return [RunSpec(("experiment=skyline_homing", "homing=sift", *p.skyline), group="skyline_homing")]

    @staticmethod
    def evaluate(ctx: Context, specs: list[RunSpec]) -> Outcome:
        out = Outcome()
        res = ctx.result(specs[0])
        sq = metric(res, "square_aae")
        if not sq:
            out.missing.append(why_missing(res) if not res.ok else "the run has no square test (square_aae)")
            return out
        duals = [sq[f] for f in DUALS if f in sq and sq[f] is not None and math.isfinite(sq[f])]
        mean = float(np.mean(duals)) if duals else None
        out.rows.append(Row("square test AAE over the dual contrasts (rad)", ctx.ref["aae"], mean, 0.2))
        for f, v in sq.items():
            out.rows.append(Row(f"square test AAE {f} (rad)", None, v))
        compare_bars(ctx.figure("fig6_26.png"), list(sq), {"bionav square-test AAE": list(sq.values()),
                                                           "thesis (all contrasts)": [ctx.ref["aae"]] * len(sq)},
                     title="square test: AAE per representation (thesis fig. 6.26)", ylabel="AAE (rad)")
        out.figures.append("fig6_26.png")
        copy_plot(ctx, res, "plots/representations.png", "fig6_27.png", out)
        out.notes.append("bionav has no plot of the square test's home vectors; fig6_26.png shows their AAE per "
                         "representation, fig6_27.png the representations (the UV channel among them).")
        return out


# ---------------------------------------------------------------------------
# chapter 7: cleaning
# ---------------------------------------------------------------------------
def _clean_spec(p: Preset, layout: str) -> RunSpec:
    return RunSpec(("experiment=cleaning", f"layout={layout}", f"runs={p.cleaning_runs}"), group="cleaning")


def _clean_item(fig: str, layout: str):
    class _C:
        @staticmethod
        def runs(p: Preset) -> list[RunSpec]:
            return [_clean_spec(p, "long_lanes"), _clean_spec(p, "short_lanes")]

        @staticmethod
        def evaluate(ctx: Context, specs: list[RunSpec]) -> Outcome:
            out = Outcome()
            res = ctx.result(specs[0 if layout == "long_lanes" else 1])
            if not res.ok:
                out.missing.append(why_missing(res))
            for key in ("coverage", "overlap", "uncovered"):
                v = metric(res, key)
                out.rows.append(Row(f"{key} (%), mean over runs", ctx.ref[f"{key}_pct"],
                                    None if v is None else 100.0 * v, 5.0))
            out.rows.append(Row("runs", ctx.ref["runs"], ctx.preset.cleaning_runs))
            if fig == "fig7_4":
                long_, short = ctx.result(specs[0]), ctx.result(specs[1])
                a, b = metric(long_, "coverage"), metric(short, "coverage")
                out.checks.append(Check("long lanes cover more than short lanes", None if a is None or b is None else a > b,
                                        "" if a is None or b is None else f"{a:.3f} vs {b:.3f}"))
            copy_plot(ctx, res, "plots/trajectories.png", f"{fig}_trajectories.png", out)
            copy_plot(ctx, res, "plots/overlap_map.png", f"{fig}_overlap.png", out)
            return out

    return _C


item("fig7_3", "Fig. 7.3", "coverage, overlap and uncovered area (means over the runs) each within 5 percentage "
     "points of the thesis'", aliases=("7.3",))(_clean_item("fig7_3", "long_lanes"))
item("fig7_4", "Fig. 7.4", "coverage, overlap and uncovered area each within 5 percentage points; long lanes "
     "cover more than short lanes", aliases=("7.4",))(_clean_item("fig7_4", "short_lanes"))


# ---------------------------------------------------------------------------
# the stand-ins as a whole (issue 18): do they rank databases and methods as reality does?
# ---------------------------------------------------------------------------
#: how much lower warping's RR* across doorlit <-> winlit must be than SIFT's to count as "clearly below"
CROSS_LIGHT_MARGIN = 0.10
PARAM_DBS = ("original", "hall1", "uni")


def _cross_light_rr(res: RunResult) -> float | None:
    """Mean RR* of the two cross-database cells doorlit -> winlit and winlit -> doorlit (None if absent)."""
    if not res.ok or res.dir is None or not (res.dir / "cross_db.csv").is_file():
        return None
    names, rr = _cross_matrix(res, "rr")
    if "sim_doorlit" not in names or "sim_winlit" not in names:
        return None
    d, w = names.index("sim_doorlit"), names.index("sim_winlit")
    return float((rr[d, w] + rr[w, d]) / 2)


def _ranking(res: RunResult) -> dict[str, dict[str, str]] | None:
    path = _ranking_csv(res) if res.dir is not None else None
    return None if path is None else {r["parameter"].strip("[]"): r for r in read_csv(path)}


@item("standins", "Stand-in hardness",
      "the checks of issue 18 across items: table 5.3 per database RR* within 0.10 and AAE* within 0.10 rad; "
      "each warping method's RR* above SIFT's on hall1 (table 5.4; on table 5.3's snapshots and draws); "
      "warping's mean RR* over doorlit <-> winlit "
      f"at least {CROSS_LIGHT_MARGIN} below SIFT's (fig. 5.6); parameter homing: uni's best RR* below original's "
      "and hall1's, rotation-invariant signatures ranked below the rotation-variant ones on average (per "
      "database), Spearman rho of each database's ranking against the thesis (reported)")
class _StandIns:
    @staticmethod
    def runs(preset: Preset) -> list[RunSpec]:
        sift = _Table53.runs(preset)
        # warping on hall1 paired with SIFT's table 5.3 runs: the same snapshots and pose-error draws
        warp = [grid_spec("sim_hall1", homing=h, size=preset.warping_size, snapshots=preset.snapshots, extra=extra,
                          blocks=preset.grid_blocks)
                for h in preset.warping for extra in _draw_args(preset)]
        cross = [_cross_spec(preset, h) for h in preset.cross_db_homing]
        params = [_param_spec(preset, db) for db in PARAM_DBS]
        return [*sift, *warp, *cross, *params]

    @staticmethod
    def evaluate(ctx: Context, specs: list[RunSpec]) -> Outcome:
        out = Outcome()
        p = ctx.preset
        n_draws = len(_draw_args(p))
        n_sift, n_warp, n_cross = len(THESIS_DBS) * n_draws, len(p.warping) * n_draws, len(p.cross_db_homing)
        sift_specs = specs[:n_sift]
        warp_specs = specs[n_sift:n_sift + n_warp]
        cross_specs = specs[n_sift + n_warp:n_sift + n_warp + n_cross]
        param_specs = specs[n_sift + n_warp + n_cross:]
        ref53 = load_reference_item("table5_3")
        v = _grid_table(ctx, out, sift_specs, THESIS_DBS, ref53, "SIFT", draws=p.pose_draws)
        mean = f" (mean of {len(p.pose_draws)} pose-error draws)" if len(p.pose_draws) > 1 else ""
        for key, tol in (("rr", TOL_RR), ("aae", TOL_ANGLE)):
            diffs = [(db, got, want) for db, got, want in zip(THESIS_DBS, v[key], ref53[key])]
            ok = None if any(g is None for _, g, _ in diffs) else all(abs(g - w) <= tol for _, g, w in diffs)
            out.checks.append(Check(f"table 5.3: every database's {key.upper()}*{mean} within {tol} of the thesis", ok,
                                    ", ".join(f"{db} {fmt(g)} vs {w}" for db, g, w in diffs)))
        sift_hall = v["rr"][THESIS_DBS.index("hall1")]
        for k, h in enumerate(p.warping):
            runs = _results(ctx, out, warp_specs[k * n_draws:(k + 1) * n_draws], f"{h} on hall1")
            w, note = _mean_over_draws(runs, "rr", p.pose_draws)  # on the table 5.3 snapshots and draws
            out.rows.append(Row(f"{h} RR* hall1", load_reference_item("table5_4")["rr"][1], w, TOL_RR, note=note))
            out.checks.append(Check(f"table 5.4: {h}'s RR* on hall1 above SIFT homing's{mean}",
                                    None if w is None or sift_hall is None else bool(w > sift_hall),
                                    f"{h} {fmt(w)}, SIFT {fmt(sift_hall)}"))
        cross = {h: _cross_light_rr(ctx.result(s)) for h, s in zip(p.cross_db_homing, cross_specs)}
        for h, val in cross.items():
            out.rows.append(Row(f"fig. 5.6 {h}: mean RR* doorlit <-> winlit", None, val))
            if val is None:
                out.missing.append(f"fig. 5.6 {h}: {why_missing(ctx.result(cross_specs[p.cross_db_homing.index(h)]))}")
        if "sift" in cross:
            for h, val in cross.items():
                if h != "sift":
                    ok = None if val is None or cross["sift"] is None else bool(val <= cross["sift"] - CROSS_LIGHT_MARGIN)
                    out.checks.append(Check(f"fig. 5.6: {h}'s RR* across doorlit <-> winlit at least "
                                            f"{CROSS_LIGHT_MARGIN} below SIFT homing's", ok,
                                            f"{h} {fmt(val)}, SIFT {fmt(cross['sift'])}"))
        best = {}
        for db, spec in zip(PARAM_DBS, param_specs):
            got = _ranking(ctx.result(spec))
            if not got:
                out.missing.append(f"parameter homing on {db}: {why_missing(ctx.result(spec))}")
                continue
            ref = load_reference_item(f"table5_{5 + PARAM_DBS.index(db)}")["ranking"]
            t_rank = {sig: rank for rank, sig, *_ in ref}
            pairs = [(t_rank[s], int(g["rank"])) for s, g in got.items() if s in t_rank]
            rho = spearman([a for a, _ in pairs], [b for _, b in pairs])
            out.rows.append(Row(f"parameter homing {db}: Spearman rho of the ranking against the thesis", None, rho))
            best[db] = max(float(g["rr"]) for g in got.values() if g.get("rr") not in (None, ""))
            out.rows.append(Row(f"parameter homing {db}: best RR*", ref[0][2], best[db], TOL_RR))
            inv = [int(g["rank"]) for g in got.values() if g.get("rot_invariant") == "y"]
            var = [int(g["rank"]) for g in got.values() if g.get("rot_invariant") == "n"]
            out.checks.append(Check(f"parameter homing {db}: rotation-invariant signatures ranked below the "
                                    "rotation-variant ones on average",
                                    None if not inv or not var else bool(np.mean(inv) > np.mean(var)),
                                    f"mean rank invariant {np.mean(inv) if inv else float('nan'):.1f}, "
                                    f"variant {np.mean(var) if var else float('nan'):.1f}"))
        if len(best) == len(PARAM_DBS):
            out.checks.append(Check("parameter homing: uni is the hardest of original, hall1, uni (lowest best RR*)",
                                    bool(best["uni"] < min(best["original"], best["hall1"])),
                                    ", ".join(f"{db} {best[db]:.3f}" for db in PARAM_DBS)))
        write_table(ctx, out, "standins.md", "Stand-in hardness (issue 18)", out.rows)
        return out


def load_reference_item(item_id: str) -> Mapping[str, Any]:
    """The thesis values of another item (reference.yaml)."""
    from bionav.thesis.reference import load_reference

    return load_reference()[item_id]
