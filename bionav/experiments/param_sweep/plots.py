"""Figures of ``experiment=param_sweep``."""

from __future__ import annotations

from typing import Any

from bionav.report.figures import pyplot, save_figure


def plot_levels(path, rows: list[dict[str, Any]], *, title: str) -> None:
    """RR* and AAE* of one job's configurations against R or K (``plots/levels.png``)."""
    plt = pyplot()

    key = "n_coeffs" if rows[0]["n_coeffs"] is not None and len(rows) > 1 else "rings"
    x = [r[key] if r[key] is not None else 0 for r in rows]
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.plot(x, [r["rr"] for r in rows], "o-", label="RR*")
    ax.plot(x, [r["aae"] for r in rows], "s--", label="AAE* (rad)")
    ax.set_xlabel("number of Fourier coefficients K" if key == "n_coeffs" else "number of rings R")
    ax.set_ylabel("RR* (fraction) | AAE* (rad)")
    ax.set_ylim(0, max(1.0, max(r["aae"] for r in rows) * 1.05))
    ax.legend()
    ax.grid(alpha=0.3)
    ax.set_title(title, fontsize=9)
    save_figure(fig, path, dpi=110)
