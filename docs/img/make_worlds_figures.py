"""Regenerate the pictures of docs/worlds.md: python docs/img/make_worlds_figures.py (from the checkout root)."""

from pathlib import Path

import numpy as np

from bionav.config import compose
from bionav.db.mesh import load_route, mesh_world, seville_world_path
from bionav.experiments.common import load_configured_database
from bionav.experiments.route_homing.plots import draw_world
from bionav.geometry import PanoramaGeometry
from bionav.report.figures import pyplot, save_figure
from bionav.world.mesh_render import render_mesh_panorama

OUT = Path(__file__).resolve().parent
plt = pyplot()
world = mesh_world(seville_world_path())
db = load_configured_database(compose(["db=sim_seville"]))
route = load_route("Ant1_Route1")

fig, ax = plt.subplots(figsize=(4.2, 4.2))
draw_world(ax, world)
for name in ("Ant1_Route1", "Ant2_Route1", "Ant5_Route1", "Ant7_Route1", "Ant12_Route3"):
    r = load_route(name)
    ax.plot(r.xy[:, 0], r.xy[:, 1], lw=1, label=name)
xy = np.asarray(db.meta["world_xy"])
ax.plot(xy[:, 0], xy[:, 1], "s", ms=1.5, color="tab:red", label="sim_seville grid")
ax.plot(*route.xy[0], "k^", ms=5)
ax.plot(*route.xy[-1], "ko", ms=5)
ax.legend(fontsize=6, loc="upper left")
ax.set_title("Seville 2009 ant world from above", fontsize=9)
save_figure(fig, OUT / "seville_world.png", dpi=90)

g = PanoramaGeometry.square_pixels(561, 81)
fig, axes = plt.subplots(2, 1, figsize=(6.5, 2.2))
for ax, (h, label) in zip(axes, [(0.01, "ant eye, 1 cm"), (0.2, "robot, 20 cm")]):
    img = render_mesh_panorama(world, position=(*route.xy[0], h), heading=float(route.heading[0]), geometry=g)
    ax.imshow(img[..., 0], cmap="gray", vmin=0, vmax=1)
    ax.set_axis_off()
    ax.set_title(f"Ant1_Route1 start, heading {np.rad2deg(route.heading[0]):.0f} deg, {label}", fontsize=7)
save_figure(fig, OUT / "seville_views.png", dpi=110)

fig, ax = plt.subplots(figsize=(3.0, 5.5))
draw_world(ax, world, color="0.6")
step = route.resample(0.25)
ax.plot(route.xy[:, 0], route.xy[:, 1], color="tab:blue", lw=0.8)
ax.quiver(step.xy[:, 0], step.xy[:, 1], np.cos(step.heading), np.sin(step.heading), angles="xy",
          scale_units="xy", scale=4.0, width=0.012, color="k")
ax.set_xlim(4.2, 7.2)
ax.set_ylim(0.8, 8.8)
ax.set_title("Ant1_Route1: recorded headings every 0.25 m", fontsize=8)
save_figure(fig, OUT / "seville_route.png", dpi=90)
