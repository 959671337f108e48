"""2-D floor plan of a world: obstacle outlines for collisions and range sensors.

Obstacles are stored as line segments (metres, world frame). Room shells,
boxes standing on the floor and cylinders become segments; anything whose
underside is above the robot (a table top) is not an obstacle, its legs are.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class FloorPlan:
    """Obstacle outlines.

    Parameters
    ----------
    segments : ndarray, shape (M, 4)
        ``(x0, y0, x1, y1)`` per segment, metres.
    is_wall : ndarray of bool, shape (M,), optional
        True for segments of room walls (candidates for wall following).
    """

    segments: np.ndarray
    is_wall: np.ndarray | None = None

    @classmethod
    def from_shapes(cls, *, rooms=(), boxes=(), discs=(), n_disc_sides: int = 16) -> "FloorPlan":
        """Build a floor plan from simple shapes.

        Parameters
        ----------
        rooms : sequence of ((x0, y0), (x1, y1))
            Axis-aligned room outlines (walls seen from inside).
        boxes : sequence of ((cx, cy), (hx, hy), yaw)
            Rectangular footprints: centre, half extents (m), yaw (rad CCW).
        discs : sequence of ((cx, cy), r)
            Round footprints, approximated by regular polygons.
        n_disc_sides : int
            Polygon sides per disc.
        """
        segs = []
        for lo, hi in rooms:
            segs += _polygon_segments(np.array([[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]]))
        n_walls = len(segs)
        for (cx, cy), (hx, hy), yaw in boxes:
            c, s = np.cos(yaw), np.sin(yaw)
            corners = np.array([[-hx, -hy], [hx, -hy], [hx, hy], [-hx, hy]])
            pts = corners @ np.array([[c, s], [-s, c]]) + np.array([cx, cy])
            segs += _polygon_segments(pts)
        for (cx, cy), r in discs:
            a = np.linspace(0.0, 2 * np.pi, n_disc_sides, endpoint=False)
            # circumscribed polygon so that the disc lies inside
            rr = r / np.cos(np.pi / n_disc_sides)
            segs += _polygon_segments(np.stack([cx + rr * np.cos(a), cy + rr * np.sin(a)], axis=1))
        arr = np.array(segs, dtype=np.float64).reshape(-1, 4)
        is_wall = np.zeros(len(arr), dtype=bool)
        is_wall[:n_walls] = True
        return cls(arr, is_wall)

    def clearance(self, x: float, y: float) -> float:
        """Distance (m) from the point ``(x, y)`` to the nearest obstacle outline (``inf`` if none)."""
        if len(self.segments) == 0:
            return float("inf")
        s = self.segments
        ax, ay = s[:, 0], s[:, 1]
        dx, dy = s[:, 2] - ax, s[:, 3] - ay
        L2 = dx * dx + dy * dy
        t = np.clip(((x - ax) * dx + (y - ay) * dy) / np.where(L2 > 0, L2, 1.0), 0.0, 1.0)
        return float(np.min(np.hypot(ax + t * dx - x, ay + t * dy - y)))

    def raycast(self, x: float, y: float, angle: float, *, max_range: float = np.inf) -> float:
        """Distance (m) along the ray from ``(x, y)`` in direction ``angle`` (rad CCW) to the first outline.

        Returns ``inf`` when nothing is hit within ``max_range``.
        """
        if len(self.segments) == 0:
            return float("inf")
        s = self.segments
        ux, uy = np.cos(angle), np.sin(angle)
        ax, ay = s[:, 0] - x, s[:, 1] - y
        ex, ey = s[:, 2] - s[:, 0], s[:, 3] - s[:, 1]
        den = ux * ey - uy * ex
        ok = np.abs(den) > 1e-12
        den = np.where(ok, den, 1.0)
        t = (ax * ey - ay * ex) / den  # along the ray
        u = (ax * uy - ay * ux) / den  # along the segment
        hit = ok & (t >= 0) & (u >= 0) & (u <= 1)
        if not np.any(hit):
            return float("inf")
        d = float(np.min(t[hit]))
        return d if d <= max_range else float("inf")


    def enclosed(self, x: float, y: float, *, n_rays: int = 8, max_range: float = 50.0) -> bool:
        """True when rays from ``(x, y)`` in ``n_rays`` directions all hit an outline (inside a room)."""
        return all(np.isfinite(self.raycast(x, y, a, max_range=max_range))
                   for a in np.linspace(0.0, 2 * np.pi, n_rays, endpoint=False))


def _polygon_segments(pts: np.ndarray) -> list:
    n = len(pts)
    return [(pts[i, 0], pts[i, 1], pts[(i + 1) % n, 0], pts[(i + 1) % n, 1]) for i in range(n)]


def floorplan_from_scene(scene, *, max_height: float = 0.35, min_height: float = 0.01) -> FloorPlan:
    """Obstacle outlines of a :class:`bionav.world.scene.Scene` for a robot ``max_height`` metres tall.

    Room shells (boxes rendered from inside) become walls; boxes, vertical
    cylinders/cones and ellipsoids whose underside is below ``max_height`` and
    whose top is above ``min_height`` (not a floor decal) become footprints:
    rotated rectangles for boxes, discs of the larger radius for the others.
    A table top is no obstacle, its legs are.

    Parameters
    ----------
    scene : Scene
        The world (its ``boxes``, ``frusta`` and ``ellipsoids`` lists).
    max_height, min_height : float
        Height band (m) in which parts of the world block the robot.
    """
    boxes, discs = [], []
    wall_segments = []
    for b in scene.boxes:
        cx, cy, cz, hx, hy, hz, c, s, inside = (float(v) for v in b[:9])
        yaw = float(np.arctan2(s, c))
        if inside:
            corners = np.array([[-hx, -hy], [hx, -hy], [hx, hy], [-hx, hy]])
            pts = corners @ np.array([[c, s], [-s, c]]) + np.array([cx, cy])
            wall_segments += _polygon_segments(pts)
            continue
        if cz - hz < max_height and cz + hz > min_height:
            boxes.append(((cx, cy), (hx, hy), yaw))
    for f in scene.frusta:
        cx, cy, z0, z1, r0, r1 = (float(v) for v in f[:6])
        if z0 < max_height and z1 > min_height:
            # the largest radius within the blocking height band
            zt = min(z1, max_height)
            r = max(r0, r0 + (r1 - r0) * (zt - z0) / (z1 - z0))
            discs.append(((cx, cy), r))
    for e in scene.ellipsoids:
        cx, cy, cz, rx, ry, rz = (float(v) for v in e[:6])
        if cz - rz < max_height and cz + rz > min_height:
            discs.append(((cx, cy), max(rx, ry)))
    inner = FloorPlan.from_shapes(boxes=boxes, discs=discs)
    walls = np.array(wall_segments, dtype=np.float64).reshape(-1, 4)
    segs = np.concatenate([walls, inner.segments])
    is_wall = np.zeros(len(segs), dtype=bool)
    is_wall[: len(walls)] = True
    return FloorPlan(segs, is_wall)
