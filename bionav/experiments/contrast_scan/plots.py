"""Figures of ``experiment=contrast_scan`` (thesis figs. 6.8-6.25, D.3-D.17)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from bionav.report.figures import draw_border_line, pyplot, save_figure


def _image_grid(images: dict, path, *, title="", cmap="gray", cols=5):
    plt = pyplot()
    names = list(images)
    rows = int(np.ceil(len(names) / cols))
    first = np.asarray(images[names[0]])
    h, w = first.shape
    fig, axes = plt.subplots(rows, cols, figsize=(cols * 3.4, rows * max(1.0, 3.4 * h / max(w, 1)) + 0.8),
                             squeeze=False)
    for ax, n in zip(axes.ravel(), names):
        ax.imshow(np.asarray(images[n], dtype=float), cmap=cmap, interpolation="nearest", aspect="auto")
        ax.set_title(n, fontsize=8)
        ax.set_xticks([])
        ax.set_yticks([])
    for ax in axes.ravel()[len(names):]:
        ax.axis("off")
    if title:
        fig.suptitle(title, fontsize=9)
    save_figure(fig, path, dpi=90)
    return Path(path)


def plot_channel_images(counts, path, *, title="") -> Path:
    """The five channel images of a scan, each normalised for display (figs. 6.8/6.9, D.7-D.10)."""
    from bionav.light.bands import CHANNELS

    return _image_grid({c: counts[..., i] for i, c in enumerate(CHANNELS)}, path, title=title, cols=5)


def plot_contrast_images(counts, path, *, title="") -> Path:
    """The ten dual-channel contrast images of a scan (figs. D.11-D.17)."""
    from bionav.spectral.scan import feature_images

    imgs = feature_images(counts[..., :5])
    return _image_grid({n: v for n, v in imgs.items() if "-" in n}, path, title=title, cols=5)


def plot_separation_images(separations: dict, path, *, title="") -> Path:
    """Sky (black) / object (white) separation images per feature (figs. 6.18-6.25)."""
    return _image_grid({n: ~v for n, v in separations.items()}, path, title=title, cols=5)


def plot_separated_scatter(counts, is_sky, lda, path, *, title="", channels=(0, 4), local=None) -> Path:
    """Pixels of a scan in a two-channel plane coloured by their classification (figs. 6.16/6.17).

    ``lda`` is the learned border (dashed); ``local``, if given, the scan's own border on its direction (solid).
    """
    plt = pyplot()
    x = counts[..., channels[0]].ravel()
    y = counts[..., channels[1]].ravel()
    sky = np.asarray(is_sky).ravel()
    fig, ax = plt.subplots(figsize=(4.5, 4))
    ax.scatter(x[~sky], y[~sky], s=3, c="tab:green", lw=0, label="objects")
    ax.scatter(x[sky], y[sky], s=3, c="tab:red", lw=0, label="sky")
    ax.set_xlabel("UV [counts]")
    ax.set_ylabel("IR [counts]")
    draw_border_line(ax, *lda.border_line(), "--", "J_sigma border")
    if local is not None:
        draw_border_line(ax, *local.border_line(), "-", "local border (this scan)")
    ax.legend(fontsize=7)
    if title:
        ax.set_title(title, fontsize=9)
    save_figure(fig, path, dpi=100)
    return Path(path)


def plot_stability(rows, hours, path, *, separated: bool, measures=None) -> Path:
    """The stability measures over the day for every channel and dual contrast (figs. 6.10-6.15, D.3-D.6).

    One row of panels per measure: single channels left, dual-channel contrasts right.
    """
    from bionav.light.bands import CHANNELS, dual_contrasts
    from bionav.spectral.stability import MEASURES

    plt = pyplot()
    measures = list(measures or MEASURES)
    fig, axes = plt.subplots(len(measures), 2, figsize=(11, 2.6 * len(measures)), squeeze=False)
    groups = (("single channels", list(CHANNELS)), ("dual-channel contrasts", list(dual_contrasts())))
    for row, measure in enumerate(measures):
        for ax, (label, names) in zip(axes[row], groups):
            for n in names:
                vals = [r[measure] for r in rows if r["feature"] == n and r["separated"] == separated]
                ls = "-" if n.startswith("UV") or "-" not in n else "--"
                ax.plot(hours[: len(vals)], vals, marker="o", ms=3, label=n, ls=ls)
            ax.set_ylabel(measure)
            if row == 0:
                ax.set_title(label + (" (after sky/object separation)" if separated else ""))
                ax.legend(fontsize=6, ncol=2)
        axes[row, 1].sharey(axes[row, 0])
    for ax in axes[-1]:
        ax.set_xlabel("hours after the first scan")
    save_figure(fig, path, dpi=90)
    return Path(path)
