"""Typed configuration of the ``db`` group (validated by Hydra)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Optional

from bionav.validation import Range, bounded

#: largest image side (pixels) a database or unfolded image may have
MAX_IMAGE_SIDE = 16384
#: ``db.image_size = [W, H]``: the one limit of a database's image size (W spans 360 degrees; the
#: homing methods and the renderers need W >= 8 columns and H >= 2 rows)
IMAGE_SIZE = dict(length=2, items=(Range(ge=8, le=MAX_IMAGE_SIDE), Range(ge=2, le=MAX_IMAGE_SIDE)), names=("W", "H"))
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
class CameraConfig:
    """Catadioptric camera of the synthetic stand-ins (used when ``db.realism=camera``).

    Mirror (unified central catadioptric model, :mod:`bionav.world.catadioptric`):
    ``mirror_xi`` and the rim (elevation and raw radius of the mirror's edge);
    the raw frame is ``raw_size`` pixels with the mirror centred. Sensor
    (:mod:`bionav.db.camera`): optics blur (Gaussian PSF), vignetting (relative
    illumination ``1 - vignetting * (r / rim radius)**2``), automatic exposure
    (mean raw level ``ae_target``, exposure time up to ``max_exposure`` times the
    world's nominal exposure, then analogue gain up to ``max_gain``), shot noise
    (``full_well_e`` electrons at full scale) and read noise, 8-bit raw frame.
    Defaults: the ultra-wide-view mirror; ``db=sim_uni`` sets the normal-view mirror.
    """

    raw_size: list[int] = bounded([640, 480], length=2, item=Range(ge=64, le=4096))  # [w, h] pixels
    mirror_xi: float = bounded(0.82, gt=0.05, lt=1.0)  # hyperbolic mirror parameter of the unified model
    rim_elevation_deg: float = bounded(36.0, ge=0.0, le=80.0)  # upper limit of the field of view
    rim_radius_px: float = bounded(230.0, ge=16.0, le=2048.0)  # raw radius of the mirror rim
    psf_sigma_px: float = bounded(0.8, ge=0.0, le=10.0)  # optics blur, Gaussian std in raw pixels
    vignetting: float = bounded(0.3, ge=0.0, le=0.95)  # illumination loss at the mirror rim
    auto_exposure: bool = True
    ae_target: float = bounded(0.4, gt=0.0, lt=1.0)  # mean raw level the automatic exposure aims at
    max_exposure: float = bounded(4.0, ge=0.01, le=1000.0)  # longest exposure / the world's nominal one
    max_gain: float = bounded(4.0, ge=1.0, le=64.0)  # largest analogue gain after the longest exposure
    full_well_e: float = bounded(10000.0, ge=10.0, le=1e7)  # electrons at full scale (gain 1): shot noise
    read_noise_e: float = bounded(12.0, ge=0.0, le=1e4)  # read noise std in electrons


@dataclass
class PoseErrorConfig:
    """Capture-pose errors of the synthetic stand-ins (used when ``db.realism=camera``).

    Each image is rendered at its grid position plus a Gaussian offset (std
    ``position_sigma_m`` per axis, metres) and with a Gaussian heading error
    (std ``heading_sigma_deg``) and tilt (std ``tilt_sigma_deg`` about each
    horizontal axis; ``null``: the world's floor, ``World.floor_tilt_deg``); the
    database still reports the nominal grid (the ground truth of the real
    databases is the nominal grid too). ``heading_drift_deg`` adds odometry's
    heading drift: a Gaussian heading change (std ``heading_drift_deg``) at each
    turn between two lanes, accumulated along the lanes (a random walk; a
    position correction does not remove it); ``null``: the world's floor,
    ``World.heading_drift_deg``. Drawn from ``seed`` (together with
    ``db.seed``).
    """

    position_sigma_m: float = bounded(0.02, ge=0.0, le=10.0)
    heading_sigma_deg: float = bounded(1.5, ge=0.0, le=180.0)
    tilt_sigma_deg: Optional[float] = bounded(None, ge=0.0, le=20.0)
    heading_drift_deg: Optional[float] = bounded(None, ge=0.0, le=45.0)
    seed: int = bounded(0, ge=0, le=2**32 - 1)


@dataclass
class DatabaseConfig:
    """Where a database comes from and how its images are to be read.

    Conventions describe the images *as they lie on disk*; loading converts
    them to canonical panoramas (:mod:`bionav.geometry`).
    """

    name: str = "sim_original"
    source: str = bounded("synthetic", choices=("synthetic", "folder", "mesh", "route", "bag"))
    path: Optional[str] = None  # folder databases: the directory; bag: the ROS bag (file or ROS 2 folder)
    image_size: Optional[list[int]] = bounded(None, **IMAGE_SIZE)  # [W, H]; None: native
    seed: int = bounded(0, ge=0, le=2**32 - 1)  # synthetic worlds: which world of this kind
    noise: float = bounded(0.01, ge=0.0, le=1.0)  # synthetic, realism=ideal: noise std before 8-bit quantisation
    # synthetic: 'camera' renders the raw mirror image and unfolds it (docs/databases.md), 'ideal' the old
    # direct panoramas; db=sim_* configs choose camera
    realism: str = bounded("ideal", choices=("ideal", "camera"))
    camera: CameraConfig = field(default_factory=CameraConfig)
    pose_error: PoseErrorConfig = field(default_factory=PoseErrorConfig)
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
    # ROS bags (source: bag; bionav/db/bag, docs/ros.md)
    image_topic: Optional[str] = None  # sensor_msgs/Image or CompressedImage topic
    pose_topic: Optional[str] = None  # nav_msgs/Odometry, geometry_msgs/PoseStamped(WithCovariance) or /tf
    pose_frame: Optional[str] = None  # with /tf: the robot's frame (None: base_link)
    world_frame: Optional[str] = None  # the frame positions are given in (None: the pose topic's, the tf root)
    pose_tolerance_s: float = bounded(0.1, gt=0.0, le=60.0)  # an image needs a pose this close before and after it
    stamps: str = bounded("header", choices=("header", "bag"))  # message times: header.stamp or the bag's record time
    grid_cell_m: Optional[float] = bounded(None, gt=0.0, le=1000.0)  # grid database: cell size, metres
    route_step_m: float = bounded(0.1, gt=0.0, le=100.0)  # route: path length between route views, metres
    align: bool = True  # grid: turn every view to the world frame by its heading (column 0 along world +x)

    def unused_keys(self) -> tuple[list[str], tuple[str, ...]]:
        """Keys given a value this database does not use, and the keys its source uses.

        Called by :func:`bionav.validation.typed_config`. A key outside
        :data:`USED_KEYS` ``[source]`` must keep its default, or the value the
        database has anyway (:meth:`own_values`: a synthetic stand-in's own
        grid, spacing and horizon, the canonical azimuth of rendered images),
        which the presets record for the reader.
        """
        import dataclasses

        used = USED_KEYS.get(self.source, ())
        own: dict[str, Any] | None = None
        unused = []
        for f in dataclasses.fields(self):
            if f.name in used:
                continue
            value = getattr(self, f.name)
            default = f.default if f.default is not dataclasses.MISSING else f.default_factory()
            if value == default:
                continue
            own = self.own_values() if own is None else own
            if f.name in own and _same(value, own[f.name]):
                continue
            unused.append(f.name)
        return unused, used

    def validate(self) -> None:
        """Relations between keys (called by :func:`bionav.validation.typed_config`)."""
        from bionav.errors import UserError

        if self.source in ("mesh", "route") and self.path is None and self.world is None:
            raise UserError(f"db={self.name} needs the mesh file: pass db.path=FILE (.mat with X/Y/Z[/colp], .obj "
                            "or .ply), or db.world=seville2009 for the packaged Seville ant world.")
        if self.source == "bag" and self.path is None:
            raise UserError("db=bag needs the bag: pass db.path=BAG (a ROS 1 .bag, a ROS 2 bag folder, or a .mcap / "
                            ".db3 file), with db.image_topic=TOPIC and db.pose_topic=TOPIC (docs/ros.md).")
        if self.source == "mesh" and self.grid_shape is None:
            raise UserError(f"db={self.name} needs its grid: pass db.grid_shape=[nx,ny], e.g. db.grid_shape=[10,10].")

    def own_values(self) -> dict[str, Any]:
        """Values this database has whatever the config says (keys outside :data:`USED_KEYS`)."""
        if self.source == "synthetic":
            from bionav.db.standins import get_spec

            spec = get_spec(self.name)
            geometry = spec.geometry(*spec.native_size)
            return {"grid_shape": list(spec.grid_shape), "spacing_m": spec.spacing_m,
                    "horizon_row": geometry.horizon_row, "azimuth": "counterclockwise"}
        if self.source in ("mesh", "route"):
            return {"azimuth": "counterclockwise"}
        return {}


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    return a == b


_ALL_SOURCES = ("name", "source", "image_size")
#: the ``db.*`` keys each ``db.source`` uses (any other key must keep its default: a key a database does
#: not use is an error naming these)
USED_KEYS: dict[str, tuple[str, ...]] = {
    "synthetic": _ALL_SOURCES + ("seed", "noise", "realism", "camera", "pose_error", "rotate_current",
                                 "rotation_seed"),
    "folder": _ALL_SOURCES + ("path", "naming", "azimuth", "x_axis_column", "horizon_row", "rad_per_row",
                              "spacing_m", "grid_shape", "on_bad_image", "rotate_current", "rotation_seed",
                              "unfold", "extra"),
    "mesh": _ALL_SOURCES + ("path", "world", "grid_shape", "spacing_m", "origin_m", "camera_height_m", "ground",
                            "channels", "clearance_m", "noise", "seed", "rotate_current", "rotation_seed"),
    "route": _ALL_SOURCES + ("path", "world", "route", "routes_path", "step_m", "camera_height_m", "ground",
                             "channels", "clearance_m", "noise", "seed"),
    "bag": _ALL_SOURCES + ("path", "image_topic", "pose_topic", "pose_frame", "world_frame", "pose_tolerance_s",
                           "stamps", "grid_cell_m", "route_step_m", "align", "origin_m", "grid_shape", "azimuth",
                           "x_axis_column", "horizon_row", "rad_per_row", "unfold", "on_bad_image", "rotate_current",
                           "rotation_seed"),
}
