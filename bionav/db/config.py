"""Typed configuration of the ``db`` group (validated by Hydra)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Optional

from bionav.validation import Range, bounded

#: largest image side (pixels) a database or unfolded image may have
MAX_IMAGE_SIDE = 16384
#: largest grid side (cells) of a database
MAX_GRID_SIDE = 10_000


@dataclass
class UnfoldConfig:
    """Unfolding of raw omnidirectional (mirror) camera frames.

    ``center`` is ``[cx, cy]`` in pixels of the raw frame, radii in pixels,
    ``size`` the unfolded ``[W, H]``. ``inner_radius`` maps to the bottom row
    (lowest elevation), ``outer_radius`` to the top row.
    """

    enabled: bool = False
    center: Optional[list[float]] = bounded(None, length=2, item=Range(ge=0.0, le=100_000.0))
    inner_radius: float = bounded(0.0, ge=0.0, le=100_000.0)
    outer_radius: float = bounded(0.0, ge=0.0, le=100_000.0)
    size: list[int] = bounded([288, 50], length=2, item=Range(ge=2, le=MAX_IMAGE_SIDE))


@dataclass
class DatabaseConfig:
    """Where a database comes from and how its images are to be read.

    Conventions describe the images *as they lie on disk*; loading converts
    them to canonical panoramas (:mod:`bionav.geometry`).
    """

    name: str = "sim_original"
    source: str = bounded("synthetic", choices=("synthetic", "folder", "mesh", "route"))
    path: Optional[str] = None  # folder databases: the directory
    image_size: Optional[list[int]] = bounded(None, length=2, item=Range(ge=2, le=MAX_IMAGE_SIDE))  # [W, H]; None: native
    seed: int = bounded(0, ge=0, le=2**32 - 1)  # synthetic worlds: which world of this kind
    noise: float = bounded(0.01, ge=0.0, le=1.0)  # synthetic: camera noise std before 8-bit quantisation
    naming: str = bounded("auto", choices=("auto", "vardy", "moeller", "csv"))
    # how azimuth grows with the column index on disk
    azimuth: str = bounded("clockwise", choices=("clockwise", "counterclockwise", "cw", "ccw", "anticlockwise",
                                                 "counter-clockwise"))
    x_axis_column: float = bounded(0.0, ge=-100_000.0, le=100_000.0)  # on-disk column along the grid's +x axis
    horizon_row: Optional[float] = bounded(None, ge=-100_000.0, le=100_000.0)  # on-disk horizon row; None = middle
    rad_per_row: Optional[float] = bounded(None, gt=0.0, le=1.0)  # vertical angle per pixel; None = horizontal's
    spacing_m: float = bounded(0.3, gt=0.0, le=1000.0)
    grid_shape: Optional[list[int]] = bounded(None, length=2, item=Range(ge=1, le=MAX_GRID_SIDE))  # None: bounding box
    on_bad_image: str = bounded("error", choices=("error", "skip"))
    rotate_current: bool = False  # Vardy's protocol: random rotation of each current view
    rotation_seed: int = bounded(0, ge=0, le=2**32 - 1)
    unfold: UnfoldConfig = field(default_factory=UnfoldConfig)
    extra: dict[str, Any] = field(default_factory=dict)
    # mesh worlds (source: mesh | route; see bionav/db/mesh.py and docs/worlds.md)
    world: Optional[str] = bounded(None, choices=("seville2009",))  # a packaged world when no path is given
    # world (x, y) in metres of grid cell (0, 0); None = centred on the world
    origin_m: Optional[list[float]] = bounded(None, length=2, item=Range(ge=-1e6, le=1e6))
    camera_height_m: float = bounded(0.01, gt=0.0, le=100.0)  # camera height over the local terrain, metres
    ground: str = bounded("auto", choices=("auto", "plane", "mesh"))  # auto: .mat plane at z = 0, .obj/.ply the mesh
    channels: str = bounded("grey", choices=("grey", "spectral"))  # spectral: UV B G R IR
    # a cell is missing if a triangle lies this close above its terrain point; None = at any height
    clearance_m: Optional[float] = bounded(None, gt=0.0, le=1000.0)
    route: Optional[str] = None  # route databases: Ant<a>_Route<r>
    routes_path: Optional[str] = None  # .mat of routes; None = the packaged Seville routes
    step_m: float = bounded(0.1, gt=0.0, le=10.0)  # route databases: path length between views, metres
