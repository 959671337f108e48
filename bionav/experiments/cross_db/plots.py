"""Figures of ``experiment=cross_db``: the measure matrices as thesis fig. 5.6."""

from __future__ import annotations

import numpy as np

from bionav.report.figures import pyplot, save_figure

#: the measures of every cell, in the order of the panels
MEASURES = ("aae", "mae", "rr")


def plot_cross_db(path, matrices: dict[str, np.ndarray], names: list[str], title: str) -> None:
    """AAE*, MAE* and RR* of every (snapshot database, current-view database) pair as heatmaps (thesis fig. 5.6)."""
    plt = pyplot()

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.8))
    labels = {"aae": "AAE* (rad)", "mae": "MAE* (rad)", "rr": "RR*"}
    for ax, key in zip(axes, MEASURES):
        m = matrices[key]
        # light = good, as thesis fig. 5.6
        cmap = "gray" if key == "rr" else "gray_r"
        im = ax.imshow(m, cmap=cmap, vmin=0, vmax=1 if key == "rr" else max(np.nanmax(m), 1e-9))
        ax.set_xticks(range(len(names)), names, rotation=60, ha="right", fontsize=7)
        ax.set_yticks(range(len(names)), names, fontsize=7)
        ax.set_xlabel("current-view database")
        ax.set_ylabel("snapshot database")
        ax.set_title(labels[key])
        for i in range(len(names)):
            for j in range(len(names)):
                ax.text(j, i, f"{m[i, j]:.2f}", ha="center", va="center", fontsize=6, color="tab:red")
        fig.colorbar(im, ax=ax, shrink=0.8)
    fig.suptitle(title)
    save_figure(fig, path, dpi=110)
