"""A large, dim, achromatic hall with pillars and galleries (stand-in for *hall1*/*hall2*).

The hall is about 22 m wide, 44 m long and 10 m high: stone floor, a dark
coffered ceiling, galleries at 4.5 m along both long walls carried by rows of
square pillars, shop fronts and notice boards on the walls, stairs, benches,
planters and a few fluorescent lamps. The 10 x 20 capture grid (0.5 m,
4.5 m x 9.5 m) lies on the open floor of the deserted hall: an information
kiosk stands over its far corner (the 30 cells within the robot's reach of it
are missing, leaving 170 images as in table 3.1) and a round pillar stands
1.3 m outside the grid near its first cell. The few lamps leave the camera little light
(``LIGHT_LEVEL``): its automatic exposure runs at its limits and the images
are noisy.
``part`` selects which part of the hall the grid covers (hall1, hall2).
"""

from __future__ import annotations

import numpy as np

from bionav.world import textures as tx
from bionav.world.lights import Ambient, PointLight
from bionav.world.scene import Scene
from bionav.world.worlds.common import World, stream
from bionav.world.worlds.furniture import potted_plant, wall_picture

GRID_SHAPE = (10, 20)
SPACING = 0.5
CAMERA_HEIGHT = 0.6
N_MISSING = 30
#: Probability that a lamp position under the galleries has its lamp on (night: few are).
LAMPS_ON = 0.75
#: Radiant intensity of one fluorescent lamp (downward Lambertian panel).
LAMP_INTENSITY = 14.0
#: Bounce light on upward / downward faces.
AMBIENT = (0.09, 0.055)
#: Camera gain.
EXPOSURE = 3.2
#: Camera tilt std (degrees) on the hall's stone floor (joints, mast sway; World.floor_tilt_deg).
FLOOR_TILT_DEG = 0.3
#: Light at the camera relative to what the nominal exposure renders at normal brightness
#: (World.light_level): the hall at night gives the camera about 1/9 of the lit lab's light, so the
#: automatic exposure runs at its limits (calibrated on table 5.3 only; docs/databases.md).
LIGHT_LEVEL = 0.085
#: The information kiosk over the grid's far corner: its near corner relative to cell (0, 0) and its
#: footprint (metres); cells closer than ROBOT_CLEARANCE to it are missing (the robot's radius).
KIOSK_CORNER = (2.6, 7.1)
KIOSK_SIZE = (2.4, 2.9)
ROBOT_CLEARANCE = 0.35
#: Distance of the round pillar's axis from the grid's near long side (metres).
PILLAR_GAP = 1.3


def _kiosk_cells(origin, footprint, clearance: float) -> np.ndarray:
    """Cells mask with the cells within ``clearance`` metres of a box footprint removed.

    ``footprint`` is ``(x0, y0, x1, y1)`` in metres (world frame); ``origin`` the world
    position of cell (0, 0).
    """
    ii, jj = np.meshgrid(np.arange(GRID_SHAPE[0]), np.arange(GRID_SHAPE[1]), indexing="ij")
    x = origin[0] + SPACING * ii
    y = origin[1] + SPACING * jj
    x0, y0, x1, y1 = footprint
    dx = np.maximum(np.maximum(x0 - x, x - x1), 0.0)
    dy = np.maximum(np.maximum(y0 - y, y - y1), 0.0)
    return np.hypot(dx, dy) >= clearance


def build_hall(seed: int = 0, *, part: int = 1) -> World:
    """Build the hall world with the capture grid in part ``part`` (1 or 2).

    Returns
    -------
    World
        10 x 20 grid at 0.5 m spacing with 170 existing cells, camera 0.6 m high.
    """
    g = stream(seed, "hall/layout")
    lx = 22.0 + g.uniform(-1, 1)
    ly = 44.0 + g.uniform(-2, 2)
    lz = 10.0
    gal_z = 4.5
    gal_d = 3.5
    pitch = 6.0 + g.uniform(-0.5, 0.5)
    scene = Scene(name="hall")
    concrete = _shell(scene, seed, lx, ly, lz, gal_z, gal_d, pitch)
    _shops(scene, seed, lx, ly, gal_z)
    _stairs(scene, seed, ly, gal_z, gal_d)
    gx0, gy0, cells, planter_mat, bench = _capture_area(scene, seed, part, lx, ly, lz, concrete)
    _props(scene, seed, lx, ly, gal_d, gx0, gy0, concrete, planter_mat, bench)
    _lights(scene, seed, lx, ly, gal_z, gal_d)
    scene.ambient = Ambient(up=AMBIENT[0], down=AMBIENT[1])
    scene.exposure = EXPOSURE
    return World(scene=scene, grid_origin=(gx0, gy0), spacing=SPACING, grid_shape=GRID_SHAPE,
                 camera_height=CAMERA_HEIGHT, cells=cells, info={"room": (lx, ly, lz), "part": part},
                 floor_tilt_deg=FLOOR_TILT_DEG, light_level=LIGHT_LEVEL)


def _shell(scene: Scene, seed: int, lx: float, ly: float, lz: float, gal_z: float, gal_d: float, pitch: float) -> int:
    """The hall's walls, floor and ceiling, the galleries along both long walls, railings and pillar rows;
    returns the concrete material (also of the kiosk's roof and the notice boards' legs).
    """
    r = stream(seed, "hall/shell")
    floor = scene.material(texture=tx.tiles(r, n=4, lo=0.25, hi=0.65, grout_level=0.2), albedo=0.6, scale=2.4)
    wall = scene.material(texture=tx.value_noise(r, lo=0.45, hi=0.7, base_cells=2), albedo=0.6, scale=4.0)
    ceiling = scene.material(texture=tx.tiles(r, n=3, lo=0.15, hi=0.35, grout_level=0.05), albedo=0.5,
                             scale=3.0)
    scene.box((0, 0, 0), (lx, ly, lz), [wall, wall, wall, wall, floor, ceiling], inside=True, shadow=False)

    # galleries along both long walls, railings and pillar rows
    slab = scene.material(texture=tx.stripes(r, n=3, lo=0.3, hi=0.6), albedo=0.55, scale=(4.0, 0.6))
    railing = scene.material(texture=tx.stripes(r, n=10, lo=0.15, hi=0.7), albedo=0.6, scale=(0.4, 1.0))
    concrete = scene.material(texture=tx.value_noise(r, lo=0.4, hi=0.75, base_cells=3), albedo=0.6, scale=1.5)
    for x0, x1, edge in ((0.0, gal_d, gal_d), (lx - gal_d, lx, lx - gal_d)):
        scene.box((x0, 0.0, gal_z - 0.5), (x1, ly, gal_z), slab)
        ex = edge - 0.05 if edge < lx / 2 else edge
        scene.box((ex, 0.0, gal_z), (ex + 0.05, ly, gal_z + 1.0), railing, shadow=False)
        px = edge - 0.35 if edge < lx / 2 else edge + 0.35
        y = 1.5
        while y < ly - 1.0:
            scene.box((px - 0.35, y - 0.35, 0.0), (px + 0.35, y + 0.35, gal_z - 0.5), concrete)
            y += pitch
    return concrete


def _shops(scene: Scene, seed: int, lx: float, ly: float, gal_z: float) -> None:
    """Shop fronts and notice boards under the galleries, pictures, doors at the ends, upper-level openings."""
    # shop fronts and notice boards under the galleries, doors at the ends
    r = stream(seed, "hall/shops")
    glass = scene.material(texture=tx.facade(r, floors=1, windows=3), albedo=0.4, scale=(6.0, 3.5))
    y = 0.5
    while y < ly - 3.0:
        w = r.uniform(3.0, 5.5)
        if r.random() < 0.6:
            scene.box((0.0, y, 0.0), (0.1, y + w, 3.5), glass, shadow=False)
            scene.box((lx - 0.1, ly - y - w, 0.0), (lx, ly - y, 3.5), glass, shadow=False)
        sign = scene.material(texture=tx.poster(r, n_shapes=8), fit=True, albedo=0.8)
        scene.box((0.0, y + 0.3, 3.6), (0.12, y + w - 0.3, 4.0), sign, shadow=False)
        y += w + r.uniform(0.5, 2.0)
    for wall_name, length in (("south", lx), ("north", lx)):
        for k in range(4):
            wall_picture(scene, r, wall=wall_name, position=length * (k + 0.5) / 4, z0=1.0, z1=2.6,
                         width=r.uniform(1.5, 3.0), room=(lx, ly))
    door = scene.material(texture=tx.panel(r, nx=4, ny=1), fit=True, albedo=0.35)
    scene.box((lx / 2 - 2.5, 0.0, 0.0), (lx / 2 + 2.5, 0.12, 3.0), door, shadow=False)
    scene.box((lx / 2 - 2.5, ly - 0.12, 0.0), (lx / 2 + 2.5, ly, 3.0), door, shadow=False)
    # upper-level windows/openings above the galleries
    upper = scene.material(texture=tx.facade(r, floors=1, windows=6), albedo=0.35, scale=(12.0, 3.0))
    scene.box((0.0, 0.0, gal_z + 1.2), (0.1, ly, gal_z + 4.2), upper, shadow=False)
    scene.box((lx - 0.1, 0.0, gal_z + 1.2), (lx, ly, gal_z + 4.2), upper, shadow=False)


def _stairs(scene: Scene, seed: int, ly: float, gal_z: float, gal_d: float) -> None:
    """Stairs to the west gallery."""
    # stairs to the west gallery
    r = stream(seed, "hall/stairs")
    step = scene.material(texture=tx.stripes(r, n=2, lo=0.35, hi=0.6), albedo=0.6, scale=(1.0, 0.3))
    sy = ly * r.uniform(0.55, 0.65)
    n_steps = 18
    for k in range(n_steps):
        scene.box((gal_d, sy + k * 0.3, 0.0), (gal_d + 1.8, sy + (k + 1) * 0.3, (k + 1) * gal_z / n_steps), step)


def _capture_area(scene: Scene, seed: int, part: int, lx: float, ly: float, lz: float, concrete: int) -> tuple:
    """The capture grid of part ``part`` with the kiosk over one corner and a pillar beside it.

    Returns the grid origin ``gx0, gy0`` (m), the existing cells, and the planter and bench materials
    (drawn from this part's random stream, used by :func:`_props`).
    """
    # the capture grid: open floor of the deserted hall (thesis 3.1), except for the information kiosk
    # standing over one corner of the grid area (the 30 cells the robot could not reach: table 3.1's
    # 170 of 10 x 20 images) and a round pillar of the hall just outside the opposite corner
    r = stream(seed, f"hall/part{part}")
    gx0 = lx / 2 - 2.25 + r.uniform(-0.5, 0.5)
    gy0 = (ly * 0.18 if part == 1 else ly * 0.55) + r.uniform(-1.0, 1.0)
    pillar = scene.material(texture=tx.value_noise(r, lo=0.45, hi=0.75, base_cells=2), albedo=0.65, scale=1.2)
    scene.cylinder((gx0 - PILLAR_GAP, gy0 + r.uniform(0.5, 2.5)), 0.0, lz, 0.45, material=pillar)
    kiosk = scene.material(texture=tx.poster(r, n_shapes=12), fit=True, albedo=0.7)
    kx0, ky0 = gx0 + KIOSK_CORNER[0], gy0 + KIOSK_CORNER[1]
    footprint = (kx0, ky0, kx0 + KIOSK_SIZE[0], ky0 + KIOSK_SIZE[1])
    scene.box((kx0, ky0, 0.0), (footprint[2], footprint[3], 2.2), kiosk)
    scene.box((kx0 - 0.1, ky0 - 0.1, 2.2), (footprint[2] + 0.1, footprint[3] + 0.1, 2.3), concrete)
    cells = _kiosk_cells((gx0, gy0), footprint, ROBOT_CLEARANCE)
    if int((~cells).sum()) != N_MISSING:
        raise RuntimeError(f"hall: the kiosk takes {int((~cells).sum())} cells, table 3.1 has {N_MISSING} missing")
    planter_mat = scene.material(texture=tx.value_noise(r, lo=0.3, hi=0.5), albedo=0.5, scale=0.8)
    bench = scene.material(texture=tx.wood(r), albedo=0.45, scale=1.0)
    return gx0, gy0, cells, planter_mat, bench


def _props(scene: Scene, seed: int, lx: float, ly: float, gal_d: float, gx0: float, gy0: float, concrete: int,
           planter_mat: int, bench: int) -> None:
    """Benches, notice boards and planters elsewhere in the hall (none near the capture grid)."""
    # more benches, bins and planters elsewhere in the hall
    r = stream(seed, "hall/props")
    for k in range(10):
        x = r.uniform(gal_d + 1.5, lx - gal_d - 1.5)
        y = r.uniform(1.0, ly - 1.0)
        if gx0 - 1.0 < x < gx0 + 5.5 and gy0 - 1.0 < y < gy0 + 10.5:
            continue
        if k % 3 == 0:
            scene.cylinder((x, y), 0.0, 0.5, 0.35, material=planter_mat)
            potted_plant(scene, stream(seed, f"hall/props/plant{k}"), x=x, y=y, height=1.8, crown=0.5,
                         min_leaf_z=0.9, leaf_glow=0.01)
        elif k % 3 == 1:
            scene.box((x - 0.9, y - 0.2, 0.4), (x + 0.9, y + 0.2, 0.46), bench)
            scene.box((x - 0.85, y - 0.2, 0.0), (x - 0.8, y + 0.2, 0.4), bench)
            scene.box((x + 0.8, y - 0.2, 0.0), (x + 0.85, y + 0.2, 0.4), bench)
        else:
            board = scene.material(texture=tx.poster(r, n_shapes=16), fit=True, albedo=0.75)
            scene.box((x - 0.6, y - 0.03, 0.5), (x + 0.6, y + 0.03, 2.0), board)
            scene.box((x - 0.55, y - 0.02, 0.0), (x - 0.5, y + 0.02, 0.5), concrete)
            scene.box((x + 0.5, y - 0.02, 0.0), (x + 0.55, y + 0.02, 0.5), concrete)


def _lights(scene: Scene, seed: int, lx: float, ly: float, gal_z: float, gal_d: float) -> None:
    """The few fluorescent lamps under the galleries that are on at night."""
    # night: no daylight through the upper windows, only a few fluorescent lamps under the galleries
    # are on (thesis 3.1: "the illumination is sparse because there are only few fluorescent lamps").
    # Most of the hall is lit only by light bounced off the lit floor patches, so the bounce
    # (ambient) term is weak and large parts of each panorama stay dark.
    r = stream(seed, "hall/lights")
    lamp = scene.material(albedo=0.7, emission=2.5)
    fitting = scene.material(albedo=0.5)
    for k in range(6):
        y = ly * (k + 0.5) / 6 + r.uniform(-1, 1)
        for x in (gal_d + 0.8, lx - gal_d - 0.8):
            on = r.random() < LAMPS_ON
            scene.box((x - 0.6, y - 0.08, gal_z - 0.56), (x + 0.6, y + 0.08, gal_z - 0.5), lamp if on else fitting,
                      shadow=False)
            if on:
                scene.add_light(PointLight((x, y, gal_z - 0.6), LAMP_INTENSITY, downward=True))
