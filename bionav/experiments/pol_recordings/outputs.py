"""Files of ``experiment=pol_recordings``: ``sessions.csv``, ``pooled.csv``, ``faults.csv``, ``summary.md`` and the plots."""

from __future__ import annotations

from pathlib import Path

from bionav.experiments.pol_recordings.scoring import GROUPS, RULE_TEXT


def _cell(value):
    if value is None:
        return ""
    return f"{value:.4g}" if isinstance(value, float) else value


def _write_rows(path: Path, rows: list[dict]) -> None:
    """Rows of dicts through the one CSV writer (columns in order of first appearance; empty file for no rows)."""
    from bionav.files import write_atomic, write_csv_atomic

    if not rows:
        write_atomic(path, "")
        return
    keys = list(rows[0])
    for r in rows[1:]:
        keys += [k for k in r if k not in keys]
    write_csv_atomic(path, keys, ([_cell(r.get(k)) for k in keys] for r in rows))


def _fmt(v, digits=1):
    return "-" if v is None else f"{v:.{digits}f}"


def _pooled_table(pooled, decoders, groups, rule: str) -> list[str]:
    lines = [f"Pooled under the `{rule}` rule ({RULE_TEXT[rule]}): MAE / RMSE (degrees), fraction within 5 degrees", "",
             "| decoder | " + " | ".join(groups) + " |", "|" + "---|" * (1 + len(groups))]
    for d in decoders:
        cells = []
        for g in groups:
            r = pooled.get((rule, d, g))
            cells.append("-" if r is None or r["mae_deg"] is None else
                         f"{_fmt(r['mae_deg'])} / {_fmt(r['rmse_deg'])} ({r['within_5']:.2f})")
        lines.append(f"| {d} | " + " | ".join(cells) + " |")
    return lines + [""]


def summary_markdown(session_rows, pooled_rows, decoders, *, reference: str, rules) -> str:
    """Per-session MAE (every named rule) and pooled tables per rule (degrees) as Markdown.

    ``reference``: ``recordings.reference``, the rule of the default-named columns; ``rules``: the rules
    pooled, the published one (``logged``) first.
    """
    lines = [f"Heading reference of the default-named values: `recordings.reference={reference}`. Numbers to set "
             "beside published ones (Gkanias et al. 2023) are those of the `logged` rule.", "",
             "Per session: MAE (degrees) per decoder, logged / stitched", ""]
    lines.append("| session | condition | sun elev. (deg) | " + " | ".join(decoders) + " | sim (" + decoders[0] + ") |")
    lines.append("|" + "---|" * (4 + len(decoders)))
    by = {}
    for r in session_rows:
        by.setdefault(r["session"], {})[r["decoder"]] = r
    for rows in by.values():
        first = next(iter(rows.values()))
        cells = [f"{_fmt(rows[d]['mae_deg_logged'])} / {_fmt(rows[d]['mae_deg_stitched'])}" if d in rows else "-"
                 for d in decoders]
        sim = rows.get(decoders[0], {}).get("sim_mae_deg")
        lines.append(f"| {first['day']} {first['time_of_day']} | {first['period']} | {_fmt(first['sun_elevation_deg'])} | "
                     + " | ".join(cells) + f" | {_fmt(sim)} |")
    lines.append("")
    pooled = {(r["rule"], r["decoder"], r["group"]): r for r in pooled_rows}
    groups = [g for g in GROUPS if any(k[2] == g for k in pooled)]
    for rule in rules:
        lines += _pooled_table(pooled, decoders, groups, rule)
    return "\n".join(lines)


def write_outputs(ctx, exp, tally, pooled_rows, chosen, reference: str) -> None:
    """Every file and plot of the run."""
    from bionav.experiments.pol_recordings import plots

    _write_rows(ctx.dir / "sessions.csv", tally.session_rows)
    _write_rows(ctx.dir / "pooled.csv", pooled_rows)
    _write_rows(ctx.dir / "faults.csv", tally.fault_rows)
    (ctx.dir / "summary.md").write_text(summary_markdown(tally.session_rows, pooled_rows, tally.names,
                                                         reference=reference, rules=tally.rules))
    plot_dir = ctx.plots
    plots.error_vs_time_of_day(plot_dir / "error_vs_time_of_day.png", tally.session_rows, tally.names)
    default_errors = [(s, d, errs[tally.default], decoded) for s, d, errs, decoded in tally.per_session_plot]
    plots.session_distributions(plot_dir / "session_errors.png", default_errors, chosen)
    first = tally.per_session_plot[0]
    plots.raw_rotation(plot_dir / "raw_unit_responses.png", first[0], first[1])
    real = {g: list(tally.errors[tally.default][chosen][g]) for g in GROUPS}
    plots.clear_vs_canopy(plot_dir / "clear_vs_canopy.png", real, chosen)
    plots.yaw_reference(plot_dir / "yaw_reference.png", tally.per_session_plot, chosen)
    if exp.simulate:  # the simulated yaw has no restarts: set beside the stitched errors
        plots.sim_vs_real(plot_dir / "sim_vs_real.png", {g: list(tally.errors["stitched"][chosen][g]) for g in GROUPS},
                          tally.sim_err, chosen)
