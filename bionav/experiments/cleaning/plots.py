"""Figures of the cleaning experiment (thesis figs. 7.2-7.4)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from bionav.report.figures import pyplot, save_figure


def plot_trajectories(path: Path, results, world, plan, *, title: str = "") -> None:
    """True trajectories of all runs in the plan frame, with obstacles and the target area (fig. 7.3/7.4 top)."""
    from matplotlib.patches import Rectangle

    from bionav.robot.lanes import ideal_meander, to_plan_frame

    plt = pyplot()
    (x0, y0), (x1, y1) = plan.target_rectangle()
    fig, ax = plt.subplots(figsize=(8, 8 * (y1 - y0 + 1.2) / (x1 - x0 + 1.2) + 0.8))
    segs = world.floor.segments
    if len(segs):
        a = to_plan_frame(np.c_[segs[:, 0:2], np.zeros(len(segs))], world.start)
        b = to_plan_frame(np.c_[segs[:, 2:4], np.zeros(len(segs))], world.start)
        for k, (p, q) in enumerate(zip(a, b)):
            ax.plot([p[0], q[0]], [p[1], q[1]], color="0.35", lw=1.0, label="obstacle outlines" if k == 0 else None)
    ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, ls="--", lw=1.0, ec="k", label="target area"))
    ideal = ideal_meander(plan)
    ax.plot(ideal[:, 0], ideal[:, 1], color="0.7", lw=3, alpha=0.6, label="ideal meander")
    colors = plt.cm.viridis(np.linspace(0, 0.9, max(1, len(results))))
    for r, c in zip(results, colors):
        p = to_plan_frame(r.episode.true_pose, world.start)
        ax.plot(p[:, 0], p[:, 1], color=c, lw=0.8,
                label=f"run {r.run} ({r.wheel_error[0]:+.2f}/{r.wheel_error[1]:+.2f})")
    ax.set_xlim(x0 - 0.6, x1 + 0.6)
    ax.set_ylim(y0 - 0.6, y1 + 0.6)
    ax.set_aspect("equal")
    ax.set_xlabel("x along the first lane (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(f"Trajectories of {len(results)} runs" + (f": {title}" if title else ""))
    # below the axes: the runs fill the target area, a legend inside would hide some (wheel errors left/right)
    ax.legend(fontsize=6, loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=3, frameon=False)
    save_figure(fig, path, dpi=120)


def _overlap_image(counts: np.ndarray) -> np.ndarray:
    # white = uncovered, light grey = cleaned once, dark grey = overlap
    img = np.ones(counts.shape + (3,))
    img[counts == 1] = 0.8
    img[counts >= 2] = 0.45
    return img


def plot_overlap_maps(path_one: Path, path_all: Path, results, raster, plan) -> None:
    """Overlap map of the median run (fig. 7.3/7.4 bottom) and small maps of every run."""
    from matplotlib.patches import Rectangle

    plt = pyplot()
    (x0, y0), (x1, y1) = plan.target_rectangle()
    cov = np.array([r.fractions["coverage"] for r in results])
    median = int(np.argsort(cov)[len(cov) // 2])

    def draw(ax, r):
        ax.imshow(_overlap_image(r.counts), origin="lower", extent=raster.extent, interpolation="nearest")
        ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, lw=0.8, ec="k"))
        f = r.fractions
        ax.set_title(f"run {r.run}: {100 * f['coverage']:.1f} / {100 * f['overlap']:.1f} / "
                     f"{100 * f['uncovered']:.1f} %", fontsize=8)
        ax.set_xlim(x0 - 0.3, x1 + 0.3)
        ax.set_ylim(y0 - 0.3, y1 + 0.3)
        ax.set_aspect("equal")

    fig, ax = plt.subplots(figsize=(8, 8 * (y1 - y0 + 0.6) / (x1 - x0 + 0.6) + 0.8))
    draw(ax, results[median])
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    fig.suptitle("Overlap analysis (white: uncleaned, light grey: cleaned once, dark grey: overlap); "
                 "coverage / overlap / uncovered", fontsize=8)
    save_figure(fig, path_one, dpi=120)

    n = len(results)
    cols = min(5, n)
    rows = int(np.ceil(n / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(3.2 * cols, 3.2 * rows * (y1 - y0 + 0.6) / (x1 - x0 + 0.6) + 0.6),
                             squeeze=False)
    for ax in axes.ravel():
        ax.axis("off")
    for ax, r in zip(axes.ravel(), results):
        ax.axis("on")
        draw(ax, r)
        ax.tick_params(labelsize=6)
    save_figure(fig, path_all, dpi=100)


def plot_layout(path: Path, results, world, plan) -> None:
    """The layout in the world (fig. 7.2): obstacle outlines, target area, ideal meander, the median run."""
    from bionav.robot.lanes import ideal_meander, to_world_frame

    plt = pyplot()
    segs = world.floor.segments
    fig, ax = plt.subplots(figsize=(7, 8))
    walls = world.floor.is_wall if world.floor.is_wall is not None else np.zeros(len(segs), bool)
    for (x0, y0, x1, y1), wall in zip(segs, walls):
        ax.plot([x0, x1], [y0, y1], color="0.1" if wall else "0.45", lw=1.6 if wall else 1.0)
    (x0, y0), (x1, y1) = plan.target_rectangle()
    rect = to_world_frame(np.array([[x0, y0, 0], [x1, y0, 0], [x1, y1, 0], [x0, y1, 0], [x0, y0, 0]]), world.start)
    ax.fill(rect[:, 0], rect[:, 1], color="0.9", zorder=0, label="target area")
    ideal = to_world_frame(ideal_meander(plan), world.start)
    ax.plot(ideal[:, 0], ideal[:, 1], color="0.6", lw=2.5, label="ideal meander")
    cov = np.array([r.fractions["coverage"] for r in results])
    r = results[int(np.argsort(cov)[len(cov) // 2])]
    ax.plot(r.episode.true_pose[:, 0], r.episode.true_pose[:, 1], color="C0", lw=0.8, label=f"run {r.run}")
    ax.plot([world.start.x], [world.start.y], "k>", ms=7, label="start")
    ax.set_aspect("equal")
    ax.set_xlabel("world x (m)")
    ax.set_ylabel("world y (m)")
    ax.set_title("Layout in the world" + (" (guide wall for the first lane)" if world.guide_wall else ""))
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)  # beside the map
    save_figure(fig, path, dpi=110)
