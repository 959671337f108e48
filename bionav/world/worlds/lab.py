"""The laboratory of Vardy's *original* database and its seven variants (thesis 3.1).

A room of about 6.6 m x 8.4 m x 2.9 m: windows with curtains along the east
wall (``x = Lx``), the door in the west wall, two ceiling light bands parallel
to the windows (the door-side band at ``x ~ 0.3 Lx``, the window-side band at
``x ~ 0.7 Lx``), cabinets, shelves, boxes, a waste bin, a robot-arm "H"
support, posters and a whiteboard on the walls, and two desks whose tops
cover the last grid row (``y = 16``), as in the thesis. The 10 x 17 capture
grid (0.3 m spacing, 2.7 m x 4.8 m) lies in the middle of the free floor.

The variants share the geometry of the same seed exactly and change only
what their names say.
"""

from __future__ import annotations

import numpy as np

from bionav.world import textures as tx
from bionav.world.lights import Ambient, PointLight, light_band
from bionav.world.scene import Scene
from bionav.world.worlds.common import World, stream
from bionav.world.worlds.furniture import cabinet, chair, potted_plant, shelf, table, wall_picture

GRID_SHAPE = (10, 17)
SPACING = 0.3
CAMERA_HEIGHT = 0.6
#: Camera tilt std (degrees) on the lab's hard, level floor (mast sway only; World.floor_tilt_deg).
FLOOR_TILT_DEG = 0.3
#: Bounce light per band that is on, on upward / downward faces (relative to a band's direct light).
AMBIENT_PER_BAND = (0.07, 0.045)
#: Total intensity of one ceiling light band (four point emitters).
BAND_INTENSITY = 6.5

#: Variant name -> builder options (what the thesis says changed).
LAB_VARIANTS: dict[str, dict] = {
    "original": {},
    "arboreal": {"plant": True},
    "chairs": {"chairs": True},
    "day": {"curtains_open": True, "daylight": 1.0},
    "doorlit": {"window_band": False},
    "screen": {"screen": True},
    "twilight": {"curtains_open": True, "daylight": 0.08},
    "winlit": {"door_band": False},
}


def build_lab(seed: int = 0, *, plant: bool = False, chairs: bool = False, curtains_open: bool = False,
              daylight: float = 0.0, door_band: bool = True, window_band: bool = True,
              screen: bool = False) -> World:
    """Build the laboratory world.

    Parameters
    ----------
    seed : int
        Which laboratory (dimensions, furniture placement, textures).
    plant : bool
        Put an arboreal plant in the middle of the room (between grid cells).
    chairs : bool
        Add office chairs around the capture area.
    curtains_open : bool
        Open the window curtains (windows show the outside).
    daylight : float
        Brightness of daylight through open windows (1 = overcast day).
    door_band, window_band : bool
        Whether the door-side / window-side ceiling light band is on.
    screen : bool
        Add a white projection screen.

    Returns
    -------
    World
        Scene plus grid placement (10 x 17 cells, 0.3 m, camera 0.6 m high).
    """
    g = stream(seed, "lab/layout")
    lx = 6.6 + g.uniform(-0.3, 0.3)
    ly = 8.4 + g.uniform(-0.3, 0.3)
    lz = 2.9 + g.uniform(-0.1, 0.1)
    gx0 = lx / 2 - 1.35 + g.uniform(-0.15, 0.15)
    gy0 = 1.45 + g.uniform(-0.1, 0.1)
    gx1, gy1 = gx0 + 2.7, gy0 + 4.8
    scene = Scene(name="lab", exposure=1.0)
    _shell(scene, seed, lx, ly, lz)
    win_centres = _windows(scene, seed, lx, ly, lz, daylight=daylight, curtains_open=curtains_open)
    _door(scene, seed, ly)
    _furniture(scene, seed, lx, ly, lz, gx0, gy0, gx1)
    _desks(scene, seed, gx0, gx1, gy1)
    _posters(scene, seed, lx, ly)
    _lights(scene, seed, lx, ly, lz, win_centres, door_band=door_band, window_band=window_band, daylight=daylight,
            curtains_open=curtains_open)
    _variants(scene, seed, gx0, gy0, gx1, plant=plant, chairs=chairs, screen=screen)
    scene.exposure = 2.4
    return World(scene=scene, grid_origin=(gx0, gy0), spacing=SPACING, grid_shape=GRID_SHAPE,
                 camera_height=CAMERA_HEIGHT, info={"room": (lx, ly, lz)}, floor_tilt_deg=FLOOR_TILT_DEG)


def _shell(scene: Scene, seed: int, lx: float, ly: float, lz: float) -> None:
    """The room's walls, floor, ceiling, skirting and cable ducts (room ``lx x ly x lz`` metres)."""
    r = stream(seed, "lab/shell")
    wall = scene.material(texture=tx.plaster(r), albedo=0.85, scale=1.7)
    floor = scene.material(texture=tx.tiles(r, n=4, lo=0.25, hi=0.55, grout_level=0.3), albedo=0.55, scale=2.0)
    ceiling = scene.material(texture=tx.ceiling_tiles(r), albedo=0.85, scale=2.4)
    scene.box((0, 0, 0), (lx, ly, lz), [wall, wall, wall, wall, floor, ceiling], inside=True, shadow=False)
    base = scene.material(albedo=0.15)
    for lo, hi in (((0, 0, 0), (0.015, ly, 0.09)), ((lx - 0.015, 0, 0), (lx, ly, 0.09)),
                   ((0, 0, 0), (lx, 0.015, 0.09)), ((0, ly - 0.015, 0), (lx, ly, 0.09))):
        scene.box(lo, hi, base, shadow=False)
    duct = scene.material(texture=tx.stripes(r, n=3, lo=0.55, hi=0.8), albedo=0.9, scale=(2.0, 0.1))
    scene.box((0, 0.3, 0.95), (0.05, ly - 0.3, 1.05), duct, shadow=False)  # cable duct on the west wall
    scene.box((0.3, ly - 0.05, 0.95), (lx - 0.3, ly, 1.05), duct, shadow=False)


def _windows(scene: Scene, seed: int, lx: float, ly: float, lz: float, *, daylight: float, curtains_open: bool) -> list[float]:
    """Windows, curtains and radiators along the east wall (``x = lx``); returns the windows' centres ``y`` (m)."""
    r = stream(seed, "lab/windows")
    n_win = 3
    win_w = 1.5
    win_centres = [ly * (k + 0.5) / n_win + r.uniform(-0.2, 0.2) for k in range(n_win)]
    sill, top = 0.9, 2.5
    view_level = daylight
    pane = scene.material(texture=tx.window_view(r), fit=True, albedo=0.2,
                          emission=2.2 * view_level)
    curtain_mat = scene.material(texture=tx.curtain(r, folds=7), albedo=0.75, scale=(1.2, 2.0))
    radiator = scene.material(texture=tx.stripes(r, n=12, lo=0.4, hi=0.9), albedo=0.85, scale=(1.0, 0.6))
    for k, c in enumerate(win_centres):
        scene.box((lx - 0.02, c - win_w / 2, sill), (lx, c + win_w / 2, top), pane, shadow=False)
        scene.box((lx - 0.12, c - 0.6, 0.15), (lx - 0.04, c + 0.6, 0.75), radiator)
        if curtains_open:
            for side in (-1, 1):
                cc = c + side * (win_w / 2 + 0.15)
                scene.box((lx - 0.16, cc - 0.18, 0.25), (lx - 0.06, cc + 0.18, lz - 0.1), curtain_mat)
        else:
            scene.box((lx - 0.16, c - win_w / 2 - 0.3, 0.25), (lx - 0.06, c + win_w / 2 + 0.3, lz - 0.1),
                      curtain_mat)
    rail = scene.material(albedo=0.7)
    scene.box((lx - 0.18, 0.1, lz - 0.12), (lx - 0.04, ly - 0.1, lz - 0.06), rail, shadow=False)
    return win_centres


def _door(scene: Scene, seed: int, ly: float) -> None:
    """The door and the whiteboard in the west wall (``x = 0``)."""
    r = stream(seed, "lab/door")
    door_y = 0.6 + r.uniform(0.0, 0.5)
    door = scene.material(texture=tx.panel(r, nx=1, ny=2), fit=True, albedo=0.7)
    frame = scene.material(albedo=0.35)
    scene.box((0.0, door_y - 0.06, 0.0), (0.05, door_y + 1.06, 2.16), frame, shadow=False)
    scene.box((0.0, door_y, 0.0), (0.06, door_y + 1.0, 2.1), door, shadow=False)
    board = scene.material(texture=tx.poster(r, n_shapes=25), fit=True, albedo=0.95)
    wy = ly * 0.55
    scene.box((0.0, wy - 1.0, 0.9), (0.04, wy + 1.0, 2.0), board, shadow=False)  # whiteboard with scribbles


def _furniture(scene: Scene, seed: int, lx: float, ly: float, lz: float, gx0: float, gy0: float, gx1: float) -> None:
    """Cabinets, shelves, crates, a bin, a stool, the robot-arm support and a pipe (grid from ``(gx0, gy0)``)."""
    r = stream(seed, "lab/furniture")
    cabinet(scene, r, x0=0.0, y0=2.2, x1=0.6, y1=3.4, height=2.0, facing="+x", doors=(2, 3))
    cabinet(scene, r, x0=0.0, y0=ly - 1.7, x1=0.5, y1=ly - 0.9, height=1.1, facing="+x", doors=(2, 2))
    shelf(scene, r, x0=0.8, y0=ly - 0.4, x1=2.6, y1=ly, height=2.1, facing="-y", shelves=5)
    shelf(scene, r, x0=lx - 2.0, y0=ly - 0.4, x1=lx - 0.9, y1=ly, height=1.8, facing="-y", shelves=4)
    cabinet(scene, r, x0=1.2, y0=0.0, x1=2.8, y1=0.55, height=0.9, facing="+y", doors=(4, 1))
    shelf(scene, r, x0=3.2, y0=0.0, x1=4.6, y1=0.35, height=1.6, facing="+y", shelves=4)
    cabinet(scene, r, x0=lx - 0.55, y0=0.2, x1=lx, y1=1.0, height=1.3, facing="-x", doors=(1, 3))
    # boxes / crates stacked in the east strip and south-west corner
    crate = scene.material(texture=tx.value_noise(r, lo=0.3, hi=0.7, base_cells=3), albedo=0.7, scale=0.5)
    carton = scene.material(texture=tx.poster(r, n_shapes=6), fit=True, albedo=0.75)
    bx, by = gx1 + 0.55 + r.uniform(0, 0.3), gy0 + 1.0 + r.uniform(0, 1.0)
    scene.box((bx, by, 0), (bx + 0.6, by + 0.45, 0.5), crate)
    scene.box((bx + 0.05, by + 0.05, 0.5), (bx + 0.5, by + 0.4, 0.85), carton)
    scene.box((0.15, 0.15, 0), (0.75, 0.6, 0.45), carton)
    # waste bin and a round lab stool
    bin_mat = scene.material(texture=tx.stripes(r, n=6, lo=0.2, hi=0.5), albedo=0.6, scale=(1.0, 0.4))
    scene.frustum((gx0 - 0.6, gy0 + 0.4), 0.0, 0.42, 0.14, 0.17, material=bin_mat)
    stool = scene.material(albedo=0.25)
    scene.cylinder((gx1 + 0.8, gy0 + 3.8), 0.0, 0.55, 0.04, material=stool)
    scene.cylinder((gx1 + 0.8, gy0 + 3.8), 0.55, 0.6, 0.18, material=scene.material(albedo=0.75))
    # robot-arm "H" support (thesis fig. 7.2) in the south-west
    steel = scene.material(texture=tx.value_noise(r, lo=0.45, hi=0.7), albedo=0.6, scale=0.4)
    hx, hy = 0.35, gy0 + 1.8
    scene.box((hx, hy, 0), (hx + 0.1, hy + 1.0, 0.8), steel)
    scene.box((hx + 0.6, hy, 0), (hx + 0.7, hy + 1.0, 0.8), steel)
    scene.box((hx + 0.1, hy + 0.45, 0.35), (hx + 0.6, hy + 0.55, 0.45), steel)
    scene.box((hx + 0.2, hy + 0.35, 0.8), (hx + 0.5, hy + 0.65, 1.1), steel)
    # a pipe in the north-east corner
    pipe = scene.material(albedo=0.8)
    scene.cylinder((lx - 0.12, ly - 0.12), 0.0, lz, 0.07, material=pipe)


def _desks(scene: Scene, seed: int, gx0: float, gx1: float, gy1: float) -> None:
    """Two desks with screens, keyboards and a PC covering the last grid row (``y = gy1``)."""
    r = stream(seed, "lab/desks")
    ty0, ty1 = gy1 - 0.25, gy1 + 0.6
    tx0, tx1 = gx0 - 0.35, gx1 + 0.35
    mid = (tx0 + tx1) / 2
    for a, b in ((tx0, mid - 0.01), (mid + 0.01, tx1)):
        table(scene, r, x0=a, y0=ty0, x1=b, y1=ty1, height=0.74)
    screen_mat = scene.material(texture=tx.poster(r, n_shapes=10), fit=True, albedo=0.6)
    case = scene.material(albedo=0.2)
    for k in range(3):
        mx = tx0 + 0.5 + k * (tx1 - tx0 - 1.0) / 2
        scene.box((mx - 0.25, ty1 - 0.3, 0.76), (mx + 0.25, ty1 - 0.26, 1.1), screen_mat)
        scene.box((mx - 0.05, ty1 - 0.25, 0.74), (mx + 0.05, ty1 - 0.15, 0.8), case)
        scene.box((mx - 0.2, ty0 + 0.15, 0.74), (mx + 0.2, ty0 + 0.3, 0.76), case)  # keyboard
    scene.box((tx1 - 0.3, ty1 - 0.45, 0.0), (tx1 - 0.08, ty1 - 0.05, 0.45), case)  # PC tower under the desk


def _posters(scene: Scene, seed: int, lx: float, ly: float) -> None:
    """Posters on the walls."""
    r = stream(seed, "lab/posters")
    for wall_name, positions, length in (("south", [0.6, 5.2], lx), ("north", [3.6, 5.6], lx),
                                          ("west", [4.2, 6.9], ly), ("east", [], ly)):
        for p in positions:
            w = r.uniform(0.6, 1.0)
            z0 = r.uniform(1.1, 1.35)
            wall_picture(scene, r, wall=wall_name, position=min(p, length - 0.5), z0=z0, z1=z0 + w * 1.3,
                         width=w, room=(lx, ly))


def _lights(scene: Scene, seed: int, lx: float, ly: float, lz: float, win_centres: list[float], *, door_band: bool,
            window_band: bool, daylight: float, curtains_open: bool) -> None:
    """The two ceiling light bands (on or off), the ambient bounce light and daylight through open windows."""
    r = stream(seed, "lab/lights")
    band_intensity = BAND_INTENSITY
    fixture_off = scene.material(texture=tx.stripes(r, n=4, lo=0.6, hi=0.9), albedo=0.8, scale=(1.2, 0.15))
    fixture_on = scene.material(texture=tx.stripes(r, n=4, lo=0.75, hi=1.0), albedo=0.8, emission=3.0,
                                scale=(1.2, 0.15))
    bands = ((lx * 0.3, door_band), (lx * 0.7, window_band))
    for bx_, on in bands:
        scene.box((bx_ - 0.1, 0.9, lz - 0.06), (bx_ + 0.1, ly - 0.9, lz - 0.005),
                  fixture_on if on else fixture_off, shadow=False)
        if on:
            scene.add_light(light_band((bx_, 1.2, lz - 0.07), (bx_, ly - 1.2, lz - 0.07), n=4,
                                       intensity=band_intensity))
    # Inter-reflected light: the walls and ceiling near a band that is on are its main secondary
    # source, so the bounce light is weak next to a band that is off. A uniform ambient term cannot
    # say where, so it is kept small against the bands' direct light (which carries the shading
    # and the hard shadows that differ between doorlit and winlit).
    n_on = int(door_band) + int(window_band)
    scene.ambient = Ambient(up=AMBIENT_PER_BAND[0] * n_on + 0.25 * daylight,
                            down=AMBIENT_PER_BAND[1] * n_on + 0.15 * daylight)
    if daylight > 0 and curtains_open:
        for c in win_centres:  # diffuse daylight entering through each window
            scene.add_light(PointLight((lx - 0.3, c, 2.0), 1.0 * daylight, downward=False))


def _variants(scene: Scene, seed: int, gx0: float, gy0: float, gx1: float, *, plant: bool, chairs: bool,
              screen: bool) -> None:
    """What the variants add: the plant, the chairs, the projection screen."""
    if plant:
        # centre of the room, between four grid cells so no camera stands inside it
        potted_plant(scene, stream(seed, "lab/plant"), x=gx0 + SPACING * 4.5, y=gy0 + SPACING * 8.5,
                     height=1.7, crown=0.4, min_leaf_z=0.8)
    if chairs:
        rc = stream(seed, "lab/chairs")
        spots = [(gx0 - 0.45, gy0 + 1.2), (gx0 - 0.45, gy0 + 3.0), (gx1 + 0.45, gy0 + 0.6),
                 (gx1 + 0.5, gy0 + 2.6), (gx0 + 0.9, gy0 - 0.45), (gx1 - 0.6, gy0 - 0.45)]
        for cx, cy in spots:
            chair(scene, rc, x=cx, y=cy, yaw=rc.uniform(0, 2 * np.pi))
    if screen:
        rs = stream(seed, "lab/screen")
        white = scene.material(albedo=0.95)
        legs = scene.material(albedo=0.2)
        sy0 = gy0 + 1.3 + rs.uniform(0, 0.4)
        scene.box((0.85, sy0, 0.85), (0.88, sy0 + 1.8, 2.25), white)
        scene.box((0.84, sy0 - 0.05, 2.25), (0.89, sy0 + 1.85, 2.3), legs)
        for yy in (sy0 + 0.1, sy0 + 1.7):
            scene.cylinder((0.86, yy), 0.0, 0.85, 0.02, material=legs)
            scene.box((0.6, yy - 0.02, 0.0), (1.1, yy + 0.02, 0.04), legs)


def build_lab_variant(variant: str, seed: int = 0) -> World:
    """Build one of :data:`LAB_VARIANTS` (``original``, ``arboreal``, ...)."""
    if variant not in LAB_VARIANTS:
        raise KeyError(variant)
    return build_lab(seed, **LAB_VARIANTS[variant])
