"""Appendix B: SIFT homing at four image sizes."""

from __future__ import annotations

from bionav.thesis.items.base import (
    TOL_ANGLE,
    TOL_RR,
    Context,
    compare_bars,
    grid_spec,
    item,
    metric,
    rho_check,
    spearman,
    why_missing,
    write_table,
)
from bionav.thesis.outcome import Check, Outcome, Row
from bionav.thesis.presets import Preset
from bionav.thesis.runs import RunSpec


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
