"""Where a cleaning robot runs: the world it sees (rendered, or an empty room for oracle runs), its lanes placed
in it, its camera (:class:`CleaningWorld`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from bionav.errors import UserError
from bionav.robot.controller import LanePlan
from bionav.robot.floorplan import FloorPlan
from bionav.robot.kinematics import Pose


def load_world(name: str, *, seed: int = 0):
    """Build the synthetic world ``name`` (a :class:`bionav.world.worlds.common.World`)."""
    import importlib

    try:
        worlds = importlib.import_module("bionav.world.worlds")
    except ModuleNotFoundError:
        raise UserError("the renderer (bionav.world) is not available in this installation; run the cleaning "
                        "experiment with experiment.vision=oracle (home vectors from true geometry).") from None
    build = getattr(worlds, "build_world", None)
    if build is not None:
        return build(name, seed=seed)
    try:
        module = importlib.import_module(f"bionav.world.worlds.{name}")
    except ModuleNotFoundError:
        raise UserError(f"there is no synthetic world named {name!r}; set experiment.world=apartment.") from None
    return getattr(module, f"build_{name}")(seed)


def render_camera(scene, geometry, *, height: float, noise: float = 0.0, seed: int = 0) -> Callable[[Pose, int], np.ndarray]:
    """A camera rendering grey panoramas in the robot's own frame.

    Parameters
    ----------
    scene : Scene
        The world.
    geometry : PanoramaGeometry
        Output size and elevation mapping (335 x 40 in the thesis).
    height : float
        Camera height above the floor, m.
    noise : float
        Std of Gaussian pixel noise added before 8-bit quantisation.
    seed : int
        Seed of the noise; capture ``k`` uses ``default_rng([seed, k])`` so a
        capture can be re-created exactly (replay).

    Returns
    -------
    callable
        ``camera(true_pose, capture_index) -> ndarray (H, W) float32`` in
        ``[0, 1]``, canonical panorama (column 0 along the robot's heading).
    """
    from bionav.world.render import render_panorama

    def camera(pose: Pose, index: int) -> np.ndarray:
        img = render_panorama(scene, position=(pose.x, pose.y, height), heading=pose.theta, geometry=geometry)
        grey = img.mean(axis=2) if img.ndim == 3 else img
        if noise > 0:
            grey = grey + noise * np.random.default_rng([int(seed), int(index)]).standard_normal(grey.shape)
        return (np.round(np.clip(grey, 0.0, 1.0) * 255.0) / 255.0).astype(np.float32)

    return camera


def plan_clearance(floor: FloorPlan, plan: LanePlan, start: Pose, *, step: float = 0.1,
                   skip_first_lane: bool = False) -> float:
    """Smallest distance (m) from the ideal meander's path to any obstacle outline.

    With ``skip_first_lane`` the first lane (which runs along a wall at
    ``plan.wall_offset`` by design) is left out.
    """
    from bionav.robot.lanes import ideal_meander, to_world_frame

    pts = ideal_meander(plan, step=step)
    if skip_first_lane:
        pts = pts[int(np.ceil(plan.lane_length / step)) + 1:]
    pts = to_world_frame(pts, start)
    return min((floor.clearance(p[0], p[1]) for p in pts), default=np.inf)


def _inside(floor: FloorPlan, plan: LanePlan, start: Pose) -> bool:
    from bionav.robot.lanes import to_world_frame

    (x0, y0), (x1, y1) = plan.target_rectangle()
    far = plan.side * (plan.n_lanes - 1) * plan.spacing
    corners = to_world_frame(np.array([[x0, 0.0, 0], [x1, 0.0, 0], [x0, far, 0], [x1, far, 0]]), start)
    return all(floor.enclosed(p[0], p[1]) for p in corners)


@dataclass(frozen=True)
class Placement:
    """Where the layout lies in the world.

    Attributes
    ----------
    start : Pose
        World pose of the plan frame (start of the first lane, heading along it).
    floor : FloorPlan
        The world's floor plan, plus the guide wall if one was added.
    guide_wall : bool
        True when no wall of the world runs along the first lane and a straight
        guide (a low strip the side sensor and the bumper see, not rendered)
        was added on its right for wall following.
    """

    start: Pose
    floor: FloorPlan
    guide_wall: bool


def _wall_along(floor: FloorPlan, plan: LanePlan, start: Pose) -> bool:
    u = np.array([np.cos(start.theta), np.sin(start.theta)])
    for f in (0.0, 0.5, 1.0):
        q = np.array([start.x, start.y]) + f * plan.lane_length * u
        r = floor.raycast(q[0], q[1], start.theta - np.pi / 2, max_range=plan.wall_offset + 0.05)
        if abs(r - plan.wall_offset) >= 0.01:
            return False
    return True


def _with_guide(floor: FloorPlan, plan: LanePlan, start: Pose) -> FloorPlan:
    u = np.array([np.cos(start.theta), np.sin(start.theta)])
    right = np.array([u[1], -u[0]])
    p = np.array([start.x, start.y]) + plan.wall_offset * right
    a, b = p - 0.5 * u, p + (plan.lane_length + 0.5) * u
    segs = np.vstack([floor.segments, [[a[0], a[1], b[0], b[1]]]])
    is_wall = np.r_[floor.is_wall if floor.is_wall is not None else np.zeros(len(floor.segments), bool), True]
    return FloorPlan(segs, is_wall)


def place_plan(world, floor: FloorPlan, plan: LanePlan, *, layout: Any = None,
               robot_radius: float = 0.17) -> Placement:
    """Place the layout in the world: the plan frame's pose and the floor plan to simulate with.

    With ``layout.start = [x, y]`` and ``layout.start_heading_deg`` given, that
    pose is used. Otherwise the first lane is placed along a wall (any obstacle
    outline at least a lane long, on the robot's right at ``plan.wall_offset``
    along the whole first lane) such that the ideal meander keeps the largest
    clearance from every obstacle; candidates start every 0.1 m along every
    such segment, in both directions. If no wall qualifies and the world has a
    ``free_area``, the layout is centred along the best edge of the free area
    and a straight guide wall is added there for the first lane's wall
    following (:class:`Placement`). A given start pose without a wall on the
    right gets a guide wall as well.

    Raises
    ------
    UserError
        When the given pose or every candidate brings the ideal lanes closer
        than ``robot_radius`` to an obstacle.
    """
    if layout is not None and layout.get("start") is not None:
        x, y = (float(v) for v in layout.start)
        start = Pose(x, y, float(np.radians(float(layout.get("start_heading_deg") or 0.0))))
        if plan_clearance(floor, plan, start) < robot_radius:
            raise UserError(f"the layout's start pose {list(layout.start)} puts the lanes into an obstacle; "
                            f"choose another layout.start / layout.start_heading_deg, or omit them for automatic "
                            f"placement.")
        if _wall_along(floor, plan, start):
            return Placement(start, floor, False)
        return Placement(start, _with_guide(floor, plan, start), True)
    best, best_clear = None, -np.inf
    for x0, y0, x1, y1 in floor.segments:
        for a, b in (((x0, y0), (x1, y1)), ((x1, y1), (x0, y0))):
            u = np.array(b) - np.array(a)
            length = float(np.hypot(*u))
            if length < plan.lane_length + 0.4:
                continue
            u /= length
            heading = float(np.arctan2(u[1], u[0]))
            left = np.array([-u[1], u[0]])
            for s in np.arange(0.2, length - plan.lane_length - 0.2 + 1e-9, 0.1):
                p = np.array(a) + s * u + plan.wall_offset * left
                start = Pose(float(p[0]), float(p[1]), heading)
                if not _wall_along(floor, plan, start) or not _inside(floor, plan, start):
                    continue
                if plan_clearance(floor, plan, start, step=0.2) < robot_radius:
                    continue
                c = plan_clearance(floor, plan, start, step=0.2, skip_first_lane=True)
                if c > best_clear + 1e-9:
                    best, best_clear = start, c
    if best is not None and best_clear >= robot_radius:
        return Placement(best, floor, False)
    free = getattr(world, "free_area", None)
    if free is not None:
        fx0, fy0, fx1, fy1 = (float(v) for v in free)
        ring = [(fx0, fy0), (fx1, fy0), (fx1, fy1), (fx0, fy1)]  # counter-clockwise: inside on the left
        if plan.side < 0:
            ring = ring[::-1]
        depth_needed = plan.wall_offset + (plan.n_lanes - 1) * plan.spacing + plan.unit_width / 2
        for i in range(4):
            a, b = np.array(ring[i]), np.array(ring[(i + 1) % 4])
            length = float(np.hypot(*(b - a)))
            u = (b - a) / length
            other = np.array(ring[(i + 2) % 4]) - b
            depth = abs(float(u[0] * other[1] - u[1] * other[0]))
            if length < plan.lane_length or depth < depth_needed:
                continue
            left = plan.side * np.array([-u[1], u[0]])
            p = a + 0.5 * (length - plan.lane_length) * u + plan.wall_offset * left
            start = Pose(float(p[0]), float(p[1]), float(np.arctan2(u[1], u[0])))
            c = plan_clearance(floor, plan, start, step=0.2)
            if c > best_clear + 1e-9:
                best, best_clear = start, c
        if best is not None and best_clear >= robot_radius:
            return Placement(best, _with_guide(floor, plan, best), True)
    raise UserError(f"the {plan.n_lanes} x {plan.lane_length} m layout does not fit along any wall of the world "
                    f"(best clearance {best_clear:.2f} m < robot radius {robot_radius} m); choose a smaller "
                    f"layout or give layout.start and layout.start_heading_deg.")


@dataclass
class CleaningWorld:
    """Where the runs happen.

    Attributes
    ----------
    floor : FloorPlan
        Obstacles (collisions, wall sensor).
    start : Pose
        World pose of the plan frame's origin (nominal start of the first lane).
    camera_factory : callable
        ``camera_factory(seed) -> camera(true_pose, capture_index) -> image``.
    geometry : PanoramaGeometry or None
        Geometry of the rendered images (None in oracle mode).
    scene : object
        The rendered scene (None in oracle mode).
    guide_wall : bool
        A straight guide wall was added for the first lane's wall following
        (the world has no wall where the layout fits).
    """

    floor: Any
    start: Pose
    camera_factory: Callable[[int], Callable]
    geometry: Any = None
    scene: Any = None
    guide_wall: bool = False


def oracle_world(plan: LanePlan, *, margin: float = 1.0) -> CleaningWorld:
    """An empty room for oracle runs: the plan frame is the world frame, the wall along the first lane.

    The first lane's wall lies ``plan.wall_offset`` to the right of the first
    lane; the other walls ``margin`` metres beyond the target area.
    """
    from bionav.robot.floorplan import FloorPlan
    from bionav.robot.oracle import oracle_camera

    (x0, y0), (x1, y1) = plan.target_rectangle()
    if plan.side > 0:
        lo, hi = (x0 - margin, -plan.wall_offset), (x1 + margin, y1 + margin)
    else:
        lo, hi = (x0 - margin, y0 - margin), (x1 + margin, plan.wall_offset)
    floor = FloorPlan.from_shapes(rooms=[(lo, hi)])
    return CleaningWorld(floor=floor, start=Pose(0.0, 0.0, 0.0), camera_factory=lambda seed: oracle_camera)


def rendered_world(plan: LanePlan, *, world: str, world_seed: int, camera, robot_height: float, robot_radius: float,
                   layout: Any = None) -> CleaningWorld:
    """The synthetic world ``world`` with the layout placed in it (:func:`place_plan`), and a rendering camera.

    ``camera`` has ``width``, ``height`` (pixels), ``horizon_row`` (None: the middle row),
    ``height_m`` (above the floor) and ``noise`` (``experiment.camera``); ``robot_height`` and
    ``robot_radius`` in metres; ``layout`` the ``layout`` node (its ``start`` and ``start_heading_deg``).
    """
    from bionav.geometry import PanoramaGeometry
    from bionav.robot.floorplan import floorplan_from_scene

    scene_world = load_world(world, seed=world_seed)
    cam = camera
    geometry = PanoramaGeometry.square_pixels(
        int(cam.width), int(cam.height), horizon_row=None if cam.horizon_row is None else float(cam.horizon_row))
    floor = floorplan_from_scene(scene_world.scene, max_height=robot_height)
    placement = place_plan(scene_world, floor, plan, layout=layout, robot_radius=robot_radius)
    height = float(cam.height_m)
    noise = float(cam.noise)

    def factory(seed: int):
        return render_camera(scene_world.scene, geometry, height=height, noise=noise, seed=seed)

    return CleaningWorld(floor=placement.floor, start=placement.start, camera_factory=factory, geometry=geometry,
                         scene=scene_world.scene, guide_wall=placement.guide_wall)
