"""``experiment=cleaning``: meandering cleaning runs of a simulated robot (thesis chapter 7).

Gerstmayr, Möller et al. (2009), "A vision-based trajectory controller for
autonomous cleaning robots", Autonome Mobile Systeme 2009,
doi:10.1007/978-3-642-10284-4_9.

``python -m bionav experiment=cleaning layout=long_lanes|short_lanes runs=10
controller=triangulation|odometry|random``

A differential-drive robot with a static wheel-speed error (``+e`` left /
``-e`` right for the first half of the runs, swapped for the second half,
unknown to its odometry) cleans the target area of a layout (``bionav/conf/layout``:
7 lanes of 4 m or 14 lanes of 2 m, 0.30 m apart, first lane by wall
following). With ``experiment.vision=render`` the robot sees 335 x 40
panoramas rendered in its own frame at its true pose in the synthetic world
``experiment.world`` and homes with ``cfg.homing`` (``minwarping_cleaning``: min-warping with
compass acceleration, by default);
with ``experiment.vision=oracle`` the home vectors come from the true geometry
plus Gaussian noise (no renderer needed).

Writes metrics.json (``coverage``, ``overlap``, ``uncovered``: fractions of the
target area, means over runs; their standard deviations; the same fractions
for the ideal meander; triangulation statistics), ``cleaning_runs.csv`` (one
row per run), run.mcap (per tick the controller's inputs and commands, the
true pose, grabbed-image digests; controller internals h, e and the chosen
snapshots; see :mod:`bionav.robot.recording`) and plots/ (trajectories of all
runs and overlap maps, thesis figs. 7.3-7.4).
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from omegaconf import DictConfig, OmegaConf

from bionav.errors import UserError
from bionav.experiments.cleaning.config import CleaningConfig
from bionav.files import write_csv_atomic
from bionav.robot.controller import LanePlan
from bionav.robot.kinematics import Pose
from bionav.robot.layout import plan_from_layout
from bionav.robot.worldview import CleaningWorld, oracle_world, rendered_world

#: log time between one run's last tick and the next run's first (runs are laid end to end after the log's start)
RUN_GAP_NS = 1_000_000_000


# ---------------------------------------------------------------------------- runs
@dataclass
class CleaningRun:
    """One simulated run and its analysis."""

    run: int
    wheel_error: tuple[float, float]
    episode: Any
    counts: np.ndarray
    fractions: dict
    fixes: list
    truth_h: np.ndarray  # true h at accepted fixes (m)
    seconds: float


def wheel_errors(runs: int, magnitude: float) -> list[tuple[float, float]]:
    """``(+e, -e)`` for the first half of the runs, ``(-e, +e)`` for the rest (thesis 7.2)."""
    half = (runs + 1) // 2
    return [(magnitude, -magnitude) if k < half else (-magnitude, magnitude) for k in range(runs)]


def true_lane_distances(episode, fixes: list, captures_true: dict[int, tuple]) -> np.ndarray:
    """True signed distance ``h`` at each fix from the true positions of its two snapshots.

    Parameters
    ----------
    episode : Episode
        The run (true poses per tick).
    fixes : list of (tick, dict)
        Accepted fixes with ``snapshots`` ids.
    captures_true : dict
        Snapshot id -> true pose ``(x, y, theta)`` at capture.
    """
    out = []
    for tick, fix in fixes:
        a = np.asarray(captures_true[fix["snapshots"][0]][:2])
        b = np.asarray(captures_true[fix["snapshots"][1]][:2])
        p = episode.true_pose[tick, :2]
        u = b - a
        out.append(float((u[0] * (p[1] - a[1]) - u[1] * (p[0] - a[0])) / np.hypot(*u)))
    return np.array(out)


def _simulate_run(ex: CleaningConfig, cfg: DictConfig, world: CleaningWorld, plan: LanePlan, make_controller, homing,
                  k: int, seeds, error: tuple[float, float], log, offset_ns: int) -> tuple[CleaningRun, int]:
    """Run ``k`` of :func:`simulate`, its ticks written to ``log`` from ``offset_ns`` on.

    Returns the result and the log time of its last tick.
    """
    from bionav.robot.coverage import Raster, coverage_fractions, sweep_counts
    from bionav.robot.kinematics import DriveModel
    from bionav.robot.lanes import to_plan_frame
    from bionav.robot.recording import EpisodeRecorder
    from bionav.robot.simulator import SimulatedRobot, run_episode

    lo, hi = plan.target_rectangle()
    raster = Raster.around(lo, hi, cell=ex.raster_cell, margin=ex.raster_margin)
    target = raster.rectangle_mask(lo, hi)
    dt = ex.dt
    controller = make_controller()
    speed = float(getattr(controller.config, "speed", 0.1))
    max_time = ex.time_limit_factor * plan.ideal_path_length / speed + 600.0
    controller_seed, camera_seed, sim_seed = (int(s) for s in seeds)
    sim_rng = np.random.default_rng(sim_seed)
    start = world.start.compose(Pose(
        ex.start_position_std * float(sim_rng.standard_normal()),
        ex.start_position_std * float(sim_rng.standard_normal()),
        float(np.radians(ex.start_heading_std_deg) * sim_rng.standard_normal())))
    confine = (lo, hi, world.start) if controller.confined else None
    camera = world.camera_factory(camera_seed) if controller.uses_camera else None
    robot = SimulatedRobot(
        DriveModel(track_width=ex.track_width, wheel_error=error), start, floor=world.floor,
        radius=ex.robot_radius, confine=confine, camera=camera, rng=sim_rng)
    controller.reset(plan, homing=homing if controller.uses_camera else None,
                     rng=np.random.default_rng(controller_seed))
    recorder = EpisodeRecorder(log, k, time_offset_ns=offset_ns, log_images=ex.log_images)
    recorder.start({
        "controller": str(cfg.controller.name),
        "controller_config": asdict(controller.config),
        "plan": asdict(plan),
        "controller_seed": controller_seed, "camera_seed": camera_seed,
        "camera": camera is not None,
        "wheel_error": list(error), "start": list(start.as_tuple()),
        "nominal_start": list(world.start.as_tuple()),
    })
    captures_true: dict[int, tuple] = {}

    def on_tick(tick, obs, cmd, robot):
        recorder.on_tick(tick, obs, cmd, robot)
        snap = cmd.info.get("snapshot") if cmd.info else None
        if snap is not None:
            captures_true[snap["id"]] = robot.pose.as_tuple()

    t0 = time.perf_counter()
    episode = run_episode(controller, robot, dt=dt, max_time=max_time, on_tick=on_tick)
    seconds = time.perf_counter() - t0
    counts = sweep_counts(to_plan_frame(episode.true_pose, world.start), raster, width=plan.unit_width)
    fractions = coverage_fractions(counts, target)
    fixes = [(t, i["fix"]) for t, i in episode.info if "fix" in i]
    accepted = [(t, f) for t, f in fixes if f.get("accepted")]
    truth = true_lane_distances(episode, accepted, captures_true) if accepted else np.zeros(0)
    return CleaningRun(k, error, episode, counts, fractions, fixes, truth, seconds), recorder.last_time_ns


class _BufferLog:
    """Collects a worker's log messages; :meth:`replay` writes them to the run log shifted in time."""

    def __init__(self) -> None:
        self.messages: list[tuple[str, dict, dict]] = []

    def write(self, topic: str, message: dict, **kwargs: Any) -> None:
        self.messages.append((topic, message, kwargs))

    @staticmethod
    def replay(messages, log, offset_ns: int) -> None:
        """Write ``messages`` to ``log`` with ``offset_ns`` added to log times and ``timestamp`` fields."""
        for topic, message, kwargs in messages:
            kwargs = dict(kwargs)
            kwargs["log_time_ns"] = int(kwargs.get("log_time_ns") or 0) + offset_ns
            stamp = message.get("timestamp")
            if isinstance(stamp, dict) and set(stamp) == {"sec", "nsec"}:
                ns = int(stamp["sec"]) * 1_000_000_000 + int(stamp["nsec"]) + offset_ns
                message = {**message, "timestamp": {"sec": ns // 1_000_000_000, "nsec": ns % 1_000_000_000}}
            log.write(topic, message, **kwargs)


#: a worker process' world, plan, controller factory and homing method (built once by :func:`_init_worker`)
_WORKER: dict[str, Any] = {}


def _init_worker(cfg_container: dict, ex: CleaningConfig) -> None:
    from bionav.config import plugin_config

    cfg = OmegaConf.create(cfg_container)
    plan = plan_from_layout(cfg.layout)
    world = make_world(ex, plan, cfg.layout)
    cls, config = plugin_config("controller", cfg.controller)
    homing = make_vision_homing(ex, cfg, world) if cls.uses_camera else None
    track_width = ex.track_width
    _WORKER.update(ex=ex, cfg=cfg, plan=plan, world=world, make_controller=lambda: cls(config, track_width=track_width),
                   homing=homing)


def _worker_run(job: tuple[int, tuple, tuple]) -> tuple[CleaningRun, list, int]:
    k, seeds, error = job
    w = _WORKER
    log = _BufferLog()
    result, last_ns = _simulate_run(w["ex"], w["cfg"], w["world"], w["plan"], w["make_controller"], w["homing"], k,
                                    seeds, error, log, 0)
    return result, log.messages, last_ns


def simulate(ex: CleaningConfig, cfg: DictConfig, ctx, world: CleaningWorld, plan: LanePlan, make_controller, homing,
             *, workers: int = 1) -> list[CleaningRun]:
    """Run ``ex.runs`` simulated cleaning runs (``ex``: the checked ``experiment`` node), logging each to ``ctx.log``.

    With ``workers > 1`` the runs are simulated in that many processes (each
    builds the world once); every run has its own seeds, drawn before any
    run starts, so results and log are the same as with one worker (the
    workers' messages are written in run order, laid end to end in time).
    """
    from bionav.robot.recording import RESULT_TOPIC

    runs = ex.runs
    if runs < 1:
        raise UserError(f"runs must be at least 1, got {runs}; set runs=10 as in the thesis.")
    errors = wheel_errors(runs, ex.wheel_error)
    seeds = ctx.rng.integers(0, 2**31 - 1, size=(runs, 3))
    results = []
    # log times: the log's wall-clock start plus simulated time (Foxglove shows real dates, not 1970)
    offset_ns = int(getattr(ctx.log, "start_ns", None) or time.time_ns())
    workers = max(1, min(int(workers), runs))

    def finish(result: CleaningRun, last_ns: int) -> None:
        nonlocal offset_ns
        fixes = result.fixes
        accepted = [f for _, f in fixes if f.get("accepted")]
        ctx.log.write(RESULT_TOPIC, {"run": result.run, "wheel_error": list(result.wheel_error), **result.fractions,
                                     "finished": bool(result.episode.finished),
                                     "ticks": int(len(result.episode.time)), "fixes": len(fixes),
                                     "accepted_fixes": len(accepted), "seconds": result.seconds},
                      schema_name="bionav.CleaningResult", log_time_ns=last_ns)
        results.append(result)
        offset_ns = last_ns + RUN_GAP_NS

    if workers == 1:
        for k in ctx.progress(range(runs), desc="cleaning runs", total=runs):
            result, last_ns = _simulate_run(ex, cfg, world, plan, make_controller, homing, k, seeds[k], errors[k],
                                            ctx.log, offset_ns)
            finish(result, last_ns)
        return results

    from bionav.experiments.common import worker_pool

    jobs = [(k, tuple(int(v) for v in seeds[k]), errors[k]) for k in range(runs)]
    container = OmegaConf.to_container(cfg, resolve=True)
    with worker_pool(workers, initializer=_init_worker, initargs=(container, ex)) as pool:
        for result, messages, last_ns in ctx.progress(pool.imap(_worker_run, jobs), desc="cleaning runs",
                                                      total=runs):
            _BufferLog.replay(messages, ctx.log, offset_ns)
            finish(result, last_ns + offset_ns)
    return results


def summarise(results: list[CleaningRun], plan: LanePlan, ideal: dict) -> dict[str, Any]:
    """Flat metrics: means (and stds) over runs plus triangulation statistics."""
    out: dict[str, Any] = {}
    for key in ("coverage", "overlap", "uncovered"):
        vals = np.array([r.fractions[key] for r in results])
        out[key] = float(vals.mean())
        out[f"{key}_std"] = float(vals.std(ddof=1)) if len(vals) > 1 else 0.0
    for key in ("coverage", "overlap", "uncovered"):
        out[f"ideal_{key}"] = ideal[key]
    out["n_runs"] = len(results)
    out["finished_runs"] = int(sum(r.episode.finished for r in results))
    n_fix = sum(len(r.fixes) for r in results)
    accepted = [f for r in results for _, f in r.fixes if f.get("accepted")]
    out["fixes"] = n_fix
    out["fix_acceptance"] = float(len(accepted) / n_fix) if n_fix else 0.0
    if accepted:
        h = np.array([f["h"] for f in accepted])
        truth = np.concatenate([r.truth_h for r in results])
        desired = np.array([abs(f["h"] - f["e"]) for f in accepted])
        out["h_error_rms"] = float(np.sqrt(np.mean((h - truth) ** 2)))
        out["lane_distance_error_rms"] = float(np.sqrt(np.mean((np.abs(truth) - desired) ** 2)))
    out["seconds_per_run"] = float(np.mean([r.seconds for r in results]))
    return out


def write_runs_csv(path, results: list[CleaningRun]) -> None:
    """``cleaning_runs.csv``: one row per run."""
    rows = []
    for r in results:
        acc = [f for _, f in r.fixes if f.get("accepted")]
        herr = (float(np.sqrt(np.mean((np.array([f["h"] for f in acc]) - r.truth_h) ** 2))) if acc else "")
        rows.append([r.run, r.wheel_error[0], r.wheel_error[1], f"{r.fractions['coverage']:.6f}",
                     f"{r.fractions['overlap']:.6f}", f"{r.fractions['uncovered']:.6f}", int(r.episode.finished),
                     len(r.episode.time), len(r.fixes), len(acc), herr if herr == "" else f"{herr:.6f}"])
    write_csv_atomic(path, ["run", "wheel_error_left", "wheel_error_right", "coverage", "overlap", "uncovered",
                            "finished", "ticks", "fixes", "accepted_fixes", "h_error_rms"], rows)


def make_oracle_homing(ex: CleaningConfig, seed: int):
    """The oracle homing method of ``experiment.oracle`` (noisy home vectors from true geometry)."""
    from bionav.robot.oracle import GeometricHoming, GeometricHomingConfig

    node = ex.oracle
    return GeometricHoming(GeometricHomingConfig(angle_noise_deg=node.angle_noise_deg,
                                                 compass_noise_deg=node.compass_noise_deg,
                                                 seed=int(seed)))


def make_world(ex: CleaningConfig, plan: LanePlan, layout) -> CleaningWorld:
    """The :class:`~bionav.robot.worldview.CleaningWorld` that ``experiment.vision`` asks for (``layout``: the node)."""
    if ex.vision != "render":
        return oracle_world(plan)
    return rendered_world(plan, world=ex.world, world_seed=ex.world_seed, camera=ex.camera,
                          robot_height=ex.robot_height, robot_radius=ex.robot_radius, layout=layout)


def make_vision_homing(ex: CleaningConfig, cfg: DictConfig, world: CleaningWorld):
    """The homing method of a run: ``cfg.homing`` on rendered images, or the oracle."""
    if ex.vision == "oracle":
        return make_oracle_homing(ex, int(cfg.seed))
    from bionav.config import plugin_config

    cls, config = plugin_config("homing", cfg.homing)
    return cls(config, geometry=world.geometry)


def run(ex: CleaningConfig, ctx) -> dict[str, Any]:
    """Run ``experiment=cleaning`` with the checked ``ex`` (the rest of the config in ``ctx.cfg``)."""
    from bionav.experiments.cleaning.plots import plot_layout, plot_overlap_maps, plot_trajectories
    from bionav.experiments.common import make_homing
    from bionav.robot.coverage import Raster, coverage_fractions, sweep_counts
    from bionav.robot.lanes import ideal_meander

    cfg = ctx.cfg
    if cfg.get("layout") is None:
        raise UserError("experiment=cleaning needs a layout; choose layout=long_lanes or layout=short_lanes.")
    if cfg.get("controller") is None or not cfg.controller.get("name"):
        raise UserError("experiment=cleaning needs a controller; choose controller=triangulation, "
                        "controller=odometry or controller=random.")
    plan = plan_from_layout(ctx.nodes.get("layout") or cfg.layout)
    vision = ex.vision
    world = make_world(ex, plan, cfg.layout)

    from bionav.config import plugin_config

    cls, config = plugin_config("controller", cfg.controller)

    def make_controller():
        return cls(config, track_width=ex.track_width)

    homing = None
    if cls.uses_camera:
        homing = make_homing(cfg, ctx, world.geometry) if vision == "render" else make_oracle_homing(ex, int(cfg.seed))

    results = simulate(ex, cfg, ctx, world, plan, make_controller, homing, workers=int(cfg.get("workers") or 1))

    lo, hi = plan.target_rectangle()
    raster = Raster.around(lo, hi, cell=ex.raster_cell, margin=ex.raster_margin)
    ideal = coverage_fractions(sweep_counts(ideal_meander(plan), raster, width=plan.unit_width),
                               raster.rectangle_mask(lo, hi))
    metrics = summarise(results, plan, ideal)
    metrics["layout"] = str(cfg.layout.name)
    metrics["controller"] = str(cfg.controller.name)
    metrics["vision"] = vision
    metrics["guide_wall"] = bool(world.guide_wall)
    write_runs_csv(ctx.dir / "cleaning_runs.csv", results)
    plot_trajectories(ctx.plots / "trajectories.png", results, world, plan,
                      title=f"{cfg.controller.name}, {cfg.layout.name}")
    plot_overlap_maps(ctx.plots / "overlap_map.png", ctx.plots / "overlap_maps_all.png", results, raster, plan)
    plot_layout(ctx.plots / "layout.png", results, world, plan)
    return metrics
