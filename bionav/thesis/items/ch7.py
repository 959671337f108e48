"""Chapter 7: the cleaning robot."""

from __future__ import annotations

from bionav.thesis.items.base import Context, copy_plot, item, metric, why_missing
from bionav.thesis.outcome import Check, Outcome, Row
from bionav.thesis.presets import Preset
from bionav.thesis.runs import RunSpec


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
