"""Figures of ``experiment=skyline_homing``."""

from __future__ import annotations

import numpy as np

from bionav.report.figures import pyplot, save_figure


def plot_skyline_homing(plots, counts, disc, reps, names, metrics, results, border) -> None:
    """RR* per representation (same and changed light), the RR* matrices and every representation of the
    first position under every condition (``rr_per_representation.png``, ``rr_matrices.png``,
    ``representations.png``)."""
    plt = pyplot()

    from bionav.spectral.representations import representation_image

    # RR* per representation: same light vs changed light
    x = np.arange(len(reps))
    fig, ax = plt.subplots(figsize=(max(6, 0.5 * len(reps) + 2), 3.8))
    ax.bar(x - 0.2, [metrics["rr_same"][r] for r in reps], 0.4, label="same light")
    if len(names) > 1:
        ax.bar(x + 0.2, [metrics["rr"][r] for r in reps], 0.4, label="changed light")
    ax.set_xticks(x, reps, rotation=60, ha="right", fontsize=8)
    ax.set_xlabel("representation (channel, contrast or skyline)")
    ax.set_ylabel("RR* (fraction of agents home)")
    ax.set_ylim(0, 1.05)
    ax.legend()
    ax.set_title(f"return ratio per representation (homing={metrics['homing']})")
    save_figure(fig, plots / "rr_per_representation.png", dpi=100)
    # RR* matrices per representation
    cols = min(5, len(reps))
    rws = int(np.ceil(len(reps) / cols))
    fig, axes = plt.subplots(rws, cols, figsize=(2.6 * cols, 2.4 * rws), squeeze=False)
    for ax, r in zip(axes.ravel(), reps):
        ax.imshow(results[r]["rr"], vmin=0, vmax=1, cmap="viridis")
        ax.set_title(r, fontsize=8)
        ax.set_xticks(range(len(names)), names, rotation=90, fontsize=5)
        ax.set_yticks(range(len(names)), names, fontsize=5)
    for ax in axes.ravel()[len(reps):]:
        ax.axis("off")
    fig.suptitle("RR*: rows snapshot condition, columns current condition", fontsize=9)
    save_figure(fig, plots / "rr_matrices.png", dpi=90)
    # the representations of the first position under every condition
    fig, axes = plt.subplots(len(reps), len(names), figsize=(3.2 * len(names), 0.9 * len(reps) + 0.5), squeeze=False)
    for i, r in enumerate(reps):
        for j, nm in enumerate(names):
            axes[i, j].imshow(representation_image(counts[j][0], r, discriminants=disc, threshold=border), cmap="gray",
                              vmin=0, vmax=1,
                              aspect="auto", interpolation="nearest")
            axes[i, j].set_xticks([])
            axes[i, j].set_yticks([])
            if j == 0:
                axes[i, j].set_ylabel(r, fontsize=7, rotation=0, ha="right")
            if i == 0:
                axes[i, j].set_title(nm, fontsize=8)
    save_figure(fig, plots / "representations.png", dpi=80)
