"""Config of ``experiment=route_homing``: following real ant routes in mesh worlds.

Units: metres and grid units as named; angles in degrees only in keys ending ``_deg``; times ISO 8601
with zone. Checked by the runner before the run (:func:`bionav.experiments.settings.experiment_config`).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any, Optional

from bionav.errors import UserError
from bionav.validation import Range, bounded

ROUTE_METHODS = ("perfect_memory", "windowed", "zernike", "homing")
ROUTE_PROTOCOLS = ("bionav", "ardin2016")
#: ``experiment.sweep`` axes (``ardin2016``): the experiment key each varies (``camera_height_m`` is ``db.camera_height_m``)
SWEEP_AXES = ("position_jitter_m", "heading_noise_deg", "start_offset_m", "training_stride", "camera_height_m",
              "routes_learned_together")
#: labels of ``experiment.worlds``
_WORLD_LABEL = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")


@dataclass
class RouteHomingConfig:
    """``experiment=route_homing``: following real ant routes (docs/worlds.md).

    routes : route names (``Ant<a>_Route<r>``); empty = ``db.route`` (``bionav``) or Route1 of Ant1..Ant15 (``ardin2016``).
    methods : subset of ``perfect_memory``, ``windowed``, ``zernike``, ``homing``.
    offsets_m : lateral offsets of the open-loop test points, metres (left positive); must include 0.
    test_stride : every k-th route view is a test point.
    error_threshold_deg : heading error below which a test point is inside the route's catchment.
    window : snapshots ahead of the last match searched by ``windowed`` (and by ``homing`` to track progress).
    lookahead : ``homing`` targets the snapshot this many views ahead of the best match.
    test_step_m : test-step length of methods with test steps, metres.
    closed_loop : run the simulated agent from a displaced start.
    start_offset_m, agent_step_m, success_radius_m, give_up_m : the agent's start displacement (left
        positive; null: the protocol's, 0.2 for ``bionav``, 0 for ``ardin2016``), step (null: the protocol's,
        0.05 for ``bionav``, 0.1 for ``ardin2016``), success radius around the route's end and give-up
        distance from the route, metres.
    max_steps_factor : step budget = factor x route length / agent step.
    zernike_order : highest Zernike-moment order of the ``zernike`` method.
    protocol : ``bionav`` (the tests above: open loop at lateral offsets, closed loop from a displaced
        start with a full 360-degree choice of heading; harder) or ``ardin2016`` (the published test of
        Ardin et al. 2016, doi:10.1371/journal.pcbi.1004683: start on the route, scan
        ``+-scan_half_deg`` in ``scan_step_deg`` around the current heading, step ``agent_step_m``,
        put back on the nearest route view and count an error beyond ``putback_m``).
    agents : ``ardin2016``: route agents (``bionav.route_agents``: ``perfect_memory``,
        ``windowed_memory``, ``infomax``, ``mushroom_body``) and homing methods (``bionav.homing``
        names, e.g. ``minwarping``, ``mfdid``, ``sift``, ``parameter``) following the route by homing
        to the view ``lookahead`` after the best match.
    agent_params : ``ardin2016``: ``{agent: {parameter: value}}`` overrides of the agents' configs
        (command line: ``+experiment.agent_params.mushroom_body.n_kc=5000``).
    seeds : ``ardin2016``: noise seeds (camera noise, position jitter, random networks); one run each.
    position_jitter_m : ``ardin2016``: Gaussian position noise added after each step, metres (std per axis).
    scan_half_deg, scan_step_deg : ``ardin2016``: the scan around the current heading, degrees.
    putback_m : ``ardin2016``: distance from the route beyond which the agent is put back (an error),
        and the radius around the nest that ends the run, metres.
    view_size : ``ardin2016``: ``[W, H]`` of the agents' views (the paper's 36 x 10).
    training_heading : ``ardin2016``: the training views face the direction of travel to the next route
        view (``travel``) or the ant's recorded heading there (``recorded``); the put-back faces the same.
    supersample : ``ardin2016``: rays per 4-degree pixel along each axis (1: one ray at the pixel centre;
        2, 4: the mean of 2 x 2 or 4 x 4 rays, area pixels as the reference renderer's rasterised patches).
    heading_noise_deg : ``ardin2016``: Gaussian noise (std, degrees) added to every heading an agent
        chooses before it steps (not in the paper).
    training_stride : ``ardin2016``: the agents learn every k-th route view (1: all, 0.1 m apart); the
        put-back rule keeps the whole route.
    routes_learned_together : ``ardin2016``: the familiarity agents learn the views of this many routes
        (the followed one and the next ones of ``routes``, cyclically) and follow each (capacity).
    passed, route_weight, follower_window : ``ardin2016`` homing followers: a target view the agent has
        passed (its home direction more than 90 degrees off the route direction there) is kept or
        skipped (``skip``: home to the next, at most ``lookahead`` views further); the heading blends
        the home direction with the route direction stored with the target view (0: homing only,
        1: the stored direction only); the windowed RIDF that tracks progress searches from one view
        behind to ``follower_window`` ahead of the last match
        (:class:`bionav.evaluation.route_followers.HomingFollower`).
    sweep : ``ardin2016``: robustness axes ``{axis: [levels]}`` (axes :data:`SWEEP_AXES`); each level
        is run with every other setting as given, and ``robustness.csv`` and ``plots/robustness_<axis>.png``
        summarise them (docs/worlds.md).
    worlds : ``ardin2016``: second worlds ``{label: {db: preset, <db key>: value, routes: [...]}}``, each a
        condition of the sweep's ``world`` axis (:mod:`bionav.experiments.route_homing.worlds`): a robot's drive
        (``db: bag``) or a mesh world with routes (``db: seville_route``, ``path``, ``routes_path``, ``routes``).
    block : ``ardin2016``: ``[i, n]``: this run is task i of n, every n-th group of units (one route, seed and
        condition) from the i-th; ``python -m bionav.experiments.merge OUT TASK_DIR...`` joins the tasks.
    """

    name: str = "route_homing"
    routes: list[str] = bounded([], length=(0, 1000))
    methods: list[str] = bounded(list(ROUTE_METHODS), length=(1, 4), item=Range(choices=ROUTE_METHODS))
    offsets_m: list[float] = bounded([-0.4, -0.2, -0.1, 0.0, 0.1, 0.2, 0.4], length=(1, 100),
                                     item=Range(ge=-5.0, le=5.0))
    test_stride: int = bounded(5, ge=1, le=10_000)
    error_threshold_deg: float = bounded(45.0, gt=0.0, le=180.0)
    window: int = bounded(10, ge=1, le=10_000)
    lookahead: int = bounded(2, ge=1, le=1000)
    test_step_m: float = bounded(0.05, gt=0.0, le=1.0)
    closed_loop: bool = True
    start_offset_m: Optional[float] = bounded(None, ge=-5.0, le=5.0)
    agent_step_m: Optional[float] = bounded(None, gt=0.0, le=1.0)
    success_radius_m: float = bounded(0.2, gt=0.0, le=5.0)
    give_up_m: float = bounded(1.0, gt=0.0, le=20.0)
    max_steps_factor: float = bounded(2.0, ge=1.0, le=20.0)
    zernike_order: int = bounded(16, ge=1, le=40)
    plots: bool = True
    protocol: str = bounded("bionav", choices=ROUTE_PROTOCOLS)
    agents: list[str] = bounded(["perfect_memory", "windowed_memory", "infomax", "mushroom_body"], length=(1, 50))
    agent_params: dict[str, Any] = field(default_factory=dict)
    seeds: list[int] = bounded([0], length=(1, 100), item=Range(ge=0, le=2**32 - 1))
    position_jitter_m: float = bounded(0.0, ge=0.0, le=1.0)
    scan_half_deg: float = bounded(60.0, gt=0.0, le=180.0)
    scan_step_deg: int = bounded(2, choices=(1, 2, 4))
    putback_m: float = bounded(0.2, gt=0.0, le=5.0)
    view_size: list[int] = bounded([36, 10], length=2, item=Range(ge=2, le=74))
    training_heading: str = bounded("travel", choices=("travel", "recorded"))
    supersample: int = bounded(4, choices=(1, 2, 4))
    heading_noise_deg: float = bounded(0.0, ge=0.0, le=180.0)
    training_stride: int = bounded(1, ge=1, le=100)
    routes_learned_together: int = bounded(1, ge=1, le=1000)
    passed: str = bounded("skip", choices=("keep", "skip"))
    route_weight: float = bounded(0.5, ge=0.0, le=1.0)
    follower_window: int = bounded(5, ge=1, le=10_000)
    sweep: dict[str, Any] = field(default_factory=dict)
    worlds: dict[str, Any] = field(default_factory=dict)
    block: Optional[list[int]] = bounded(None, length=(2, 2), item=Range(ge=0, le=10**6))

    def validate(self) -> None:
        """``offsets_m`` includes 0, the route itself; ``sweep`` names known axes with lists of levels in range.

        Called by :func:`bionav.validation.typed_config`.
        """
        if 0.0 not in self.offsets_m:
            raise UserError(f"experiment.offsets_m={self.offsets_m} must include 0 (the route itself), "
                            "e.g. experiment.offsets_m=[-0.2,0.0,0.2].")
        for axis, levels in self.sweep.items():
            if axis not in SWEEP_AXES:
                raise UserError(f"experiment.sweep: unknown axis {axis!r}; the axes are {', '.join(SWEEP_AXES)} "
                                "(e.g. +experiment.sweep.position_jitter_m=[0,0.01,0.02]).")
            if not isinstance(levels, (list, tuple)) or not levels:
                raise UserError(f"experiment.sweep.{axis} must be a non-empty list of levels, e.g. "
                                f"+experiment.sweep.{axis}=[...].")
            for level in levels:
                sweep_level(self, axis, level)
        if self.block is not None and self.protocol != "ardin2016":
            raise UserError("experiment.block splits the published test (experiment.protocol=ardin2016) into tasks; "
                            "add experiment.protocol=ardin2016 or drop experiment.block.")
        if self.worlds:
            if self.protocol != "ardin2016":
                raise UserError("experiment.worlds runs the published test in second worlds: add "
                                "experiment.protocol=ardin2016.")
            check_worlds(self.worlds)


def check_worlds(worlds: dict) -> None:
    """``experiment.worlds``: labels that are plain names, each world a mapping (called by :meth:`RouteHomingConfig.validate`)."""
    for label, entry in worlds.items():
        if not isinstance(label, str) or not _WORLD_LABEL.match(label):
            raise UserError(f"experiment.worlds: bad label {label!r}; use letters, digits, '_', '-' or '.', e.g. "
                            "+experiment.worlds.pillars={db:bag,path:DRIVE,image_topic:/camera/image,pose_topic:/odom}.")
        if not isinstance(entry, dict):
            raise UserError(f"experiment.worlds.{label} must be a mapping of db keys (and routes), e.g. "
                            f"+experiment.worlds.{label}={{db:bag,path:DRIVE,image_topic:/camera/image,pose_topic:/odom}}.")
        routes = entry.get("routes")
        if routes is not None and (not isinstance(routes, (list, tuple)) or not routes
                                   or not all(isinstance(r, str) for r in routes)):
            raise UserError(f"experiment.worlds.{label}.routes must be a non-empty list of route names, e.g. "
                            "routes:[Ant1_Route1,Ant2_Route1].")


def sweep_level(exp: "RouteHomingConfig", axis: str, level: Any) -> Any:
    """``level`` of sweep axis ``axis`` checked against the range of the key it sets (one message naming both)."""
    import dataclasses

    from bionav.validation import check_config, range_of

    if axis == "camera_height_m":
        from bionav.db.config import DatabaseConfig

        rng = range_of(next(f for f in dataclasses.fields(DatabaseConfig) if f.name == "camera_height_m"))
        if isinstance(level, bool) or not isinstance(level, (int, float)) or rng.problem(level):
            raise UserError(f"experiment.sweep.camera_height_m: bad level {level!r}; db.camera_height_m takes "
                            f"{rng.describe()}.")
        return float(level)
    kind = type(getattr(exp, axis))
    if isinstance(level, bool) or not isinstance(level, (int, float)) or (kind is int and level != int(level)):
        raise UserError(f"experiment.sweep.{axis}: bad level {level!r}; give numbers "
                        f"({'whole numbers' if kind is int else 'metres or degrees as the key says'}).")
    value = kind(level) if kind in (int, float) else float(level)
    try:
        check_config(dataclasses.replace(exp, sweep={}, **{axis: value}), prefix="experiment")
    except UserError as exc:
        raise UserError(f"experiment.sweep.{axis}: bad level {level!r} ({exc})") from None
    return value
