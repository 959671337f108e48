"""Plots of ``experiment=route_homing``: world from above, headings along a route, heading-error maps."""

from __future__ import annotations

import numpy as np

from bionav.report.figures import pyplot, save_figure


def draw_world(ax, world, *, color="0.15") -> None:
    """The mesh world from above: every triangle filled (x, y in metres); a recorded drive (``db=bag``): where
    its views were taken."""
    from matplotlib.collections import PolyCollection

    if hasattr(world, "mesh"):
        tri = world.mesh.triangles[:, :, :2]
        ax.add_collection(PolyCollection(tri, facecolors=color, edgecolors="none"))
    else:
        ax.plot(world.xy[:, 0], world.xy[:, 1], ".", color="0.8", ms=3, label="recorded views")
    (x0, y0), (x1, y1) = world.extent()
    ax.set_xlim(x0 - 0.2, x1 + 0.2)
    ax.set_ylim(y0 - 0.2, y1 + 0.2)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")


#: colour of the recorded routes in world_routes.png (no method's colour: methods take matplotlib's cycle)
ROUTE_COLOR = "0.55"


def plot_world_routes(path, world, setups, paths) -> None:
    """World from above (x, y in metres) with each recorded route, its snapshots and the agents' paths per method.

    Every line drawn has a legend entry; the legend sits below the axes so it
    covers neither the world nor a path.
    """
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 7.3))
    draw_world(ax, world)
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    methods = sorted({m for (_r, m) in paths})
    for k, s in enumerate(setups):
        ax.plot(s.dense_xy[:, 0], s.dense_xy[:, 1], color=ROUTE_COLOR, lw=2.5,
                label="recorded route" if k == 0 else None)
        ax.plot(s.xy[:, 0], s.xy[:, 1], ".", color="k", ms=2, label="route snapshots" if k == 0 else None)
    for (_r, m), p in paths.items():
        if p is not None:
            c = colors[methods.index(m) % len(colors)]
            ax.plot(p[:, 0], p[:, 1], color=c, lw=1, label=f"agent path: {m}" if _r == setups[0].name else None)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2, fontsize=8, frameon=False)
    ax.set_title(f"{len(setups)} route{'s' if len(setups) != 1 else ''} (grey) with snapshots (black)"
                 + (" and agent paths" if any(p is not None for p in paths.values()) else "")
                 + ("; world from above (dark)" if hasattr(world, "mesh") else "; recorded views (light)"), fontsize=9)
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
