"""A tiny analytic test world: a box room with textured walls and pillars.

Panoramas are ray-cast exactly (no renderer library), so tests can place a
camera at a known position and heading and know the true home direction and
rotation. The room spans ``[-3, 3] x [-2, 2]`` metres with a 2.5 m ceiling;
cylindrical pillars of different heights stand inside; walls and pillars carry
smooth random blob textures (posters), so both holistic methods (edges along
columns) and SIFT (blobs at many scales) find structure.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.geometry import PanoramaGeometry

ROOM_X = 3.0
ROOM_Y = 2.0
ROOM_H = 2.5


@dataclass(frozen=True)
class Pillar:
    """A vertical cylinder standing on the floor (metres)."""

    x: float
    y: float
    radius: float
    height: float


DEFAULT_PILLARS = (
    Pillar(1.4, 0.9, 0.22, 1.6),
    Pillar(-1.2, 1.1, 0.3, 1.1),
    Pillar(-1.6, -0.9, 0.18, 2.0),
    Pillar(0.9, -1.2, 0.25, 0.8),
    Pillar(2.2, -0.2, 0.15, 1.3),
    Pillar(-0.3, 1.5, 0.12, 0.6),
)


def _blobs(rng, n, s_range, z_range):
    return np.stack(
        [
            rng.uniform(*s_range, n),
            rng.uniform(*z_range, n),
            np.exp(rng.uniform(np.log(0.03), np.log(0.25), n)),
            rng.uniform(-0.45, 0.45, n),
        ],
        axis=1,
    )


def _texture(s, z, blobs, base):
    out = np.full(s.shape, base, dtype=np.float64)
    for bs, bz, br, ba in blobs:
        out += ba * np.exp(-((s - bs) ** 2 + (z - bz) ** 2) / (2.0 * br * br))
    return out


def render_pillar_panorama(
    position,
    *,
    heading: float = 0.0,
    width: int = 288,
    height: int = 50,
    camera_height: float = 0.6,
    pillars=DEFAULT_PILLARS,
    seed: int = 0,
    supersample: int = 3,
):
    """Ray-cast a canonical panorama of the pillar room.

    Parameters
    ----------
    position : sequence of two floats
        Camera position ``(x, y)`` in metres (room frame, inside the room).
    heading : float
        Robot heading, radians CCW from +x; column 0 looks along it.
    width, height : int
        Panorama size; pixels are square (``2 pi / width`` radians) and the
        horizon lies in the middle row.
    camera_height : float
        Camera height above the floor in metres.
    pillars : sequence of Pillar
    seed : int
        Seed of the textures (the world, not the view).
    supersample : int
        Rays per pixel along each axis (area anti-aliasing).

    Returns
    -------
    image : ndarray, shape (height, width), float32 in [0, 1]
    geometry : PanoramaGeometry
    """
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        return _render(position, heading, width, height, camera_height, pillars, seed, supersample)


def _render(position, heading, width, height, camera_height, pillars, seed, supersample):
    geometry = PanoramaGeometry.square_pixels(width, height)
    rng = np.random.default_rng(seed)
    perimeter = 2.0 * (2 * ROOM_X + 2 * ROOM_Y)
    wall_blobs = _blobs(rng, 160, (0.0, perimeter), (0.0, ROOM_H))
    pillar_blobs = [_blobs(rng, 14, (0.0, 2 * np.pi * p.radius), (0.0, p.height)) for p in pillars]
    pillar_base = rng.uniform(0.25, 0.75, len(pillars))

    n = supersample
    cols = (np.arange(width * n) + 0.5) / n - 0.5
    rows = (np.arange(height * n) + 0.5) / n - 0.5
    az = heading + cols * geometry.rad_per_column
    el = (geometry.horizon_row - rows) * geometry.rad_per_row
    dx, dy = np.cos(az)[None, :], np.sin(az)[None, :]
    tan_e = np.tan(el)[:, None]
    px, py = float(position[0]), float(position[1])
    shape = (rows.size, cols.size)

    # walls (horizontal distance to the rectangle along each azimuth)
    with np.errstate(divide="ignore", invalid="ignore"):
        tx = np.where(dx > 0, (ROOM_X - px) / dx, np.where(dx < 0, (-ROOM_X - px) / dx, np.inf))
        ty = np.where(dy > 0, (ROOM_Y - py) / dy, np.where(dy < 0, (-ROOM_Y - py) / dy, np.inf))
    t_wall = np.minimum(tx, ty)
    hx, hy = px + t_wall * dx, py + t_wall * dy
    # arc-length coordinate along the walls, counter-clockwise from (X, -Y)
    s_wall = np.where(
        tx <= ty,
        np.where(dx > 0, hy + ROOM_Y, 2 * ROOM_Y + 2 * ROOM_X + (ROOM_Y - hy)),
        np.where(dy > 0, 2 * ROOM_Y + (ROOM_X - hx), 2 * ROOM_Y + 2 * ROOM_X + 2 * ROOM_Y + (hx + ROOM_X)),
    )
    z_wall = camera_height + t_wall * tan_e
    dist = np.broadcast_to(t_wall, shape).copy()
    value = _texture(np.broadcast_to(s_wall, shape), z_wall, wall_blobs, 0.5)
    # floor and ceiling
    with np.errstate(divide="ignore"):
        t_floor = np.broadcast_to(np.where(tan_e < 0, -camera_height / tan_e, np.inf), shape)
        t_ceil = np.broadcast_to(np.where(tan_e > 0, (ROOM_H - camera_height) / tan_e, np.inf), shape)
    floor_hit = t_floor < dist
    fx, fy = px + t_floor * dx, py + t_floor * dy
    floor_val = 0.35 + 0.12 * np.sin(2 * np.pi * fx / 0.9) * np.sin(2 * np.pi * fy / 0.7)
    value = np.where(floor_hit, floor_val, value)
    dist = np.where(floor_hit, t_floor, dist)
    ceil_hit = t_ceil < dist
    value = np.where(ceil_hit, 0.85, value)
    dist = np.where(ceil_hit, t_ceil, dist)
    # pillars
    for p, blobs, base in zip(pillars, pillar_blobs, pillar_base):
        ox, oy = px - p.x, py - p.y
        b = ox * dx + oy * dy
        c = ox * ox + oy * oy - p.radius**2
        disc = b * b - c
        with np.errstate(invalid="ignore"):
            t = -b - np.sqrt(disc)
        t = np.where((disc > 0) & (t > 0), t, np.inf)
        z = camera_height + t * tan_e
        hit = (z >= 0.0) & (z <= p.height) & (t < dist)
        ang = np.arctan2(py + t * dy - p.y, px + t * dx - p.x)
        s = np.broadcast_to((ang % (2 * np.pi)) * p.radius, shape)
        val = _texture(s, z, blobs, base)
        value = np.where(hit, val, value)
        dist = np.where(hit, t, dist)
        # the pillar's flat top, seen from above
        t_top = np.where(tan_e < 0, (p.height - camera_height) / np.where(tan_e < 0, tan_e, -1.0), np.inf)
        tx_, ty_ = px + t_top * dx - p.x, py + t_top * dy - p.y
        top = (tx_ * tx_ + ty_ * ty_ <= p.radius**2) & (t_top > 0) & (t_top < dist)
        value = np.where(top, base * 0.6, value)
        dist = np.where(top, t_top, dist)
    img = np.clip(value, 0.0, 1.0).reshape(height, n, width, n).mean(axis=(1, 3))
    return img.astype(np.float32), geometry
