"""What a world builder returns, and the seeding helper every builder uses.

A world whose light changed while its database was recorded has a capture light
(:class:`~bionav.light.capture.CaptureLight`: the sun, the clouds and the sky at each capture) and an
aperture where that light enters: the whole sky outdoors (:class:`OpenSky`), a room's windows indoors
(:class:`Windows`). :meth:`World.capture_scenes` is the one capture interface of both: the world as it
was at each capture of a recording session (with the person who supervised it, :class:`Supervisor`).
"""

from __future__ import annotations

import copy
import math
import zlib
from dataclasses import dataclass, field, replace
from typing import Callable

import numpy as np

from bionav.light.capture import CaptureLight
from bionav.world.lights import Ambient, DirectionalLight
from bionav.world.scene import CompiledScene, Scene


def stream(seed: int, name: str) -> np.random.Generator:
    """An independent random stream for one named part of a world.

    Every object of a world draws from its own stream (keyed by the world seed
    and a stable hash of the object's name), so adding an object to a variant
    never changes the rest of the world.
    """
    return np.random.default_rng(np.random.SeedSequence([int(seed) & 0xFFFFFFFF, zlib.crc32(name.encode())]))


def lane_order(grid_shape: tuple[int, int], *, lane_axis: int = 1) -> np.ndarray:
    """Capture index of every grid cell when a robot drives boustrophedon lanes.

    Lanes run along grid axis ``lane_axis`` and follow each other along the
    other axis (lane 0 first), in alternate directions: lane 0 from index 0 up,
    lane 1 back down, and so on.

    Parameters
    ----------
    grid_shape : (int, int)
        ``(nx, ny)``.
    lane_axis : int
        Grid axis (0: ``i``, 1: ``j``) along which the lanes run.

    Returns
    -------
    ndarray, shape (nx, ny), int
        0, 1, 2 ... ``nx * ny - 1`` in driving order.
    """
    ii, jj = np.meshgrid(np.arange(grid_shape[0]), np.arange(grid_shape[1]), indexing="ij")
    along, across = (jj, ii) if lane_axis == 1 else (ii, jj)
    n_along = int(grid_shape[lane_axis])
    return across * n_along + np.where(across % 2 == 0, along, n_along - 1 - along)


@dataclass(frozen=True)
class Windows:
    """Where the capture light enters a room: its windows (geometry of an indoor world).

    The living-room databases took hours to record (a supervised robot, its
    position corrected semi-automatically at every cell; thesis 3.1, Kreft
    2007). Meanwhile the sun moved: its light, entering through the windows,
    lays bright patches on the floor, the furniture and the walls that move
    across the room and come and go with passing clouds, and the brightness
    of the sky seen through the windows changes. The light itself (sun path,
    clouds, skylight factor per capture) is the world's
    :class:`~bionav.light.capture.CaptureLight` (``World.capture_light``); this
    class is the room's side, the world's ``aperture``: which openings let the sun in, which lights
    and panes stand for the sky outside. Used by the camera model only
    (``db.realism=camera``, :meth:`World.capture_scenes`);
    ``db.realism=ideal`` renders the scene as built.

    Parameters
    ----------
    room : (float, float, float)
        Inner room size ``(lx, ly, lz)`` in metres (the room shell spans
        ``[0, lx] x [0, ly] x [0, lz]``).
    windows : tuple of (str, float, float, float, float)
        Openings the sun can shine through: ``(wall, u0, u1, z0, z1)`` with
        ``wall`` in ``"x0", "x1", "y0", "y1"`` (the wall at ``x = 0``,
        ``x = lx``, ``y = 0``, ``y = ly``), ``u0 .. u1`` the span along the
        wall and ``z0 .. z1`` the height span, metres.
    sky_lights : tuple of int
        Indices into ``scene.lights`` of the lights standing for the skylight
        through the windows; scaled by the capture light's skylight factor.
    panes : tuple of int
        Material indices of the window panes; their emission is scaled like
        the skylight.
    """

    room: tuple[float, float, float]
    windows: tuple[tuple[str, float, float, float, float], ...]
    sky_lights: tuple[int, ...] = ()
    panes: tuple[int, ...] = ()

    def session_scene(self, scene: Scene, *, sun_irradiance: float) -> Scene:
        """A copy of ``scene`` with the sun added and the room closed against it except at the windows.

        ``sun_irradiance``: the unclouded sun's irradiance on a surface facing
        it (:attr:`CaptureLight.sun_irradiance <bionav.light.capture.CaptureLight>`),
        in the units of the scene's lights.

        The walls of the room shell cast no shadows (the lamps are inside);
        the sun, outside, must be blocked by the walls and the ceiling except
        where the windows are: thin shadow-casting slabs just outside the
        shell (never seen from inside) with holes at ``windows``. The sun is
        the last light of the copy.
        """
        s = copy.deepcopy(scene)
        s.info.pop("_compiled", None)
        lx, ly, lz = self.room
        t, m = 0.05, 0.01  # slab thickness, gap outside the shell
        blk = s.material(albedo=0.0)
        s.box((-m - t, -m - t, lz + m), (lx + m + t, ly + m + t, lz + m + t), blk)  # above the ceiling
        for wall in ("x0", "x1", "y0", "y1"):
            length = ly if wall[0] == "x" else lx
            holes = sorted((u0, u1, z0, z1) for w, u0, u1, z0, z1 in self.windows if w == wall)
            pieces = []  # (u0, u1, z0, z1) slabs covering the wall minus its holes
            u = -m - t
            for u0, u1, z0, z1 in holes:
                pieces += [(u, u0, 0.0, lz + m), (u0, u1, 0.0, z0), (u0, u1, z1, lz + m)]
                u = u1
            pieces.append((u, length + m + t, 0.0, lz + m))
            for u0, u1, z0, z1 in pieces:
                if u1 - u0 <= 0 or z1 - z0 <= 0:
                    continue
                if wall[0] == "x":
                    x0 = -m - t if wall == "x0" else lx + m
                    s.box((x0, u0, z0), (x0 + t, u1, z1), blk)
                else:
                    y0 = -m - t if wall == "y0" else ly + m
                    s.box((u0, y0, z0), (u1, y0 + t, z1), blk)
        s.add_light(DirectionalLight((0.0, 0.0, 1.0), float(sun_irradiance)))
        return s

    def capture_lighting(self, session: CompiledScene, *, sun_index: int, sky_index: np.ndarray, sun_dir,
                         transmission: float, sky: float) -> dict:
        """Light arrays of the compiled session scene at one capture (for ``dataclasses.replace``).

        Sun direction and power, skylight lights and pane emission scaled;
        the shadow bins must be rebuilt (the sun moved).
        """
        params = session.light_params.copy()
        params[sun_index, 1:4] = sun_dir
        power = session.light_power.copy()
        power[sun_index] *= transmission
        power[sky_index] *= sky
        emission = session.mat_emission.copy()
        emission[list(self.panes)] *= sky
        return {"light_params": params, "light_power": power, "mat_emission": emission}


@dataclass(frozen=True)
class OpenSky:
    """Where the capture light enters outdoors: the whole sky (the aperture of an outdoor world).

    Each capture relights the scene as :meth:`CaptureLight.conditions
    <bionav.light.capture.CaptureLight.conditions>` gives the light at its cell: the sun (direction,
    irradiance after the clouds), the sky's ambient light above and ``ground_ambient`` times it below
    (light reflected by the ground), and the sky seen by rays that hit nothing (:meth:`Scene.relit`,
    which keeps the compiled geometry). Used by the camera model only (``db.realism=camera``).

    Parameters
    ----------
    ground_ambient : float
        Ambient light from below relative to the sky's from above (dimensionless).
    """

    ground_ambient: float = 0.4

    def capture_scene(self, scene: Scene, light: CaptureLight, cell) -> Scene:
        """``scene`` relit as at the capture of grid cell ``cell = (i, j)``."""
        i, j = (int(v) for v in cell)
        cond = light.conditions(i, j)
        up = np.asarray(cond["sky_irradiance"], float)
        return scene.relit(lights=[DirectionalLight(tuple(float(v) for v in cond["sun"]),
                                                    tuple(float(v) for v in cond["sun_irradiance"]))],
                           ambient=Ambient(up=tuple(up), down=tuple(self.ground_ambient * up)), sky=cond["sky"])


@dataclass(frozen=True)
class Supervisor:
    """The person who supervised a recording, standing behind the robot in every image.

    The living-room databases were recorded with a supervised robot whose
    position was corrected semi-automatically (thesis 3.1, Kreft 2007): a
    person stayed close to it, and an omnidirectional camera cannot be
    hidden from. The supervisor follows the robot along its lanes
    (boustrophedon along grid axis ``lane_axis``), standing ``distance_m``
    behind it (against its driving direction) with a Gaussian scatter of
    ``jitter_m`` per horizontal axis, facing the robot, inside the room at
    least ``margin_m`` from the walls. Used by the camera model only
    (``db.realism=camera``); the stance is drawn per recording session
    (``db.pose_error.seed``, ``db.seed``).

    Parameters
    ----------
    room : (float, float)
        Inner room size ``(lx, ly)`` in metres.
    distance_m, jitter_m, margin_m : float
        Metres.
    height_m : float
        The person's height.
    lane_axis : int
        Grid axis (0: ``i``, 1: ``j``) along which the robot drove its lanes.
    """

    room: tuple[float, float]
    distance_m: float = 1.2
    jitter_m: float = 0.3
    margin_m: float = 0.3
    height_m: float = 1.75
    lane_axis: int = 1

    def stances(self, cells: np.ndarray, xy: np.ndarray, *, seed: int) -> tuple[np.ndarray, np.ndarray]:
        """Where the supervisor stands at each capture.

        Parameters
        ----------
        cells : ndarray, shape (N, 2), int
            Grid cells ``(i, j)`` (the lane is the index across ``lane_axis``).
        xy : ndarray, shape (N, 2)
            Robot positions in metres, world frame.
        seed : int
            The recording session's seed.

        Returns
        -------
        feet : ndarray, shape (N, 2)
            Position of the person in metres, world frame.
        yaw : ndarray, shape (N,)
            Direction the person faces (towards the robot), radians CCW from ``+x``.
        """
        cells = np.asarray(cells, np.int64).reshape(-1, 2)
        xy = np.asarray(xy, float).reshape(-1, 2)
        lane = cells[:, 1 - self.lane_axis]
        forward = np.where(lane % 2 == 0, 1.0, -1.0)  # driving direction along the lane axis
        back = np.zeros_like(xy)
        back[:, self.lane_axis] = -forward
        rng = stream(seed, "supervisor/stance")
        feet = xy + self.distance_m * back + self.jitter_m * rng.standard_normal(xy.shape)
        lo, hi = self.margin_m, np.asarray(self.room, float) - self.margin_m
        feet = np.clip(feet, lo, hi)
        d = xy - feet
        return feet, np.arctan2(d[:, 1], d[:, 0])

    def add_to(self, scene: Scene, *, seed: int) -> tuple[slice, slice]:
        """Add the person at the origin facing ``+x``; returns the slices of its boxes and ellipsoids."""
        from bionav.world.worlds.furniture import person

        b0, e0 = len(scene.boxes), len(scene.ellipsoids)
        n_frusta = len(scene.frusta)
        person(scene, stream(seed, "supervisor/looks"), height=self.height_m)
        if len(scene.frusta) != n_frusta:
            raise RuntimeError("the supervisor's figure must consist of boxes and spheres")
        return slice(b0, len(scene.boxes)), slice(e0, len(scene.ellipsoids))

    @staticmethod
    def place(boxes: np.ndarray, ellipsoids: np.ndarray, parts: tuple[slice, slice], feet, yaw: float):
        """Copies of the compiled ``boxes`` and ``ellipsoids`` with the person moved to ``feet``, turned to ``yaw``."""
        bs, es = parts
        c, s = float(np.cos(yaw)), float(np.sin(yaw))
        boxes = boxes.copy()
        ellipsoids = ellipsoids.copy()
        for arr, sl in ((boxes, bs), (ellipsoids, es)):
            x, y = arr[sl, 0].copy(), arr[sl, 1].copy()
            arr[sl, 0] = feet[0] + c * x - s * y
            arr[sl, 1] = feet[1] + s * x + c * y
        cb, sb = boxes[bs, 6].copy(), boxes[bs, 7].copy()
        boxes[bs, 6] = c * cb - s * sb
        boxes[bs, 7] = s * cb + c * sb
        return boxes, ellipsoids


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
    capture_light : CaptureLight, optional
        The light during the recording (sun path, clouds; camera model only),
        entering through ``aperture``.
    aperture : Windows or OpenSky, optional
        Where ``capture_light`` enters (given with it): a room's windows, or the whole sky outdoors.
    supervisor : Supervisor, optional
        The person supervising the recording (camera model only, indoors).
    floor_tilt_deg : float
        Standard deviation in degrees, about each horizontal axis, of the
        camera's tilt where the robot stands: the unevenness of the floor
        (rug edges and carpet pile under one wheel, tile and paving joints,
        slopes) and the sway of the camera mast after the robot stops. The
        camera model of the stand-ins (:func:`bionav.db.camera.camera_images`)
        tilts every capture by a Gaussian draw of this size unless
        ``db.pose_error.tilt_sigma_deg`` is given.
    heading_drift_deg : float
        Standard deviation in degrees of the robot's heading change at each
        turn between two lanes that its odometry did not see (wheel slip;
        more on carpet pile than on hard floors). The camera model adds the
        accumulated drift to every capture's heading
        (:func:`bionav.db.camera.lane_heading_drift`) unless
        ``db.pose_error.heading_drift_deg`` is given.
    light_level : float
        Light reaching the camera, relative to the light at which the
        scene's nominal exposure (``scene.exposure``) renders it at normal
        brightness; dimensionless, > 0. The camera model multiplies the
        radiance by it before the sensor, whose automatic exposure then
        compensates within ``max_exposure`` x ``max_gain`` and adds the noise
        of a dim scene (:func:`bionav.db.camera.camera_images`).
        ``db.realism=ideal`` ignores it. 1 for every world but the night hall.
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
    heading_drift_deg: float = 0.0
    light_level: float = 1.0
    capture_light: CaptureLight | None = None
    aperture: Windows | OpenSky | None = None
    supervisor: Supervisor | None = None

    def __post_init__(self) -> None:
        if not (math.isfinite(self.light_level) and self.light_level > 0):
            raise ValueError(f"World.light_level must be a finite number > 0, got {self.light_level!r}")
        if (self.capture_light is None) != (self.aperture is None):
            raise ValueError("World.capture_light and World.aperture come together (the capture light and where "
                             "it enters: a room's Windows or the OpenSky); give both or neither")
        if self.cells is None:
            self.cells = np.ones(self.grid_shape, bool)

    def cell_position(self, i: float, j: float) -> tuple[float, float, float]:
        """World position ``(x, y, z)`` of the camera at grid cell ``(i, j)``."""
        return (self.grid_origin[0] + self.spacing * i, self.grid_origin[1] + self.spacing * j, self.camera_height)

    def capture_scenes(self, positions: np.ndarray, *, seed: int) -> Callable[[int], Scene | CompiledScene] | None:
        """``scene_at(k)``: the world as it was at capture ``k`` of a recording session; None if it did not change.

        The one capture interface of indoor and outdoor worlds (the camera model,
        :func:`bionav.db.camera.camera_images`). Outdoors (:class:`OpenSky`) each capture relights a
        copy of the scene (a :class:`Scene`). Indoors (:class:`Windows`) the sun, the clouds and the
        sky through the windows, and the :attr:`supervisor`, are added once to a compiled copy of the
        scene and each capture only moves lights and the person in its arrays (a
        :class:`CompiledScene`, which renders without the scene's exposure).

        Parameters
        ----------
        positions : ndarray, shape (N, 2), int
            Grid cells ``(i, j)`` in capture order of the database (not the time order).
        seed : int
            The recording session's seed (:func:`bionav.db.camera.session_seed`): the clouds along the
            capture order indoors and where the supervisor stood.
        """
        if self.capture_light is None and self.supervisor is None:
            return None
        if isinstance(self.aperture, OpenSky):
            if self.supervisor is not None:
                raise ValueError("a supervisor is modelled for indoor worlds only")
            light, sky = self.capture_light, self.aperture
            return lambda k: sky.capture_scene(self.scene, light, positions[k])
        if getattr(self.scene, "sky", None) is not None:
            raise ValueError("recording-session changes through windows (capture light, supervisor) are modelled for "
                             "indoor worlds only (a compiled scene renders without the world's sky)")
        return self._indoor_session(positions, seed)

    def _indoor_session(self, positions: np.ndarray, seed: int) -> Callable[[int], CompiledScene]:
        """:meth:`capture_scenes` of a room: its compiled session scene, changed per capture."""
        daylight, supervisor, windows = self.capture_light, self.supervisor, self.aperture
        scene = (windows.session_scene(self.scene, sun_irradiance=daylight.sun_irradiance) if daylight is not None
                 else copy.deepcopy(self.scene))
        scene.info.pop("_compiled", None)
        parts = supervisor.add_to(scene, seed=seed) if supervisor is not None else None
        session = scene.compiled()
        if daylight is not None:
            kinds = session.light_params[:, 0]
            sun = int(np.flatnonzero(kinds == 1)[-1])
            sky = []
            for idx in windows.sky_lights:
                pos = np.asarray(self.scene.lights[idx].position, float)
                hit = np.flatnonzero((kinds == 0) & np.all(np.isclose(session.light_params[:, 1:4], pos), axis=1))
                sky.append(int(hit[0]))
            sky = np.asarray(sky, np.int64)
            cond = daylight.session_conditions(positions, rng=stream(seed, "daylight/clouds"))
        if supervisor is not None:
            xy = np.array([self.cell_position(i, j)[:2] for i, j in positions], float).reshape(-1, 2)
            feet, yaw = supervisor.stances(positions, xy, seed=seed)

        def scene_at(k: int) -> CompiledScene:
            kw = {}
            if daylight is not None:
                kw.update(windows.capture_lighting(session, sun_index=sun, sky_index=sky, sun_dir=cond["sun_dir"][k],
                                                   transmission=float(cond["transmission"][k]),
                                                   sky=float(cond["sky"][k])))
            if supervisor is not None:
                boxes, ell = Supervisor.place(session.boxes, session.ellipsoids, parts, feet[k], float(yaw[k]))
                kw.update(boxes=boxes, ellipsoids=ell, prim_kind=None, prim_idx=None, spheres=None, casters=None)
            return replace(session, **kw, shadow_grids=None, shadow_starts=None, shadow_items=None)

        return scene_at
