"""What a world builder returns, and the seeding helper every builder uses."""

from __future__ import annotations

import zlib
from typing import Callable
from dataclasses import dataclass, field

import numpy as np

from bionav.world.scene import Scene


def stream(seed: int, name: str) -> np.random.Generator:
    """An independent random stream for one named part of a world.

    Every object of a world draws from its own stream (keyed by the world seed
    and a stable hash of the object's name), so adding an object to a variant
    never changes the rest of the world.
    """
    return np.random.default_rng(np.random.SeedSequence([int(seed) & 0xFFFFFFFF, zlib.crc32(name.encode())]))


@dataclass
class World:
    """A scene plus where a database's capture grid lies in it.

    Parameters
    ----------
    scene : Scene
        The renderable world.
    grid_origin : (float, float)
        World position ``(x, y)`` in metres of grid cell ``(0, 0)``; cell
        ``(i, j)`` lies at ``grid_origin + spacing * (i, j)`` (grid axes =
        world axes).
    spacing : float
        Grid spacing in metres.
    grid_shape : (int, int)
        ``(nx, ny)`` cells.
    camera_height : float
        Height of the camera (mirror centre) above the floor in metres.
    cells : ndarray, shape (nx, ny), bool
        Cells that exist (False where an obstacle stands).
    free_area : tuple of float, optional
        ``(x0, y0, x1, y1)`` of an obstacle-free floor rectangle (apartment).
    info : dict
        Free-form facts about the world (room size, sun position ...).
    floor_tilt_deg : float
        Standard deviation in degrees, about each horizontal axis, of the
        camera's tilt where the robot stands: the unevenness of the floor
        (rug edges and carpet pile under one wheel, tile and paving joints,
        slopes) and the sway of the camera mast after the robot stops. The
        camera model of the stand-ins (:func:`bionav.db.camera.camera_images`)
        tilts every capture by a Gaussian draw of this size unless
        ``db.pose_error.tilt_sigma_deg`` is given.
    capture_scene : callable, optional
        ``capture_scene(i, j) -> Scene``: the world as lit when cell ``(i, j)``
        was captured, for worlds whose light changed during the capture (the
        outdoor *uni*: sun, clouds). The camera model renders every capture
        with it; ``None`` (and ``db.realism=ideal``) use ``scene``.
    """

    scene: Scene
    grid_origin: tuple[float, float]
    spacing: float
    grid_shape: tuple[int, int]
    camera_height: float
    cells: np.ndarray | None = None
    free_area: tuple[float, float, float, float] | None = None
    info: dict = field(default_factory=dict)
    floor_tilt_deg: float = 0.0
    capture_scene: Callable[[int, int], Scene] | None = None

    def __post_init__(self) -> None:
        if self.cells is None:
            self.cells = np.ones(self.grid_shape, bool)

    def cell_position(self, i: float, j: float) -> tuple[float, float, float]:
        """World position ``(x, y, z)`` of the camera at grid cell ``(i, j)``."""
        return (self.grid_origin[0] + self.spacing * i, self.grid_origin[1] + self.spacing * j, self.camera_height)
