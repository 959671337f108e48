"""Typed configuration of the ``db`` group (validated by Hydra)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Optional


@dataclass
class UnfoldConfig:
    """Unfolding of raw omnidirectional (mirror) camera frames.

    ``center`` is ``[cx, cy]`` in pixels of the raw frame, radii in pixels,
    ``size`` the unfolded ``[W, H]``. ``inner_radius`` maps to the bottom row
    (lowest elevation), ``outer_radius`` to the top row.
    """

    enabled: bool = False
    center: Optional[list[float]] = None
    inner_radius: float = 0.0
    outer_radius: float = 0.0
    size: list[int] = field(default_factory=lambda: [288, 50])


@dataclass
class DatabaseConfig:
    """Where a database comes from and how its images are to be read.

    Conventions describe the images *as they lie on disk*; loading converts
    them to canonical panoramas (:mod:`bionav.geometry`).
    """

    name: str = "sim_original"
    source: str = "synthetic"  # synthetic | folder
    path: Optional[str] = None  # folder databases: the directory
    image_size: Optional[list[int]] = None  # [W, H]; None keeps the native size
    seed: int = 0  # synthetic worlds: which world of this kind
    noise: float = 0.01  # synthetic: camera noise std before 8-bit quantisation
    naming: str = "auto"  # auto | vardy | moeller | csv
    azimuth: str = "clockwise"  # how azimuth grows with the column index on disk
    x_axis_column: float = 0.0  # on-disk column that looks along the grid's +x axis
    horizon_row: Optional[float] = None  # on-disk horizon row; None = middle row
    rad_per_row: Optional[float] = None  # vertical angle per pixel; None = same as horizontal
    spacing_m: float = 0.3
    grid_shape: Optional[list[int]] = None  # [nx, ny]; None = bounding box of the cells found
    on_bad_image: str = "error"  # error | skip
    rotate_current: bool = False  # Vardy's protocol: random rotation of each current view
    rotation_seed: int = 0
    unfold: UnfoldConfig = field(default_factory=UnfoldConfig)
    extra: dict[str, Any] = field(default_factory=dict)
    # mesh worlds (source: mesh | route; see bionav/db/mesh.py and docs/worlds.md)
    world: Optional[str] = None  # a packaged world (seville2009) when no path is given
    origin_m: Optional[list[float]] = None  # world (x, y) in metres of grid cell (0, 0); None = centred
    camera_height_m: float = 0.01  # camera height over the local terrain, metres
    ground: str = "auto"  # plane | mesh | auto (.mat: plane at z = 0, .obj/.ply: the mesh)
    channels: str = "grey"  # grey | spectral (UV B G R IR)
    clearance_m: Optional[float] = None  # a cell is missing if a triangle lies this close above it; None = any
    route: Optional[str] = None  # route databases: Ant<a>_Route<r>
    routes_path: Optional[str] = None  # .mat of routes; None = the packaged Seville routes
    step_m: float = 0.1  # route databases: distance between views along the route, metres
