"""Figures of the spectral-contrast experiments (thesis figs. 6.3-6.5, 6.8-6.25, D.1-D.2)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from bionav.report.figures import pyplot, save_figure


def _border(ax, lda, style, label):
    point, tangent = lda.border_line()
    x0, x1 = ax.get_xlim()
    y0, y1 = ax.get_ylim()
    span = 4 * max(x1 - x0, y1 - y0)
    p = point + np.outer(np.linspace(-span, span, 3), tangent)
    # move the border's reference point next to the data
    centre = np.array([(x0 + x1) / 2, (y0 + y1) / 2])
    shift = ((centre - point) @ tangent) * tangent
    p = p + shift
    ax.plot(p[:, 0], p[:, 1], style, color="tab:blue", lw=1.3, label=label)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)


def scatter_pair(ax, samples, result) -> None:
    """Objects (green) and sky (red) in a two-channel feature with the J (solid) and J_sigma (dashed) borders."""
    from bionav.light.bands import CHANNELS

    i, j = result.channels
    obj, sky = ~samples.is_sky, samples.is_sky
    ax.scatter(samples.counts[obj, i], samples.counts[obj, j], s=5, c="tab:green", label="objects", alpha=0.7, lw=0)
    ax.scatter(samples.counts[sky, i], samples.counts[sky, j], s=5, c="tab:red", label="sky", alpha=0.7, lw=0)
    ax.set_xlabel(f"{CHANNELS[i]} [counts]")
    ax.set_ylabel(f"{CHANNELS[j]} [counts]")
    _border(ax, result.lda, "-", f"J = {result.J:.2f}")
    _border(ax, result.lda_sigma, "--", f"J_sigma = {result.J_sigma:.2f}")
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
    _border(ax, lda, "--", "J_sigma border")
    if local is not None:
        _border(ax, local, "-", "local border (this scan)")
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
