"""Replay of logged cleaning runs: ``python -m bionav.experiments.cleaning_replay RUN_DIR_OR_MCAP``.

Rebuilds controller, homing method, layout and (for images that were not logged) the camera from
the config attached to ``run.mcap`` and checks that the controller emits the logged commands exactly.
"""

from __future__ import annotations

from typing import Any

from omegaconf import OmegaConf

from bionav.config import plugin_config
from bionav.errors import UserError
from bionav.experiments.cleaning.run import make_vision_homing, make_world
from bionav.experiments.settings import config_from_recorded, experiment_config
from bionav.logs.reader import read_attachment, read_messages, read_metadata
from bionav.robot.layout import plan_from_layout
from bionav.robot.recording import load_logged_runs, replay_episode


def replay_log(path, *, runs: list[int] | None = None) -> dict[int, Any]:
    """Replay the runs of a cleaning ``run.mcap`` through freshly built controllers.

    The resolved config attached to the log (keys of earlier versions read as
    today's: :func:`~bionav.experiments.settings.config_from_recorded`) rebuilds the layout, the world
    (its camera re-creates images that were not logged), the homing method
    and the controller; :func:`bionav.robot.recording.replay_episode` then
    checks every command.

    Returns
    -------
    dict
        Run index -> :class:`~bionav.robot.recording.ReplayResult`.

    Raises
    ------
    ReplayMismatch
        At the first difference.
    """

    raw = read_attachment(path, "config.yaml")
    if raw is None:
        raise UserError(f"{path} has no attached config.yaml; it was not written by `python -m bionav`.")
    recorded_by = read_metadata(path).get("plugins", {}).get("bionav")
    cfg = config_from_recorded(OmegaConf.create(raw.decode()), source=str(path),
                               recorded_by=recorded_by and f"bionav {recorded_by}")
    if cfg.experiment.name != "cleaning":
        raise UserError(f"{path} is a log of experiment={cfg.experiment.name}, not of experiment=cleaning.")
    plan = plan_from_layout(cfg.layout)
    logged = load_logged_runs(read_messages(path))
    ex = experiment_config(cfg)  # the recorded experiment node, checked as a run's
    cls, config = plugin_config("controller", cfg.controller)
    world = make_world(ex, plan, cfg.layout) if cls.uses_camera else None
    homing = make_vision_homing(ex, cfg, world) if cls.uses_camera else None
    out = {}
    for k in sorted(logged) if runs is None else runs:
        if k not in logged:
            raise UserError(f"{path} has no run {k}; it holds runs {sorted(logged)}.")
        camera = world.camera_factory(int(logged[k].meta["camera_seed"])) if world is not None else None
        out[k] = replay_episode(logged[k], cls(config, track_width=ex.track_width), plan, homing=homing,
                               camera=camera)
    return out
