"""An apartment room for the cleaning-robot experiments (thesis chapter 7, fig. 7.2).

A room of about 5.6 m x 7.2 m x 2.6 m whose middle holds an obstacle-free
floor rectangle of 3.0 m x 5.0 m (``World.free_area``), enough for seven
4 m lanes or fourteen 2 m lanes 0.3 m apart; furniture (sofa, shelves,
cabinets, a dining table, plants) and a robot-arm "H" support stand around
it. The robot renders panoramas at arbitrary poses inside the free area
(:func:`bionav.world.render.render_panorama`). The ``World`` grid is a
0.1 m raster over the free area (31 x 51 cells), for convenience only.
"""

from __future__ import annotations

import numpy as np

from bionav.world import textures as tx
from bionav.world.lights import Ambient, PointLight, light_band
from bionav.world.scene import Scene
from bionav.world.worlds.common import World, stream
from bionav.world.worlds.furniture import cabinet, chair, potted_plant, shelf, table, wall_picture
from bionav.world.worlds.living import _floor_lamp, _shell, _sofa, _window

FREE_SIZE = (3.0, 5.0)


def build_apartment(seed: int = 0, *, camera_height: float = 0.6) -> World:
    """Build the apartment world.

    Parameters
    ----------
    seed : int
        Which apartment (dimensions within a few decimetres, textures, details).
    camera_height : float
        Camera height above the floor in metres.

    Returns
    -------
    World
        With ``free_area = (x0, y0, x1, y1)`` (metres) of the obstacle-free floor.
    """
    g = stream(seed, "apartment/layout")
    lx = 5.6 + g.uniform(-0.1, 0.2)
    ly = 7.2 + g.uniform(-0.1, 0.2)
    lz = 2.6
    fx0 = (lx - FREE_SIZE[0]) / 2
    fy0 = (ly - FREE_SIZE[1]) / 2
    fx1, fy1 = fx0 + FREE_SIZE[0], fy0 + FREE_SIZE[1]
    scene = Scene(name="apartment")
    _shell(scene, seed, lx, ly, lz, "apartment")

    r = stream(seed, "apartment/furniture")
    _sofa(scene, r, x=0.48, y=ly / 2 + 0.4, yaw=0.0, width=2.2)  # west wall
    shelf(scene, r, x0=0.3, y0=ly - 0.38, x1=2.3, y1=ly, height=2.1, facing="-y", shelves=5)
    cabinet(scene, r, x0=2.6, y0=ly - 0.5, x1=3.9, y1=ly, height=0.9, facing="-y", doors=(2, 2))
    cabinet(scene, r, x0=lx - 0.5, y0=ly - 2.4, x1=lx, y1=ly - 1.0, height=1.9, facing="-x", doors=(2, 3))
    table(scene, r, x0=lx - 1.05, y0=1.0, x1=lx - 0.2, y1=2.2, height=0.74)
    chair(scene, r, x=lx - 0.62, y=0.65, yaw=np.pi / 2)
    cabinet(scene, r, x0=1.0, y0=0.0, x1=2.6, y1=0.45, height=0.8, facing="+y", doors=(3, 1))
    potted_plant(scene, stream(seed, "apartment/plant"), x=0.45, y=0.45, height=1.5, crown=0.35, min_leaf_z=0.7)
    potted_plant(scene, stream(seed, "apartment/plant2"), x=lx - 0.4, y=ly - 0.4, height=1.3, crown=0.3,
                 min_leaf_z=0.6)
    _floor_lamp(scene, r, x=0.35, y=ly - 1.0)
    steel = scene.material(texture=tx.value_noise(r, lo=0.45, hi=0.7), albedo=0.6, scale=0.4)
    hx, hy = fx1 + 0.25, fy0 + 1.2  # robot-arm "H" support beside the cleaning area
    scene.box((hx, hy, 0), (hx + 0.1, hy + 0.9, 0.8), steel)
    scene.box((hx + 0.55, hy, 0), (hx + 0.65, hy + 0.9, 0.8), steel)
    scene.box((hx + 0.1, hy + 0.4, 0.35), (hx + 0.55, hy + 0.5, 0.45), steel)
    _window(scene, r, wall_x=None, wall_y=0.0, centre=lx * 0.65, width=1.5, lx=lx, ly=ly)
    _window(scene, r, wall_x=lx, wall_y=None, centre=ly * 0.45, width=1.2, lx=lx, ly=ly)
    door = scene.material(texture=tx.panel(r, nx=1, ny=3), fit=True, albedo=0.85)
    scene.box((0.0, 1.0, 0.0), (0.04, 1.9, 2.05), door, shadow=False)
    for wall, pos in (("west", ly * 0.7), ("north", lx * 0.55), ("east", ly * 0.8), ("south", lx * 0.25),
                      ("west", ly * 0.25)):
        length = lx if wall in ("north", "south") else ly
        w = r.uniform(0.5, 0.9)
        wall_picture(scene, r, wall=wall, position=min(pos, length - 0.6), z0=1.3, z1=1.3 + w * 0.8, width=w,
                     room=(lx, ly))

    lamp = scene.material(albedo=0.9, emission=1.5)
    scene.box((lx / 2 - 0.08, 1.5, lz - 0.05), (lx / 2 + 0.08, ly - 1.5, lz - 0.01), lamp, shadow=False)
    scene.add_light(light_band((lx / 2, 1.7, lz - 0.07), (lx / 2, ly - 1.7, lz - 0.07), n=3, intensity=5.0))
    scene.add_light(PointLight((lx * 0.65, 0.4, 1.6), 0.8, downward=False))
    scene.ambient = Ambient(up=0.3, down=0.2)
    scene.exposure = 1.5
    nx = int(round(FREE_SIZE[0] / 0.1)) + 1
    ny = int(round(FREE_SIZE[1] / 0.1)) + 1
    return World(scene=scene, grid_origin=(fx0, fy0), spacing=0.1, grid_shape=(nx, ny),
                 camera_height=camera_height, free_area=(fx0, fy0, fx1, fy1), info={"room": (lx, ly, lz)})
