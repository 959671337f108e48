"""Plots of ``experiment=route_homing``: world from above, headings along a route, heading-error maps."""

from __future__ import annotations

import numpy as np

from bionav.report.figures import pyplot, save_figure


def draw_world(ax, world, *, color="0.15") -> None:
    """The mesh world from above: every triangle filled (x, y in metres)."""
    from matplotlib.collections import PolyCollection

    tri = world.mesh.triangles[:, :, :2]
    ax.add_collection(PolyCollection(tri, facecolors=color, edgecolors="none"))
    (x0, y0), (x1, y1) = world.extent()
    ax.set_xlim(x0 - 0.2, x1 + 0.2)
    ax.set_ylim(y0 - 0.2, y1 + 0.2)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")


def plot_world_routes(path, world, setups, paths) -> None:
    """World from above with each route (snapshots) and the agents' paths per method."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 6.5))
    draw_world(ax, world)
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    methods = sorted({m for (_r, m) in paths})
    for s in setups:
        ax.plot(s.dense_xy[:, 0], s.dense_xy[:, 1], color="k", lw=2.5, alpha=0.35)
        ax.plot(s.xy[:, 0], s.xy[:, 1], ".", color="k", ms=2)
    for (_r, m), p in paths.items():
        if p is not None:
            c = colors[methods.index(m) % len(colors)]
            ax.plot(p[:, 0], p[:, 1], color=c, lw=1, label=m if _r == setups[0].name else None)
    if any(p is not None for p in paths.values()):
        ax.legend(loc="upper left", fontsize=8)
    ax.set_title("routes (grey) and agent paths")
    save_figure(fig, path, dpi=110)


def plot_headings(path, setup, results, offsets) -> None:
    """Recorded heading along the route and each method's estimate on the route (offset 0)."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7, 3.2))
    s_along = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(setup.xy, axis=0), axis=1))])
    ax.plot(s_along, np.rad2deg(setup.heading), "k-", lw=1.5, label="recorded")
    zero = list(offsets).index(0.0)
    for m, r in results.items():
        ax.plot(s_along[r["stations"]], np.rad2deg(r["est"][:, zero]), "o", ms=3, label=m)
    ax.set_xlabel("distance along route (m)")
    ax.set_ylabel("heading (deg, CCW from +x)")
    ax.set_title(f"{setup.name}: headings along the route")
    ax.legend(fontsize=8)
    save_figure(fig, path, dpi=110)


def plot_error_maps(path, setup, results, offsets) -> None:
    """Heading error (deg) over route position x lateral offset, one panel per method."""
    plt = pyplot()
    n = len(results)
    fig, axes = plt.subplots(1, n, figsize=(3.4 * n + 1.0, 3.4), squeeze=False, layout="constrained")
    s_along = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(setup.xy, axis=0), axis=1))])
    for ax, (m, r) in zip(axes[0], results.items()):
        st = s_along[r["stations"]]
        im = ax.imshow(np.rad2deg(r["err"]).T, origin="lower", aspect="auto", vmin=0, vmax=180, cmap="viridis",
                       extent=[st[0], st[-1] if len(st) > 1 else st[0] + 1, -0.5, len(offsets) - 0.5])
        ax.set_yticks(range(len(offsets)))
        ax.set_yticklabels([f"{o:g}" for o in offsets])
        ax.set_xlabel("along route (m)")
        ax.set_ylabel("lateral offset (m)")
        ax.set_title(m, fontsize=9)
    fig.colorbar(im, ax=axes[0].tolist(), label="heading error (deg)")
    fig.suptitle(f"{setup.name}: heading error")
    fig.savefig(path, dpi=110)  # constrained layout (save_figure's tight layout fights the shared colour bar)
    plt.close(fig)
