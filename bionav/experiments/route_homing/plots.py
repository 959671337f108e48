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


def plot_errors_per_route(path, table: list[dict], agents: list[str], *, title: str,
                          labels: dict[str, str] | None = None) -> dict[str, np.ndarray]:
    """Boxplots of the errors per route of each agent (Ardin et al. 2016, Fig. 4D), with every run as a dot.

    ``table`` holds the rows of ``errors_per_route.csv`` (one per route and seed, one integer
    column per agent); each box covers all of an agent's runs: median, quartiles and whiskers
    to the extremes (the paper's "maximum and minimum"). Returns the values drawn per agent,
    read back from the dots of the figure (what the tests compare with the CSV). ``labels``
    names the agents on the axis (default: their names).
    """
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(1.1 * len(agents) + 2.2, 3.8))
    data = [np.array([int(r[a]) for r in table], np.int64) for a in agents]
    ax.boxplot(data, whis=(0, 100), widths=0.55, medianprops={"color": "k", "lw": 2})
    jitter = np.random.default_rng(0)  # only spreads the dots sideways
    drawn = {}
    for k, (a, d) in enumerate(zip(agents, data), start=1):
        dots = ax.scatter(k + jitter.uniform(-0.18, 0.18, len(d)), d, s=9, alpha=0.6, zorder=3)
        drawn[a] = np.asarray(dots.get_offsets())[:, 1].astype(np.int64)
    names = [(labels or {}).get(a, a).replace("_", " ") for a in agents]
    ax.set_xticks(range(1, len(agents) + 1), names, rotation=30, ha="right", fontsize=8)
    ax.set_ylabel("errors per route (put-backs)")
    ax.set_title(title, fontsize=9)
    ax.set_ylim(bottom=-0.5)
    save_figure(fig, path, dpi=110)
    return drawn


def plot_robustness(path, summary: list[dict], *, axis: str, unit: str, agents: list[str],
                    categories: list[str] | None = None) -> dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Errors per route (median with interquartile band) and nest arrivals against one robustness axis, per agent.

    ``summary`` holds rows of ``robustness.csv`` for this axis (``agent``, ``level``,
    ``errors_median``, ``errors_q25``, ``errors_q75``, ``reached_nest``). Returns, per agent drawn,
    the levels, medians and nest arrivals (%) read back from the figure's lines (what the tests
    compare with the CSV). With ``categories`` (the ``world`` axis: labels) the levels are those names, drawn at
    x = 0, 1, ... in that order (the levels returned are these positions).
    """
    plt = pyplot()
    fig, (ax_e, ax_n) = plt.subplots(1, 2, figsize=(9.5, 3.6))
    drawn = {}

    def x_of(r):
        return float(categories.index(str(r["level"]))) if categories else float(r["level"])

    style = "o:" if categories else "o-"  # worlds are not a scale: dotted joins

    for a in agents:
        mine = sorted((r for r in summary if r["agent"] == a), key=x_of)
        if not mine:
            continue
        x = np.array([x_of(r) for r in mine])
        med = np.array([float(r["errors_median"]) for r in mine])
        line, = ax_e.plot(x, med, style, ms=4, label=a.replace("_", " "))
        ax_e.fill_between(x, [float(r["errors_q25"]) for r in mine], [float(r["errors_q75"]) for r in mine],
                          color=line.get_color(), alpha=0.15, lw=0)
        nest, = ax_n.plot(x, [100.0 * float(r["reached_nest"]) for r in mine], style, ms=4, color=line.get_color())
        drawn[a] = (np.asarray(line.get_xdata(), float), np.asarray(line.get_ydata(), float),
                    np.asarray(nest.get_ydata(), float))
    ax_e.set_xlabel(f"{axis} ({unit})" if unit else axis)
    ax_n.set_xlabel(f"{axis} ({unit})" if unit else axis)
    if categories:
        for ax in (ax_e, ax_n):
            ax.set_xticks(range(len(categories)), categories, fontsize=8)
    ax_e.set_ylabel("errors per route: median (IQR)")
    ax_n.set_ylabel("routes reaching the nest (%)")
    ax_n.set_ylim(-3, 103)
    ax_e.set_ylim(bottom=-0.3)
    ax_e.legend(fontsize=7, ncol=2)
    fig.suptitle(f"Route following against {axis} (protocol of Ardin et al. 2016)", fontsize=9)
    save_figure(fig, path, dpi=110)
    return drawn
