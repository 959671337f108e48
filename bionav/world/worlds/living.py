"""Living rooms (stand-ins for *moeller1* and *roeben1*, thesis 3.1).

``build_living_room``: a furnished living room (sofa, armchair, coffee table,
TV sideboard, bookshelf, plant, floor lamp, rug, window with curtains,
pictures) with an 11 x 22 grid at 0.1 m (1.0 m x 2.1 m) on the free floor.

``build_living_kitchen``: a living room joined to a kitchen (counters, upper
cabinets, fridge, dining table and chairs) with an 11 x 36 grid at 0.1 m
(1.0 m x 3.5 m) running close along the furniture, so that images at the
start of a lane (in the kitchen) differ considerably from those at its end
(in the living room).
"""

from __future__ import annotations

import numpy as np

from bionav.light.capture import CaptureLight
from bionav.world import textures as tx
from bionav.world.lights import Ambient, PointLight
from bionav.world.scene import Scene
from bionav.world.worlds.common import Supervisor, Windows, World, lane_order, stream
from bionav.world.worlds.furniture import cabinet, chair, oriented_box, potted_plant, shelf, table, wall_picture

SPACING = 0.1
CAMERA_HEIGHT = 0.6
#: Clearance in metres between the outermost grid cells and the furniture next to the lanes.
CLUTTER_GAP = 0.2
#: Camera tilt std (degrees) in the living rooms (World.floor_tilt_deg): the robot rocks on its caster
#: over the rug and carpet pile under the moeller1 grid, less on the kitchen tiles and parquet of roeben1.
FLOOR_TILT_DEG = {"living": 0.3, "kitchen": 0.8}
#: Heading drift std (degrees) per lane turn (World.heading_drift_deg): the Pioneer's wheels slip when it
#: turns on the spot, more on the rug and carpet pile under the moeller1 grid than on roeben1's tiles and
#: parquet; the supervisor corrected the positions, not the headings (thesis 3.1, Kreft 2007).
HEADING_DRIFT_DEG = {"living": 12.0, "kitchen": 6.0}
#: Contrast of the painted walls (texture value range; real painted walls are nearly uniform).
WALL_TEXTURE = (0.7, 0.8)
#: Seconds per image of the supervised recording (drive, semi-automatic position correction, capture):
#: fixes the hours the sun moves while a database is taken (CaptureLight.seconds_per_capture).
SECONDS_PER_IMAGE = 40.0
#: Irradiance of the unclouded sun entering through the windows, in the units of the scene's lights
#: (the ceiling lamp gives about 0.8 on the floor below it); 0 would be an overcast day.
SUN_IRRADIANCE = 3.0
#: Clouds passing the sun: log-standard deviation of their transmission and correlation length in images.
CLOUD_SIGMA = 1.0
CLOUD_IMAGES = 15.0
#: The supervisor (Supervisor): metres behind the robot along its lane, and the scatter of the stance.
SUPERVISOR_DISTANCE = 1.2
SUPERVISOR_JITTER = 0.3


def _shell(scene: Scene, seed: int, lx: float, ly: float, lz: float, tag: str) -> None:
    r = stream(seed, f"{tag}/shell")
    wall = scene.material(texture=tx.plaster(r, lo=WALL_TEXTURE[0], hi=WALL_TEXTURE[1]), albedo=0.85, scale=1.3)
    floor = scene.material(texture=tx.wood(r, rings=14), albedo=0.6, scale=(1.4, 0.9))
    ceiling = scene.material(texture=tx.plaster(r, lo=0.75, hi=0.85), albedo=0.9, scale=2.0)
    scene.box((0, 0, 0), (lx, ly, lz), [wall, wall, wall, wall, floor, ceiling], inside=True, shadow=False)
    base = scene.material(albedo=0.9)
    for lo, hi in (((0, 0, 0), (0.015, ly, 0.07)), ((lx - 0.015, 0, 0), (lx, ly, 0.07)),
                   ((0, 0, 0), (lx, 0.015, 0.07)), ((0, ly - 0.015, 0), (lx, ly, 0.07))):
        scene.box(lo, hi, base, shadow=False)


def _sofa(scene: Scene, r: np.random.Generator, *, x: float, y: float, yaw: float, width: float = 2.0) -> None:
    """A sofa centred at ``(x, y)``, its seat facing direction ``yaw``."""
    fabric = scene.material(texture=tx.carpet(r, lo=0.25, hi=0.6), albedo=r.uniform(0.4, 0.8), scale=0.4)
    cushion = scene.material(texture=tx.poster(r, n_shapes=5), fit=True, albedo=0.8)
    c, s = np.cos(yaw), np.sin(yaw)

    def at(u, v):  # u along the seat direction, v across
        return x + c * u - s * v, y + s * u + c * v

    oriented_box(scene, (*at(0.0, 0.0), 0.0), (0.9, width, 0.42), fabric, yaw=yaw)
    oriented_box(scene, (*at(-0.35, 0.0), 0.42), (0.2, width, 0.45), fabric, yaw=yaw)
    for v in (-width / 2 + 0.1, width / 2 - 0.1):
        oriented_box(scene, (*at(0.0, v), 0.42), (0.9, 0.2, 0.2), fabric, yaw=yaw)
    for v in (-width / 4, width / 4):
        oriented_box(scene, (*at(-0.17, v), 0.45), (0.15, 0.42, 0.38), cushion, yaw=yaw)


def _window(scene: Scene, r: np.random.Generator, *, wall_x: float | None, wall_y: float | None, centre: float,
            width: float, lx: float, ly: float, open_fraction: float = 0.6) -> tuple[int, tuple]:
    """A bright window with curtains drawn to both sides, on an x- or y-wall.

    Returns the pane's material and the opening as :class:`~bionav.world.worlds.common.Windows`
    takes it: ``(wall, u0, u1, z0, z1)``.
    """
    pane = scene.material(texture=tx.window_view(r), fit=True, albedo=0.2, emission=1.6)
    curtain = scene.material(texture=tx.curtain(r, folds=5, lo=0.4, hi=0.85), albedo=0.8, scale=(0.8, 2.0))
    cw = width * (1 - open_fraction) / 2 + 0.15
    if wall_x is not None:
        x0, x1 = (wall_x - 0.02, wall_x) if wall_x > 0 else (0.0, 0.02)
        scene.box((x0, centre - width / 2, 0.9), (x1, centre + width / 2, 2.2), pane, shadow=False)
        cx0, cx1 = (wall_x - 0.12, wall_x - 0.05) if wall_x > 0 else (0.05, 0.12)
        for sgn in (-1, 1):
            a = centre + sgn * (width / 2 + 0.15)
            b = a - sgn * cw
            scene.box((cx0, min(a, b), 0.05), (cx1, max(a, b), 2.35), curtain)
    else:
        y0, y1 = (wall_y - 0.02, wall_y) if wall_y > 0 else (0.0, 0.02)
        scene.box((centre - width / 2, y0, 0.9), (centre + width / 2, y1, 2.2), pane, shadow=False)
        cy0, cy1 = (wall_y - 0.12, wall_y - 0.05) if wall_y > 0 else (0.05, 0.12)
        for sgn in (-1, 1):
            a = centre + sgn * (width / 2 + 0.15)
            b = a - sgn * cw
            scene.box((min(a, b), cy0, 0.05), (max(a, b), cy1, 2.35), curtain)
    wall = ("x0" if wall_x == 0 else "x1") if wall_x is not None else ("y0" if wall_y == 0 else "y1")
    return pane, (wall, centre - width / 2, centre + width / 2, 0.9, 2.2)


def _floor_lamp(scene: Scene, r: np.random.Generator, *, x: float, y: float) -> None:
    pole = scene.material(albedo=0.2)
    shade = scene.material(texture=tx.value_noise(r, lo=0.7, hi=0.9), albedo=0.9, emission=0.6, scale=0.3)
    scene.cylinder((x, y), 0.0, 0.03, 0.15, material=pole)
    scene.cylinder((x, y), 0.03, 1.45, 0.015, material=pole)
    scene.frustum((x, y), 1.4, 1.7, 0.22, 0.14, material=shade, shadow=False)
    scene.add_light(PointLight((x, y, 1.45), 0.35, downward=False))


def build_living_room(seed: int = 0) -> World:
    """The *moeller1* stand-in: a living room with an 11 x 22 grid at 0.1 m spacing.

    Returns
    -------
    World
        Grid 11 x 22 (1.0 m x 2.1 m), camera 0.6 m high.
    """
    g = stream(seed, "living/layout")
    lx = 4.6 + g.uniform(-0.2, 0.2)
    ly = 5.4 + g.uniform(-0.2, 0.2)
    lz = 2.5
    gx0 = lx / 2 - 0.5 + g.uniform(-0.2, 0.2)
    gy0 = ly / 2 - 1.05 + g.uniform(-0.2, 0.2)
    gx1, gy1 = gx0 + 1.0, gy0 + 2.1
    scene = Scene(name="living room")
    _shell(scene, seed, lx, ly, lz, "living")

    r = stream(seed, "living/furniture")
    _sofa(scene, r, x=0.5, y=ly / 2, yaw=0.0, width=2.2)  # along the west wall, facing east
    _sofa(scene, r, x=lx / 2 - 0.2, y=0.5, yaw=np.pi / 2, width=1.0)  # an armchair facing north
    table(scene, r, x0=gx0 - 0.85, y0=gy0 + 0.6, x1=gx0 - 0.25, y1=gy0 + 1.6, height=0.45, apron=False)
    cabinet(scene, r, x0=lx - 0.45, y0=ly / 2 - 0.9, x1=lx, y1=ly / 2 + 0.9, height=0.55, facing="-x", doors=(3, 1))
    tv = scene.material(texture=tx.poster(r, n_shapes=8), fit=True, albedo=0.35)
    scene.box((lx - 0.3, ly / 2 - 0.6, 0.6), (lx - 0.25, ly / 2 + 0.6, 1.3), tv)
    scene.box((lx - 0.33, ly / 2 - 0.1, 0.55), (lx - 0.22, ly / 2 + 0.1, 0.6), scene.material(albedo=0.15))
    shelf(scene, r, x0=0.6, y0=ly - 0.35, x1=2.4, y1=ly, height=2.0, facing="-y", shelves=5)
    cabinet(scene, r, x0=lx - 1.4, y0=ly - 0.5, x1=lx - 0.2, y1=ly, height=0.9, facing="-y", doors=(2, 2))
    potted_plant(scene, stream(seed, "living/plant"), x=lx - 0.45, y=0.45, height=1.4, crown=0.35,
                 min_leaf_z=0.7)
    _floor_lamp(scene, r, x=0.35, y=0.4)
    # furniture right beside the lanes (thesis 3.1: a small grid in a furnished room): a
    # dining corner east of the grid and a stool and a side table at its ends, 0.15-0.4 m from
    # the outermost cells, so that near objects fill much of the view and their image moves
    # and occludes the room behind them from one cell to the next.
    rc = stream(seed, "living/clutter")
    table(scene, rc, x0=gx1 + CLUTTER_GAP, y0=gy0 + 0.9, x1=gx1 + CLUTTER_GAP + 0.8, y1=gy0 + 1.9, height=0.74)
    for cy, yaw in ((gy0 + 1.15, np.pi), (gy0 + 1.65, np.pi)):
        chair(scene, rc, x=gx1 + CLUTTER_GAP + 1.05, y=cy, yaw=yaw)
    chair(scene, rc, x=gx1 + CLUTTER_GAP + 0.4, y=gy0 + 0.6, yaw=np.pi / 2)
    stool = scene.material(texture=tx.value_noise(rc, lo=0.2, hi=0.6), albedo=0.6, scale=0.3)
    scene.cylinder((gx0 + 0.3, gy0 - CLUTTER_GAP - 0.2), 0.0, 0.45, 0.2, material=stool)
    side = scene.material(texture=tx.wood(rc), albedo=0.5, scale=0.6)
    scene.box((gx0 + 0.45, gy1 + CLUTTER_GAP, 0.0), (gx0 + 0.95, gy1 + CLUTTER_GAP + 0.4, 0.6), side)
    basket = scene.material(texture=tx.stripes(rc, n=8, lo=0.2, hi=0.7), albedo=0.7, scale=(0.3, 0.2))
    scene.frustum((gx0 - CLUTTER_GAP - 0.15, gy1 - 0.3), 0.0, 0.35, 0.15, 0.18, material=basket)
    rug = scene.material(texture=tx.poster(r, n_shapes=20), fit=True, albedo=0.7)
    scene.box((gx0 - 0.9, gy0 + 0.2, 0.0), (gx1 + 0.2, gy1 - 0.2, 0.012), rug, shadow=False)
    panes, windows = zip(_window(scene, r, wall_x=None, wall_y=0.0, centre=lx * 0.6, width=1.4, lx=lx, ly=ly),
                         _window(scene, r, wall_x=lx, wall_y=None, centre=ly * 0.2, width=1.0, lx=lx, ly=ly))
    door = scene.material(texture=tx.panel(r, nx=1, ny=3), fit=True, albedo=0.85)
    scene.box((0.0, ly - 1.3, 0.0), (0.04, ly - 0.45, 2.05), door, shadow=False)
    radiator = scene.material(texture=tx.stripes(r, n=14, lo=0.55, hi=0.95), albedo=0.9, scale=(1.0, 0.5))
    scene.box((lx * 0.6 - 0.6, 0.04, 0.15), (lx * 0.6 + 0.6, 0.12, 0.7), radiator)
    for wall, pos in (("west", ly / 2), ("north", lx * 0.75), ("east", ly * 0.75), ("south", lx * 0.2)):
        length = lx if wall in ("north", "south") else ly
        w = r.uniform(0.4, 0.9)
        wall_picture(scene, r, wall=wall, position=min(pos, length - 0.6), z0=1.3, z1=1.3 + w * 0.8,
                     width=w, room=(lx, ly))

    r = stream(seed, "living/lights")
    lamp = scene.material(albedo=0.9, emission=1.5)
    scene.ellipsoid((lx / 2, ly / 2, lz - 0.25), (0.25, 0.25, 0.12), material=lamp, shadow=False)
    scene.add_light(PointLight((lx / 2, ly / 2, lz - 0.4), 3.0, downward=False))
    sky = len(scene.lights)
    scene.add_light(PointLight((lx * 0.6, 0.4, 1.6), 0.8, downward=False))  # daylight from the window
    scene.ambient = Ambient(up=0.3, down=0.2)
    scene.exposure = 1.5
    # an afternoon: the sun moves west past the south window (azimuth -60 -> -100 deg, sinking)
    daylight = CaptureLight(order=lane_order((11, 22), lane_axis=1), seconds_per_capture=SECONDS_PER_IMAGE,
                            sun_azimuth_deg=(-60.0, -100.0), sun_elevation_deg=(40.0, 22.0),
                            sun_irradiance=SUN_IRRADIANCE, cloud_sigma=CLOUD_SIGMA, cloud_images=CLOUD_IMAGES)
    openings = Windows(room=(lx, ly, lz), windows=windows, sky_lights=(sky,), panes=panes)
    return World(scene=scene, grid_origin=(gx0, gy0), spacing=SPACING, grid_shape=(11, 22),
                 camera_height=CAMERA_HEIGHT, info={"room": (lx, ly, lz)}, floor_tilt_deg=FLOOR_TILT_DEG["living"],
                 heading_drift_deg=HEADING_DRIFT_DEG["living"],
                 capture_light=daylight, aperture=openings, supervisor=Supervisor(room=(lx, ly), distance_m=SUPERVISOR_DISTANCE,
                                                          jitter_m=SUPERVISOR_JITTER, lane_axis=1))


def build_living_kitchen(seed: int = 0) -> World:
    """The *roeben1* stand-in: living room with kitchen, 11 x 36 grid at 0.1 m close to the furniture.

    The grid's y axis runs from the kitchen (``y = 0``) into the living room.

    Returns
    -------
    World
        Grid 11 x 36 (1.0 m x 3.5 m), camera 0.6 m high.
    """
    g = stream(seed, "kitchen/layout")
    lx = 3.8 + g.uniform(-0.2, 0.2)
    ly = 7.5 + g.uniform(-0.3, 0.3)
    lz = 2.5
    gx0 = 0.95 + g.uniform(-0.05, 0.05)  # 0.35 m from the kitchen counters along the west wall
    gy0 = 0.9 + g.uniform(-0.1, 0.1)
    gx1, gy1 = gx0 + 1.0, gy0 + 3.5
    scene = Scene(name="living room and kitchen")
    _shell(scene, seed, lx, ly, lz, "kitchen")
    _kitchen_units(scene, seed)
    _dining_corner(scene, seed, gx1)
    panes, windows = _kitchen_living_room(scene, seed, lx, ly, gy0, gx1, gy1)

    lamp = scene.material(albedo=0.9, emission=1.5)
    for cy in (1.6, ly - 2.0):
        scene.ellipsoid((lx / 2, cy, lz - 0.2), (0.2, 0.2, 0.1), material=lamp, shadow=False)
        scene.add_light(PointLight((lx / 2, cy, lz - 0.35), 2.2, downward=False))
    scene.ambient = Ambient(up=0.3, down=0.2)
    scene.exposure = 1.5
    # a morning: the sun rises in front of the east windows (azimuth -50 -> +16 deg)
    daylight = CaptureLight(order=lane_order((11, 36), lane_axis=1), seconds_per_capture=SECONDS_PER_IMAGE,
                            sun_azimuth_deg=(-50.0, 16.0), sun_elevation_deg=(15.0, 40.0),
                            sun_irradiance=SUN_IRRADIANCE, cloud_sigma=CLOUD_SIGMA, cloud_images=CLOUD_IMAGES)
    openings = Windows(room=(lx, ly, lz), windows=windows, sky_lights=(), panes=panes)
    return World(scene=scene, grid_origin=(gx0, gy0), spacing=SPACING, grid_shape=(11, 36),
                 camera_height=CAMERA_HEIGHT, info={"room": (lx, ly, lz)}, floor_tilt_deg=FLOOR_TILT_DEG["kitchen"],
                 heading_drift_deg=HEADING_DRIFT_DEG["kitchen"],
                 capture_light=daylight, aperture=openings, supervisor=Supervisor(room=(lx, ly), distance_m=SUPERVISOR_DISTANCE,
                                                          jitter_m=SUPERVISOR_JITTER, lane_axis=1))


def _kitchen_units(scene: Scene, seed: int) -> None:
    """*roeben1*'s kitchen: counters along the west and south walls, upper cabinets, fridge, stove, sink."""
    r = stream(seed, "kitchen/kitchen")
    counter_top = scene.material(texture=tx.value_noise(r, lo=0.2, hi=0.5, base_cells=8), albedo=0.7, scale=0.8)
    front = scene.material(texture=tx.panel(r, nx=4, ny=2), fit=True, albedo=0.8)
    side = scene.material(albedo=0.8)
    kitchen_len = 3.2
    scene.box((0.0, 0.0, 0.0), (0.6, kitchen_len, 0.86), [side, front, side, side, side, side])
    scene.box((0.0, 0.0, 0.86), (0.62, kitchen_len, 0.9), counter_top)
    scene.box((0.6, 0.0, 0.0), (2.4, 0.6, 0.86), [side, side, side, front, side, side])
    scene.box((0.6, 0.0, 0.86), (2.4, 0.62, 0.9), counter_top)
    upper = scene.material(texture=tx.panel(r, nx=5, ny=1), fit=True, albedo=0.85)
    scene.box((0.0, 0.3, 1.45), (0.35, kitchen_len, 2.15), [side, upper, side, side, side, side])
    tiles_mat = scene.material(texture=tx.tiles(r, n=8, lo=0.5, hi=0.9, grout_level=0.4), albedo=0.9, scale=0.8)
    scene.box((0.0, 0.0, 0.9), (0.01, kitchen_len, 1.45), tiles_mat, shadow=False)
    scene.box((0.6, 0.0, 0.9), (2.4, 0.01, 1.6), tiles_mat, shadow=False)
    fridge = scene.material(texture=tx.panel(r, nx=1, ny=2), fit=True, albedo=0.9)
    scene.box((2.45, 0.0, 0.0), (3.1, 0.65, 1.85), [side, side, side, fridge, side, side])
    hob = scene.material(texture=tx.poster(r, n_shapes=4), fit=True, albedo=0.3)
    scene.box((0.05, 1.2, 0.9), (0.55, 1.8, 0.92), hob)
    sink = scene.material(albedo=0.55)
    scene.box((1.0, 0.05, 0.88), (1.6, 0.5, 0.91), sink)
    scene.cylinder((1.3, 0.08), 0.9, 1.2, 0.015, material=sink)


def _dining_corner(scene: Scene, seed: int, gx1: float) -> None:
    """*roeben1*'s dining table with chairs between kitchen and living room, east of the grid (``x > gx1``)."""
    rt = stream(seed, "kitchen/dining")
    dx0 = gx1 + CLUTTER_GAP
    table(scene, rt, x0=dx0, y0=1.6, x1=dx0 + 0.9, y1=3.0, height=0.74, apron=True)
    for cy in (1.9, 2.6):
        chair(scene, rt, x=dx0 + 1.1, y=cy, yaw=np.pi)
    chair(scene, rt, x=dx0 + 0.45, y=1.25, yaw=np.pi / 2)
    chair(scene, rt, x=dx0 + 0.45, y=3.35, yaw=-np.pi / 2)


def _kitchen_living_room(scene: Scene, seed: int, lx: float, ly: float, gy0: float, gx1: float, gy1: float):
    """*roeben1*'s living room: sofa, shelf, TV, armchair, plant, lamp, east windows, door and pictures.

    Returns the windows' panes and openings (as :class:`~bionav.world.worlds.common.Windows` takes them).
    """
    r = stream(seed, "kitchen/living")
    _sofa(scene, r, x=0.4, y=gy0 + 3.5 + 0.2, yaw=0.0, width=2.0)
    shelf(scene, r, x0=0.6, y0=ly - 0.35, x1=2.6, y1=ly, height=2.0, facing="-y", shelves=5)
    cabinet(scene, r, x0=lx - 0.45, y0=ly - 2.8, x1=lx, y1=ly - 1.2, height=0.55, facing="-x", doors=(3, 1))
    tv = scene.material(texture=tx.poster(r, n_shapes=8), fit=True, albedo=0.35)
    scene.box((lx - 0.3, ly - 2.5, 0.6), (lx - 0.25, ly - 1.5, 1.2), tv)
    table(scene, r, x0=gx1 + CLUTTER_GAP, y0=gy1 - 0.6, x1=gx1 + CLUTTER_GAP + 0.6, y1=gy1 + 0.3, height=0.45,
          apron=False)
    _sofa(scene, r, x=gx1 + CLUTTER_GAP + 1.2, y=gy1 - 0.15, yaw=np.pi, width=0.9)  # armchair facing the sofa
    potted_plant(scene, stream(seed, "kitchen/plant"), x=lx - 0.4, y=ly - 0.4, height=1.5, crown=0.35,
                 min_leaf_z=0.7)
    _floor_lamp(scene, r, x=0.35, y=ly - 0.5)
    panes, windows = zip(_window(scene, r, wall_x=lx, wall_y=None, centre=1.5, width=1.2, lx=lx, ly=ly),
                         _window(scene, r, wall_x=lx, wall_y=None, centre=ly - 3.8, width=1.4, lx=lx, ly=ly))
    door = scene.material(texture=tx.panel(r, nx=1, ny=3), fit=True, albedo=0.85)
    scene.box((0.0, ly - 2.6, 0.0), (0.04, ly - 1.75, 2.05), door, shadow=False)
    for wall, pos in (("west", 4.2), ("north", lx * 0.6), ("east", ly - 0.9), ("south", 3.4)):
        length = lx if wall in ("north", "south") else ly
        w = r.uniform(0.4, 0.8)
        wall_picture(scene, r, wall=wall, position=min(pos, length - 0.5), z0=1.4, z1=1.4 + w * 0.8, width=w,
                     room=(lx, ly))
    return panes, windows
