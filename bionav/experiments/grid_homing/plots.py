"""Figures of ``experiment=grid_homing`` (home-vector fields, per-snapshot heatmaps)."""

from __future__ import annotations

from pathlib import Path
from typing import Sequence

import numpy as np

from bionav.report.figures import capped_colorbar, capped_colormap, grid_cell_axes, pyplot, save_figure


def plot_home_vector_field(
    path: Path,
    *,
    positions: np.ndarray,
    angles: np.ndarray,
    snapshot: np.ndarray,
    grid_shape: tuple[int, int],
    title: str,
    paths: Sequence[np.ndarray] | None = None,
    success: np.ndarray | None = None,
) -> None:
    """Quiver plot of the home vectors towards one snapshot (grid frame, x right, y up)."""
    plt = pyplot()
    nx, ny = grid_shape
    fig, (ax, legend_ax) = plt.subplots(2, 1, figsize=(max(4.8, 0.45 * nx + 2.0), 0.45 * ny + 2.5),
                                        gridspec_kw={"height_ratios": [0.45 * ny + 1.2, 1.3]})
    ok = np.isfinite(angles)
    colors = None
    if success is not None:
        colors = np.where(success[ok], "tab:blue", "tab:red")
    ax.quiver(
        positions[ok, 0], positions[ok, 1], np.cos(angles[ok]), np.sin(angles[ok]),
        color=colors if colors is not None else "tab:blue", angles="xy", scale_units="xy", scale=1.6, width=0.006,
    )
    if paths is not None:
        for p in paths:
            ax.plot(p[:, 0], p[:, 1], color="0.6", lw=0.5, alpha=0.6)
    if (~ok).any():  # cells where the method gave no direction (scored as a random one)
        ax.plot(positions[~ok, 0], positions[~ok, 1], "x", color="0.3", markersize=5)
    ax.plot(*snapshot, marker="*", color="gold", markeredgecolor="k", markersize=16, zorder=5)
    ax.set_xlim(-1, nx)
    ax.set_ylim(-1, ny)
    ax.set_aspect("equal")
    grid_cell_axes(ax)
    ax.set_title(title, fontsize=9)
    _field_legend(legend_ax, success=success, paths=paths is not None, no_direction=bool((~ok).any()))
    save_figure(fig, path, dpi=110)


def _field_legend(ax, *, success, paths: bool, no_direction: bool) -> None:
    """A legend naming every colour and marker of a home-vector field, in the empty axes ``ax`` below the map."""
    from matplotlib.lines import Line2D

    arrow = dict(marker=r"$\rightarrow$", linestyle="none", markersize=10)
    handles = [Line2D([], [], color="tab:blue", **arrow,
                      label="home vector" + (" (its return agent reached the snapshot)" if success is not None else ""))]
    if success is not None:
        handles.append(Line2D([], [], color="tab:red", **arrow, label="home vector (its return agent failed)"))
    if no_direction:
        handles.append(Line2D([], [], color="0.3", marker="x", linestyle="none", label="no direction given"))
    if paths:
        handles.append(Line2D([], [], color="0.6", lw=1, label="return agents' paths"))
    handles.append(Line2D([], [], color="gold", marker="*", markeredgecolor="k", markersize=12, linestyle="none",
                          label="snapshot position"))
    ax.axis("off")
    ax.legend(handles=handles, loc="center", ncol=1, fontsize=7, frameon=False)


def plot_per_snapshot_maps(
    path: Path,
    *,
    positions: np.ndarray,
    grid_shape: tuple[int, int],
    aae_s: np.ndarray,
    rr_s: np.ndarray,
    title: str,
) -> None:
    """Heatmaps of AAE_s (rad) and RR_s (fraction) over the grid, like thesis fig. 5.9 (missing cells blank).

    Each cell shows the value of the snapshot taken there; axes are grid cells
    (x right, y up) with whole-cell ticks.
    """
    plt = pyplot()
    nx, ny = grid_shape
    maps = []
    for values in (aae_s, rr_s):
        m = np.full((ny, nx), np.nan)
        m[positions[:, 1], positions[:, 0]] = values
        maps.append(m)
    fig, axes = plt.subplots(1, 2, figsize=(2 * (0.35 * nx + 1.6), 0.35 * ny + 1.4))
    for ax, m, label, cmap, vmax in zip(axes, maps, ("AAE$_s$ (rad)", "RR$_s$"), ("magma_r", "viridis"), (np.pi / 2, 1.0)):
        capped = label.startswith("AAE")  # AAE_s reaches pi; above pi/2 (worse than a guess) in the over colour
        im = ax.imshow(m, origin="lower", cmap=capped_colormap(cmap) if capped else cmap, vmin=0, vmax=vmax)
        ax.set_title(f"{label} per snapshot position")
        grid_cell_axes(ax)
        if capped:
            capped_colorbar(fig, im, ax=ax, shrink=0.8, label=label)
        else:
            fig.colorbar(im, ax=ax, shrink=0.8, label=label)
    fig.suptitle(title, fontsize=9)
    save_figure(fig, path, dpi=110)


def plot_fields(plots, homing: str, db, hv, q, s_pos, success, paths, plotted) -> None:
    """Home-vector fields of the ``plotted`` snapshot rows and the per-snapshot maps of AAE_s and RR_s."""
    label = f"{homing} on {db.name}"
    for row in sorted(plotted):
        si = hv.snapshot_index[row]
        x, y = db.positions[si]
        plot_home_vector_field(
            plots / f"home_vectors_{x}_{y}.png", positions=db.positions, angles=hv.angles[row],
            snapshot=db.positions[si], grid_shape=db.grid_shape, paths=paths.get(row), success=success[row],
            title=f"{label}: snapshot ({x}, {y}), AAE$_s$={q.aae_s[row]:.3f} rad, RR$_s$={q.rr_s[row]:.2f}",
        )
    plot_per_snapshot_maps(
        plots / "per_snapshot.png", positions=s_pos, grid_shape=db.grid_shape, aae_s=q.aae_s, rr_s=q.rr_s,
        title=f"{label}: AAE*={q.aae:.3f} rad, MAE*={q.mae:.3f} rad, RR*={q.rr:.3f}",
    )
