"""``experiment=route_homing db=bag``: a robot's drive from a ROS bag as the route to follow.

The route views are the drive's views every ``db.route_step_m`` of path length and the world the agents
walk in is the drive's recorded views (:func:`bionav.db.bag.route.load_bag_route`): at any pose an agent
sees the recorded view nearest to it, turned to its heading. It is followed with the published protocol
(``experiment.protocol=ardin2016``: put back on the route beyond ``putback_m``, so the agents stay where
views were recorded; the ``bionav`` protocol, which measures views beside the route, is refused); the
scans of the familiarity agents are
cut from that view resampled to columns of ``experiment.scan_step_deg`` (area averages centred on the
columns' azimuths; rows: the camera's own, resized to ``experiment.view_size`` as the paper's).
"""

from __future__ import annotations

import math

import numpy as np
from omegaconf import DictConfig, OmegaConf

from bionav.errors import UserError


def is_bag(cfg: DictConfig) -> bool:
    """Whether the run's database is a ROS bag (``db=bag``)."""
    return OmegaConf.select(cfg, "db.source", default=None) == "bag"


def bag_route_setup(cfg: DictConfig, setup_cls):
    """The route setup (``setup_cls``, route_homing's ``_RouteSetup``) of the bag's drive."""
    from bionav.db.bag.route import load_bag_route
    from bionav.db.loading import as_database_config

    route = load_bag_route(as_database_config(OmegaConf.to_container(cfg.db, resolve=True)))
    db = route.db
    return setup_cls(route.name, route.world, db, np.asarray(db.meta["world_xy"]), np.asarray(db.headings),
                     route.dense_xy, 0.0, db.geometry, 0.0)


def check_routes(exp) -> None:
    """With a bag the route is its drive (``experiment.routes``, Seville routes, must stay empty), followed by the
    published protocol: the ``bionav`` protocol starts beside the route and measures views off it, which a
    recorded drive does not hold (the nearest recorded view would stand for them)."""
    if exp.protocol != "ardin2016":
        raise UserError("with db=bag follow the drive with the published protocol: experiment.protocol=ardin2016 (the "
                        "bionav protocol tests views beside the route, and a recorded drive has views only along it).")
    if exp.routes:
        raise UserError(f"experiment.routes={list(exp.routes)} names routes of the Seville world, but with db=bag the "
                        "route is the bag's drive (db.image_topic, db.pose_topic); drop experiment.routes.")


def recorded_renderer(setup):
    """``render(xy, heading)``: the recorded view nearest to ``xy`` turned to ``heading``."""
    return setup.world.render


def recorded_scan_renderer(setup, exp, *, half_deg=None):
    """``views(xy, heading) -> (views (S, h, w), offsets (S,))``: the scan views of the familiarity agents."""
    from bionav.evaluation.route import scan_views
    from bionav.homing.imageops import resize_images

    col = float(exp.scan_step_deg)
    columns = int(round(360.0 / col))
    half = exp.scan_half_deg if half_deg is None else half_deg
    width = setup.world.images.shape[-1]
    # area averages of columns j*s .. (j+1)*s - 1 are centred 0.5*col - 0.5*(360/width) deg after the render heading
    centre = math.radians(0.5 * col - 0.5 * 360.0 / width)

    def views(xy, heading):
        pano = setup.world.render(xy, heading - centre)
        img = resize_images(pano[None], (columns, pano.shape[0]))[0]
        return scan_views(img, column_deg=col, scan_half_deg=half, scan_step_deg=col, size=exp.view_size)

    return views
