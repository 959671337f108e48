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
    """

    segments: np.ndarray

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
        return cls(arr)

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


def _polygon_segments(pts: np.ndarray) -> list:
    n = len(pts)
    return [(pts[i, 0], pts[i, 1], pts[(i + 1) % n, 0], pts[(i + 1) % n, 1]) for i in range(n)]
