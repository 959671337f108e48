"""Figures of ``experiment=contrast_lda`` (thesis figs. 6.3-6.5, D.1-D.2)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from bionav.report.figures import draw_border_line, pyplot, save_figure


def scatter_pair(ax, samples, result) -> None:
    """Objects (green) and sky (red) in a two-channel feature with the J (solid) and J_sigma (dashed) borders."""
    from bionav.light.bands import CHANNELS

    i, j = result.channels
    obj, sky = ~samples.is_sky, samples.is_sky
    ax.scatter(samples.counts[obj, i], samples.counts[obj, j], s=5, c="tab:green", label="objects", alpha=0.7, lw=0)
    ax.scatter(samples.counts[sky, i], samples.counts[sky, j], s=5, c="tab:red", label="sky", alpha=0.7, lw=0)
    ax.set_xlabel(f"{CHANNELS[i]} [counts]")
    ax.set_ylabel(f"{CHANNELS[j]} [counts]")
    draw_border_line(ax, *result.lda.border_line(), "-", f"J = {result.J:.2f}")
    draw_border_line(ax, *result.lda_sigma.border_line(), "--", f"J_sigma = {result.J_sigma:.2f}")
    ax.set_title(f"{result.name}: J={result.J:.2f}, J_s={result.J_sigma:.2f}, n_f={1000 * result.n_f:.0f}‰",
                 fontsize=8)


def plot_pairs(samples, results, path, *, names=None, title="") -> Path:
    """All ten dual-channel scatter plots in an upper-triangle grid (fig. 6.4/6.5), or the given ``names`` in a row (fig. 6.3)."""
    from bionav.light.bands import CHANNELS

    plt = pyplot()
    if names:
        fig, axes = plt.subplots(1, len(names), figsize=(4.2 * len(names), 4))
        for ax, n in zip(np.atleast_1d(axes), names):
            scatter_pair(ax, samples, results[n])
            ax.legend(fontsize=7, loc="best")
    else:
        k = len(CHANNELS) - 1
        fig, axes = plt.subplots(k, k, figsize=(3.2 * k, 3.2 * k))
        for r in range(k):
            for c in range(k):
                ax = axes[r, c]
                if c < r:
                    ax.axis("off")
                    continue
                scatter_pair(ax, samples, results[f"{CHANNELS[r]}-{CHANNELS[c + 1]}"])
        axes[0, 0].legend(fontsize=7, loc="best")
    if title:
        fig.suptitle(title)
    save_figure(fig, path, dpi=110)
    return Path(path)


def plot_projection_histograms(samples, results, path, *, title="") -> Path:
    """Histograms of the projected samples per feature with the class border (figs. D.1/D.2).

    Bin width: range of the projected data divided by ``10 log10 N`` (as in the thesis).
    """
    plt = pyplot()
    names = list(results)
    cols = 4
    rows = int(np.ceil(len(names) / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(3.4 * cols, 2.4 * rows))
    n_bins = max(int(round(10 * np.log10(len(samples)))), 5)
    for ax, n in zip(axes.ravel(), names):
        lda = results[n].lda
        y = lda.project(samples.counts[:, list(results[n].channels)])
        bins = np.linspace(y.min(), y.max(), n_bins + 1)
        ax.hist(y[samples.is_sky], bins=bins, histtype="step", lw=2, color="tab:red", label="sky")
        ax.hist(y[~samples.is_sky], bins=bins, histtype="step", lw=1, color="tab:green", label="objects")
        ax.axvline(lda.threshold, color="k", lw=1)
        ax.set_title(f"{n}  (n_f={1000 * results[n].n_f:.0f}‰)", fontsize=8)
        ax.tick_params(labelsize=6)
    for ax in axes.ravel()[len(names):]:
        ax.axis("off")
    axes.ravel()[0].legend(fontsize=6)
    if title:
        fig.suptitle(title)
    save_figure(fig, path, dpi=100)
    return Path(path)


def plot_criteria(results, path, *, title="") -> Path:
    """Bar chart of J and J_sigma per feature, ranked by J."""
    plt = pyplot()
    names = sorted(results, key=lambda n: -results[n].J)
    x = np.arange(len(names))
    fig, ax = plt.subplots(figsize=(10, 3.5))
    ax.bar(x - 0.2, [results[n].J for n in names], 0.4, label="J")
    ax.bar(x + 0.2, [results[n].J_sigma for n in names], 0.4, label="J_sigma")
    ax.set_xticks(x, names, rotation=45, ha="right")
    ax.set_ylabel("discriminant criterion")
    ax.legend()
    if title:
        ax.set_title(title)
    save_figure(fig, path, dpi=110)
    return Path(path)
