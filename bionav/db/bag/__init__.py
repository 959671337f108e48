"""ROS bags as image databases and routes (``db=bag``; docs/ros.md).

* :mod:`~bionav.db.bag.reader`: opening a ROS 1 / ROS 2 bag with ``rosbags`` and
  streaming its messages, with one clear message for every bad bag;
* :mod:`~bionav.db.bag.images`: image messages as grey float images (the decoding of
  ``db=folder``'s files);
* :mod:`~bionav.db.bag.poses`: odometry, pose and tf topics as a planar pose track
  interpolated to any stamp;
* :mod:`~bionav.db.bag.views`: the stamps and poses of every image, then only the
  images needed, decoded;
* :mod:`~bionav.db.bag.grid`: the grid database (:func:`load_bag_database`);
* :mod:`~bionav.db.bag.route`: the drive as a route and its recorded views as the
  world a route follower walks in (:func:`load_bag_route`).

Needs the ``rosbags`` package (``pip install "bionav[ros]"``).
"""

from __future__ import annotations

__all__ = ["load_bag_database", "load_bag_route"]


def __getattr__(name: str):
    if name == "load_bag_database":
        from bionav.db.bag.grid import load_bag_database

        return load_bag_database
    if name == "load_bag_route":
        from bionav.db.bag.route import load_bag_route

        return load_bag_route
    raise AttributeError(f"module 'bionav.db.bag' has no attribute {name!r}")
