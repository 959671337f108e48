"""Chapter 3: the databases (table 3.1)."""

from __future__ import annotations

from bionav.thesis.items.base import Context, db_meta, item, markdown
from bionav.thesis.outcome import Outcome, Row
from bionav.thesis.presets import Preset
from bionav.thesis.runs import RunSpec

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
