"""The stand-ins as a whole: do they rank databases and methods as reality does?"""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np

from bionav.thesis.items.base import (
    THESIS_DBS,
    TOL_ANGLE,
    TOL_RR,
    Context,
    grid_spec,
    item,
    read_csv,
    spearman,
    why_missing,
    write_table,
)
from bionav.thesis.items.ch5 import _cross_matrix, _cross_spec, _draw_args, _grid_table, _mean_over_draws, _results, _Table53
from bionav.thesis.items.ch5_params import _param_spec, _ranking_csv
from bionav.thesis.outcome import Check, Outcome, Row, fmt
from bionav.thesis.presets import Preset
from bionav.thesis.runs import RunResult, RunSpec

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
