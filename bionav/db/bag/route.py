"""A robot's drive as a route: route views every ``db.route_step_m``, and its recorded views as the world.

:func:`load_bag_route` reads every image of ``db.image_topic`` that the poses
cover (:mod:`bionav.db.bag.views`), in stamp order, as canonical panoramas in
the robot's frame (column 0 along its heading at the stamp; ``db.azimuth``,
``db.x_axis_column``, ``db.unfold`` as for any database), resized to
``db.image_size`` when given. The route views are the first view at or after
each multiple of ``db.route_step_m`` of path length along the drive (the path
through the views' positions), the last view included; their headings are the
robot's.

A route follower needs the view at any pose it walks to. In a recorded drive
the only views are the recorded ones, so :class:`RecordedViews` answers
``render(xy, heading)`` with the recorded view nearest to ``xy`` (Euclidean;
ties: the earlier), turned to ``heading`` (cyclic column shift with linear
interpolation, :func:`bionav.db.conventions.to_canonical`): the image
database as the world, the rule the grid return agent uses for the nearest
existing cell. Every recorded view is a candidate, not only the route views,
so a follower between two route views sees the view taken there.

Conventions: positions in metres in the world frame of the poses, headings
radians CCW from world +x.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from bionav.db.bag.grid import decode_all, view_geometry
from bionav.db.bag.reader import open_bag
from bionav.db.bag.views import index_views
from bionav.db.conventions import to_canonical
from bionav.db.database import ImageDatabase
from bionav.errors import UserError
from bionav.geometry import TWO_PI

#: most recorded views a route world holds
MAX_ROUTE_VIEWS = 50_000


def route_stations(xy: np.ndarray, step_m: float) -> np.ndarray:
    """Indices of the route views: the first view at or after each multiple of ``step_m`` of path length.

    Parameters
    ----------
    xy : ndarray, shape (N, 2)
        The drive's view positions in stamp order, metres.
    step_m : float

    Returns
    -------
    ndarray, shape (K,), int
        Increasing indices; the first view always, the last view always.
    """
    xy = np.asarray(xy, np.float64)
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(xy, axis=0), axis=1))])
    targets = np.arange(0.0, s[-1] + 1e-12, step_m)
    idx = np.unique(np.minimum(np.searchsorted(s, targets - 1e-12, side="left"), len(s) - 1))
    if idx[-1] != len(s) - 1:
        idx = np.append(idx, len(s) - 1)
    return idx


@dataclass
class RecordedViews:
    """The recorded views of a drive as a view source: :meth:`render` ``(xy, heading) -> panorama``.

    Attributes
    ----------
    images : ndarray, shape (N, H, W), float32
        Canonical panoramas, column 0 along ``yaw``.
    xy : ndarray, shape (N, 2)
        Where each was taken, metres.
    yaw : ndarray, shape (N,)
        The robot's heading at each, radians CCW from world +x.
    """

    images: np.ndarray
    xy: np.ndarray
    yaw: np.ndarray

    def nearest(self, xy) -> int:
        """The recorded view nearest to ``xy`` (ties: the earlier)."""
        d = np.sum((self.xy - np.asarray(xy, np.float64)[None, :2]) ** 2, axis=1)
        return int(np.argmin(d))

    def render(self, xy, heading: float) -> np.ndarray:
        """The nearest recorded view turned to ``heading``: column 0 looks along ``heading`` (see the module)."""
        k = self.nearest(xy)
        width = self.images.shape[-1]
        shift = (float(heading) - float(self.yaw[k])) * width / TWO_PI
        whole = round(shift)
        shift = whole if abs(shift - whole) < 1e-9 else shift
        return to_canonical(self.images[k], azimuth="counterclockwise", x_axis_column=shift)

    def extent(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """``((xmin, ymin), (xmax, ymax))`` of the views, metres."""
        lo, hi = self.xy.min(axis=0), self.xy.max(axis=0)
        return (float(lo[0]), float(lo[1])), (float(hi[0]), float(hi[1]))


@dataclass
class BagRoute:
    """A drive read as a route (:func:`load_bag_route`).

    Attributes
    ----------
    name : str
        The bag's name and the image topic, ``/`` as ``_`` (``drive_camera_image``; names plot files).
    db : ImageDatabase
        The route views (positions ``(k, 0)``, grid ``(K, 1)``, spacing ``db.route_step_m``,
        headings the robot's; ``meta["world_xy"]`` in metres).
    world : RecordedViews
        Every recorded view, the followers' view source.
    dense_xy : ndarray, shape (N, 2)
        The whole drive (every view position), metres.
    """

    name: str
    db: ImageDatabase
    world: RecordedViews
    dense_xy: np.ndarray

    @property
    def length_m(self) -> float:
        return float(np.linalg.norm(np.diff(self.dense_xy, axis=0), axis=1).sum())


def load_bag_route(cfg) -> BagRoute:
    """The drive of ``db=bag`` as a route (see the module docstring).

    Raises
    ------
    UserError
        Everything :func:`~bionav.db.bag.views.index_views` refuses; fewer than 2 route views.
    """
    from pathlib import Path

    with open_bag(cfg.path, key="db.path") as bag:
        views = index_views(bag, cfg)
        n = len(views.index)
        if n > MAX_ROUTE_VIEWS:
            raise UserError(f"{views.topic.name} has {n} views with poses, more than the {MAX_ROUTE_VIEWS} a route "
                            "world holds; cut the bag to the drive you want to follow (rosbags-convert with a time "
                            "range).")
        kept, images, native = decode_all(bag, views, np.arange(n), cfg, align=False, size=cfg.image_size)
        if len(kept) != n:
            raise UserError(f"{views.topic.name}: a route needs every view of the drive; {n - len(kept)} could not "
                            "be used (see the warnings above).")
    stations = route_stations(views.xy, cfg.route_step_m)
    if len(stations) < 2:
        raise UserError(f"the drive of {views.topic.name} is {float(np.ptp(views.xy, axis=0).max()):.3f} m long: "
                        f"fewer than 2 route views at db.route_step_m={cfg.route_step_m:g}; give a smaller step.")
    geometry = view_geometry(cfg, *native).resized(images.shape[-1], images.shape[-2])
    name = Path(str(cfg.path)).stem + re.sub(r"[^A-Za-z0-9_.-]+", "_", views.topic.name)  # a file-name part
    k = len(stations)
    meta = {"source": "bag", "kind": "route", "path": str(cfg.path), "image_topic": views.topic.name,
            "pose_topic": views.pose_topic, "world_frame": views.world_frame, "step_m": cfg.route_step_m,
            "world_xy": views.xy[stations].tolist(), "stamps_ns": views.stamp_ns[stations].tolist(),
            "n_views": len(views.index), "n_uncovered": views.n_uncovered}
    db = ImageDatabase(name=f"{cfg.name}:{name}", images=images[stations],
                       positions=np.column_stack([np.arange(k), np.zeros(k, np.int64)]), grid_shape=(k, 1),
                       geometry=geometry, spacing_m=float(cfg.route_step_m), headings=views.yaw[stations].copy(),
                       meta=meta)
    return BagRoute(name, db, RecordedViews(images, views.xy.copy(), views.yaw.copy()), views.xy.copy())

