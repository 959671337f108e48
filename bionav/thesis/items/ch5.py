"""Chapter 5: SIFT homing and warping (tables 5.3, 5.4, figs. 5.4-5.6)."""

from __future__ import annotations

from typing import Any, Mapping, Sequence

import numpy as np

from bionav.thesis.items.base import (
    THESIS_DBS,
    TOL_ANGLE,
    TOL_RR,
    Context,
    compare_bars,
    copy_plot,
    cutoff_preprocess,
    db_meta,
    grid_spec,
    item,
    markdown,
    metric,
    read_csv,
    rho_check,
    size_arg,
    why_missing,
    write_table,
)
from bionav.thesis.outcome import Check, Outcome, Row, fmt
from bionav.thesis.presets import Preset
from bionav.thesis.runs import RunResult, RunSpec


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
    # (snapshot, database pair) units, never a block without one (bionav.experiments.cross_db.run.task_units)
    units = max(1, int(-(-nx // stride) * -(-ny // stride) * 0.85)) * len(preset.cross_db_family) ** 2
    return RunSpec(tuple(ov), group="cross_db", blocks=min(int(preset.cross_db_blocks.get(homing, 1)), units))


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
