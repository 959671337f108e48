"""Reusable objects built from primitives: tables, chairs, shelves, plants, trees, buildings.

Every function adds primitives to a :class:`~bionav.world.scene.Scene` and
draws its randomness from the Generator it is given. Positions are metres in
the world frame; ``yaw`` is radians CCW about ``+z``.
"""

from __future__ import annotations

import numpy as np

from bionav.world import textures as tx
from bionav.world.scene import Scene


def _rot(x, y, yaw):
    c, s = np.cos(yaw), np.sin(yaw)
    return c * x - s * y, s * x + c * y


def oriented_box(scene: Scene, centre, size, material, *, yaw: float = 0.0, shadow: bool = True) -> int:
    """Box of full ``size`` ``(sx, sy, sz)`` whose bottom centre is ``centre`` ``(x, y, z0)``."""
    cx, cy, z0 = centre
    sx, sy, sz = size
    return scene.box((cx - sx / 2, cy - sy / 2, z0), (cx + sx / 2, cy + sy / 2, z0 + sz), material, yaw=yaw,
                     shadow=shadow)


def table(scene: Scene, rng: np.random.Generator, *, x0: float, y0: float, x1: float, y1: float,
          height: float = 0.74, top_thickness: float = 0.03, leg: float = 0.05, top_material: int | None = None,
          leg_material: int | None = None, apron: bool = True) -> None:
    """A table: a top slab on four legs (a camera lower than the top can stand underneath)."""
    if top_material is None:
        top_material = scene.material(texture=tx.wood(rng), albedo=rng.uniform(0.5, 0.8), scale=1.2)
    if leg_material is None:
        leg_material = scene.material(albedo=rng.uniform(0.2, 0.4))
    scene.box((x0, y0, height - top_thickness), (x1, y1, height), top_material)
    for lx, ly in ((x0, y0), (x1 - leg, y0), (x0, y1 - leg), (x1 - leg, y1 - leg)):
        scene.box((lx, ly, 0.0), (lx + leg, ly + leg, height - top_thickness), leg_material)
    if apron:  # a frame below the top along the long sides
        a = 0.08
        scene.box((x0 + leg, y0, height - top_thickness - a), (x1 - leg, y0 + 0.02, height - top_thickness),
                  leg_material)
        scene.box((x0 + leg, y1 - 0.02, height - top_thickness - a), (x1 - leg, y1, height - top_thickness),
                  leg_material)


def chair(scene: Scene, rng: np.random.Generator, *, x: float, y: float, yaw: float,
          material: int | None = None, frame: int | None = None) -> None:
    """An office chair: star base on a column, seat, backrest (facing ``yaw``)."""
    if material is None:
        material = scene.material(texture=tx.carpet(rng, lo=0.1, hi=0.45), albedo=rng.uniform(0.4, 0.9),
                                  scale=0.3)
    if frame is None:
        frame = scene.material(albedo=rng.uniform(0.1, 0.3))
    for k in range(5):
        a = yaw + 2 * np.pi * k / 5
        dx, dy = 0.22 * np.cos(a), 0.22 * np.sin(a)
        oriented_box(scene, (x + dx / 2, y + dy / 2, 0.04), (0.3, 0.04, 0.04), frame, yaw=a)
    scene.cylinder((x, y), 0.04, 0.45, 0.025, material=frame)
    oriented_box(scene, (x, y, 0.45), (0.46, 0.46, 0.07), material, yaw=yaw)
    bx, by = _rot(-0.21, 0.0, yaw)
    oriented_box(scene, (x + bx, y + by, 0.55), (0.05, 0.42, 0.45), material, yaw=yaw)
    oriented_box(scene, (x + bx * 0.9, y + by * 0.9, 0.45), (0.03, 0.05, 0.12), frame, yaw=yaw)


def shelf(scene: Scene, rng: np.random.Generator, *, x0: float, y0: float, x1: float, y1: float, height: float,
          facing: str, shelves: int = 5) -> None:
    """A bookshelf against a wall; ``facing`` is the side showing the books (``+x -x +y -y``)."""
    books = scene.material(texture=tx.bookshelf(rng, shelves=shelves), fit=True, albedo=0.9)
    side = scene.material(texture=tx.wood(rng), albedo=rng.uniform(0.45, 0.7), scale=1.0)
    faces = [side] * 6
    faces[{"-x": 0, "+x": 1, "-y": 2, "+y": 3}[facing]] = books
    scene.box((x0, y0, 0.0), (x1, y1, height), faces)


def cabinet(scene: Scene, rng: np.random.Generator, *, x0: float, y0: float, x1: float, y1: float, height: float,
            facing: str, doors: tuple[int, int] = (2, 2), albedo: float | None = None) -> None:
    """A cabinet with panelled doors on the ``facing`` side."""
    alb = rng.uniform(0.45, 0.85) if albedo is None else albedo
    front = scene.material(texture=tx.panel(rng, nx=doors[0], ny=doors[1]), fit=True, albedo=alb)
    side = scene.material(texture=tx.plaster(rng, lo=0.6, hi=0.75), albedo=alb, scale=1.0)
    faces = [side] * 6
    faces[{"-x": 0, "+x": 1, "-y": 2, "+y": 3}[facing]] = front
    scene.box((x0, y0, 0.0), (x1, y1, height), faces)


def wall_picture(scene: Scene, rng: np.random.Generator, *, wall: str, position: float, z0: float, z1: float,
                 width: float, room: tuple[float, float], depth: float = 0.02, material: int | None = None) -> None:
    """A poster/picture/board on a room wall.

    ``wall`` is ``west`` (x = 0), ``east`` (x = room[0]), ``south`` (y = 0) or
    ``north`` (y = room[1]); ``position`` is the centre along the wall.
    """
    if material is None:
        material = scene.material(texture=tx.poster(rng), fit=True, albedo=rng.uniform(0.7, 1.0))
    lx, ly = room
    h = width / 2
    if wall == "west":
        lo, hi = (0.0, position - h, z0), (depth, position + h, z1)
    elif wall == "east":
        lo, hi = (lx - depth, position - h, z0), (lx, position + h, z1)
    elif wall == "south":
        lo, hi = (position - h, 0.0, z0), (position + h, depth, z1)
    elif wall == "north":
        lo, hi = (position - h, ly - depth, z0), (position + h, ly, z1)
    else:
        raise ValueError(f"unknown wall {wall!r}")
    scene.box(lo, hi, material, shadow=False)


def potted_plant(scene: Scene, rng: np.random.Generator, *, x: float, y: float, height: float = 1.6,
                 crown: float = 0.35, min_leaf_z: float = 0.75, leaf_glow: float = 0.12) -> None:
    """An arboreal plant: pot, stem and clumps of foliage (none below ``min_leaf_z``).

    ``leaf_glow`` is the radiance the translucent leaves pass on from the room light behind them
    (an emission term; scale it with the room's light level, e.g. small in a dark hall).
    """
    pot = scene.material(texture=tx.value_noise(rng, lo=0.35, hi=0.6), albedo=0.6, scale=0.3)
    soil = scene.material(texture=tx.carpet(rng, lo=0.05, hi=0.2), albedo=0.5, scale=0.2)
    leaves = scene.material(texture=tx.foliage(rng), albedo=0.8, emission=leaf_glow, scale=0.25,  # leaves are translucent
                            kind="foliage")
    stem = scene.material(texture=tx.bark(rng), albedo=0.4, scale=0.2, kind="bark")
    scene.frustum((x, y), 0.0, 0.35, 0.12, 0.16, material=pot, top=soil)
    scene.cylinder((x, y), 0.35, height * 0.8, 0.02, material=stem)
    n = 14
    for k in range(n):
        rad = crown * rng.uniform(0.35, 0.6)
        rz = rad * rng.uniform(0.6, 0.9)
        lo = min_leaf_z + rz
        z = lo + (height - rz - lo) * (k + rng.uniform(0.0, 1.0)) / n
        a = rng.uniform(0, 2 * np.pi)
        r = crown * rng.uniform(0.1, 0.8) * (1.0 - 0.5 * (z - lo) / max(height - lo, 1e-6))
        scene.ellipsoid((x + r * np.cos(a), y + r * np.sin(a), z), (rad, rad, rz), material=leaves)


def tree(scene: Scene, rng: np.random.Generator, *, x: float, y: float, height: float, crown: float,
         conifer: bool = False, bark_mat: int | None = None, leaf_mat: int | None = None) -> None:
    """A tree: trunk plus either a spheroidal crown (with a few sub-clumps) or a cone (conifer)."""
    if bark_mat is None:
        bark_mat = scene.material(texture=tx.bark(rng), albedo=0.35, scale=0.8, kind="bark")
    if leaf_mat is None:
        leaf_mat = scene.material(texture=tx.foliage(rng), albedo=0.4, scale=1.5, kind="foliage")
    trunk_r = 0.06 + 0.02 * height
    if conifer:
        scene.cylinder((x, y), 0.0, height * 0.3, trunk_r, material=bark_mat)
        scene.frustum((x, y), height * 0.2, height, crown, 0.0, material=leaf_mat)
        return
    scene.cylinder((x, y), 0.0, height - crown, trunk_r, material=bark_mat)
    cz = height - crown
    scene.ellipsoid((x, y, cz), (crown, crown, crown * 0.85), material=leaf_mat)
    for _ in range(3):
        a = rng.uniform(0, 2 * np.pi)
        r = crown * 0.55
        scene.ellipsoid((x + r * np.cos(a), y + r * np.sin(a), cz + rng.uniform(-0.2, 0.3) * crown),
                        crown * rng.uniform(0.45, 0.6), material=leaf_mat)


def building(scene: Scene, rng: np.random.Generator, *, x0: float, y0: float, x1: float, y1: float, height: float,
             floor_height: float = 3.5, window_width: float = 2.5, albedo: float | None = None,
             kind: str = "concrete", roof_material: int | None = None) -> None:
    """A building block with window-grid facades (one texture repeat per floor and window bay)."""
    alb = rng.uniform(0.4, 0.75) if albedo is None else albedo
    tex = tx.facade(rng, floors=4, windows=4)
    fac = scene.material(texture=tex, albedo=alb, scale=(4 * window_width, 4 * floor_height), kind=kind)
    roof = roof_material if roof_material is not None else scene.material(albedo=0.3, kind=kind)
    scene.box((x0, y0, 0.0), (x1, y1, height), [fac, fac, fac, fac, roof, roof])


def person(scene: Scene, rng: np.random.Generator, *, x: float = 0.0, y: float = 0.0, yaw: float = 0.0,
           height: float = 1.75) -> None:
    """A standing person (shoes, trousers, shirt, arms, head), facing ``yaw``, feet at ``(x, y, 0)``.

    Built from boxes and a spherical head (rotation-invariant about ``+z``), so
    that the figure can be moved and turned as a whole in a compiled scene
    (:meth:`bionav.world.worlds.common.Supervisor.place`).
    """
    s = height / 1.75
    trousers = scene.material(texture=tx.carpet(rng, lo=0.1, hi=0.35), albedo=rng.uniform(0.3, 0.6), scale=0.3)
    shirt = scene.material(texture=tx.stripes(rng, n=int(rng.integers(6, 14)), lo=0.3, hi=0.9)
                           if rng.uniform() < 0.5 else tx.value_noise(rng, lo=0.4, hi=0.8),
                           albedo=rng.uniform(0.5, 0.9), scale=(0.3, 0.4))
    skin = scene.material(albedo=rng.uniform(0.55, 0.75))
    hair = scene.material(albedo=rng.uniform(0.05, 0.3))
    shoe = scene.material(albedo=0.1)

    def part(u, v, z0, size, mat):  # u forward, v left, in the person's frame
        dx, dy = _rot(u, v, yaw)
        oriented_box(scene, (x + dx, y + dy, z0 * s), (size[0] * s, size[1] * s, size[2] * s), mat, yaw=yaw)

    for v in (-0.1, 0.1):
        part(0.03, v, 0.0, (0.26, 0.1, 0.07), shoe)
        part(0.0, v, 0.07, (0.14, 0.14, 0.8), trousers)
    part(0.0, 0.0, 0.87, (0.22, 0.38, 0.08), trousers)
    part(0.0, 0.0, 0.95, (0.24, 0.42, 0.5), shirt)
    for v in (-0.25, 0.25):
        part(0.0, v, 0.8, (0.1, 0.09, 0.62), shirt)
        part(0.0, v, 0.68, (0.09, 0.08, 0.12), skin)
    part(0.0, 0.0, 1.45, (0.1, 0.1, 0.08), skin)
    scene.ellipsoid((x, y, 1.62 * s), 0.11 * s, material=skin)
    scene.ellipsoid((x - 0.02 * np.cos(yaw), y - 0.02 * np.sin(yaw), 1.66 * s), 0.1 * s, material=hair)
