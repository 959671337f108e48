"""Running one experiment: the files every run writes, whatever happens."""

from __future__ import annotations

import errno
import json
import logging
import os
import time
import traceback
from pathlib import Path
from typing import Any

import numpy as np
from omegaconf import DictConfig, OmegaConf

from bionav import __version__
from bionav.errors import UserError
from bionav.experiments.context import RunContext
from bionav.experiments.warmup import start_warmup, stop_warmup
from bionav.files import write_json_atomic
from bionav.logs.writer import McapLog
from bionav.runlock import RunLock

log = logging.getLogger(__name__)

METRICS_FILE = "metrics.json"
LOG_FILE = "run.mcap"


def read_metrics(run_dir: Path) -> dict | None:
    """The metrics.json of a run directory, or ``None`` if absent, not a regular file, unreadable or not an object."""
    from bionav.files import not_a_regular_file

    path = Path(run_dir) / METRICS_FILE
    if not_a_regular_file(path) is not None:  # a FIFO must not block
        return None
    try:
        metrics = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    return metrics if isinstance(metrics, dict) else None


def is_completed(run_dir: Path) -> bool:
    """True when the run directory holds a metrics.json with ``"status": "completed"``."""
    metrics = read_metrics(run_dir)
    return bool(metrics) and metrics.get("status") == "completed"


def used_plugin_groups(cfg: DictConfig) -> tuple[str, ...]:
    """The config groups whose plugins ``cfg.experiment`` uses (every group for an unknown or broken experiment).

    The defaults select ``homing=sift`` for every run; an experiment that
    homes on nothing (the compass, the spectral contrasts) does not use it,
    so its run.mcap must not name it. Each experiment plugin says which it reads
    (:meth:`Experiment.used_plugin_groups <bionav.experiments.base.Experiment.used_plugin_groups>`).
    """
    from bionav.errors import PluginError
    from bionav.experiments.base import DEFAULT_PLUGIN_GROUPS
    from bionav.experiments.settings import experiment_class

    node = cfg.get("experiment")
    try:
        cls = experiment_class(str(OmegaConf.select(cfg, "experiment.name", default="") or ""))
    except PluginError:
        return DEFAULT_PLUGIN_GROUPS
    return tuple(cls.used_plugin_groups(node))


def plugin_versions(cfg: DictConfig) -> dict[str, str]:
    """The plugins the run's experiment uses: name, distribution and version per config group.

    Only the groups of :func:`used_plugin_groups` are recorded (a compass run
    names its sensor and decoder, not the default ``homing=sift``).
    """
    from bionav import registry

    out = {"bionav": __version__}
    kinds = {"homing": "homing", "signature": "signature", "sensor": "sensor", "pantilt": "sensor", "controller": "controller"}
    kinds["decoder"] = "decoder"
    used = used_plugin_groups(cfg)
    for group, kind in kinds.items():
        if group not in used:
            continue
        node = cfg.get(group)
        if not node or not node.get("name"):
            continue
        entry = registry.entry_points_of(kind).get(str(node.name))
        if entry is not None:
            out[f"{group}"] = f"{entry.name} ({entry.distribution} {entry.version})"
    return out


def json_safe(value: Any) -> Any:
    """``value`` with every non-finite float (NaN, inf) replaced by ``None`` (JSON ``null``).

    metrics.json must be strict JSON; a measure that is undefined (e.g. a
    compass error when no pair had one) is written as ``null``.
    """
    if isinstance(value, dict):
        return {k: json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_safe(v) for v in value]
    if isinstance(value, np.ndarray):
        return json_safe(value.tolist())
    if isinstance(value, (float, np.floating)):
        return float(value) if np.isfinite(value) else None
    return value


#: config groups that select plugins, and the plugin kind each selects
PLUGIN_NODES = {"homing": "homing", "signature": "signature", "sensor": "sensor", "pantilt": "sensor",
                "controller": "controller"}


def validate_run_config(cfg: DictConfig) -> Any:
    """Check every value of a run's config against its declared type and range; the typed experiment node.

    The selected plugins' nodes (``homing``, ``signature``, ``sensor``,
    ``pantilt``, ``controller``), the ``db`` node, the experiment node and the
    other nodes the experiment reads (``layout``, ``data``, ``recordings``) are
    each checked against their dataclass (:func:`bionav.validation.typed_config`).

    Returns
    -------
    The experiment's checked ``Config`` instance (None without an ``experiment`` node).

    Raises
    ------
    UserError
        Naming the first bad key, its value and the allowed range.
    """
    from bionav.config import plugin_config
    from bionav.db.loading import as_database_config
    from bionav.experiments.settings import check_group_nodes, check_run_settings, experiment_class, experiment_config

    check_run_settings(cfg)
    name = OmegaConf.select(cfg, "experiment.name", default=None) if cfg.get("experiment") is not None else None
    if name is not None:
        check_group_nodes(cfg, experiment_class(str(name)))  # a PluginError names the installed experiments
    if cfg.get("cache_dir") is not None:  # before any rendering: a cache that cannot be written wastes it all
        from bionav.files import check_cache_dir

        check_cache_dir(str(cfg.cache_dir))
    for group, kind in PLUGIN_NODES.items():
        node = cfg.get(group)
        if node and node.get("name"):
            plugin_config(kind, node, key=group)  # a broken or conflicting plugin raises its message
    if cfg.get("db") is not None:
        as_database_config(cfg.db)
    return experiment_config(cfg)


def run_experiment(cfg: DictConfig, run_dir: Path, *, show_progress: bool = True) -> dict[str, Any]:
    """Run ``cfg.experiment.name`` in ``run_dir`` and write metrics.json and run.mcap.

    The directory is locked for the run (a second run into it is refused;
    see :mod:`bionav.runlock`). metrics.json first says
    ``"status": "running"``, then, written atomically, ``"completed"`` on
    success, or ``"status": "failed"`` and ``"error"`` on any failure (the
    exception is re-raised); run.mcap is closed properly either way. With
    ``cfg.bionav.resume`` a run directory whose metrics say completed is
    left untouched and its metrics returned.
    """
    run_dir = Path(run_dir)
    run_dir.mkdir(parents=True, exist_ok=True)
    with RunLock(run_dir):
        resume = bool(OmegaConf.select(cfg, "bionav.resume", default=False))
        if resume and is_completed(run_dir):
            log.info("resume: %s already completed, skipped", run_dir)
            metrics = read_metrics(run_dir) or {}
            metrics["resumed"] = True
            return metrics
        if resume:
            _keep_attempt(run_dir)
        return _run_locked(cfg, run_dir, show_progress=show_progress)


def _keep_attempt(run_dir: Path) -> None:
    """A resumed run that did not finish: its earlier attempt's metrics.json and run.mcap are kept, renamed
    ``metrics.attempt-<n>.json`` and ``run.attempt-<n>.mcap``, before the run starts again (nothing recorded
    is lost)."""
    if not (run_dir / METRICS_FILE).exists() and not (run_dir / LOG_FILE).exists():
        return
    n = 1
    while (run_dir / f"metrics.attempt-{n}.json").exists() or (run_dir / f"run.attempt-{n}.mcap").exists():
        n += 1
    for name, kept in ((METRICS_FILE, f"metrics.attempt-{n}.json"), (LOG_FILE, f"run.attempt-{n}.mcap")):
        if (run_dir / name).exists():
            os.replace(run_dir / name, run_dir / kept)
    log.info("resume: the earlier attempt in %s is kept as metrics.attempt-%d.json and run.attempt-%d.mcap",
             run_dir, n, n)


def _run_locked(cfg: DictConfig, run_dir: Path, *, show_progress: bool) -> dict[str, Any]:
    name = str(cfg.experiment.name)
    started = time.time()
    metrics: dict[str, Any] = {"experiment": name}
    # a SIGKILL from here on leaves metrics.json saying "running" (and since when) next to a readable run.mcap
    write_json_atomic(run_dir / METRICS_FILE, {
        **metrics, "status": "running", "started": time.strftime("%Y-%m-%dT%H:%M:%S%z", time.localtime(started)),
        "pid": os.getpid(),
    })
    log.info("%s started in %s (pid %d); results: %s, %s", name, run_dir, os.getpid(), METRICS_FILE, LOG_FILE)
    mcap = None
    try:
        mcap = McapLog(run_dir / LOG_FILE)
        mcap.attach("config.yaml", OmegaConf.to_yaml(cfg, resolve=True).encode(), media_type="application/yaml")
        mcap.metadata("plugins", plugin_versions(cfg))
        config = validate_run_config(cfg)
        from bionav.experiments.settings import check_group_nodes, experiment_class

        cls = experiment_class(name)  # from the registry (bionav.experiments)
        ctx = RunContext(
            dir=run_dir,
            log=mcap,
            rng=np.random.default_rng(int(cfg.get("seed", 0))),
            cfg=cfg,
            show_progress=show_progress,
            nodes=check_group_nodes(cfg, cls),
        )
        experiment = cls(config)
        # compiles the homing kernels the run needs later in a second process, beside the run
        warmup = start_warmup(cfg, used_groups=tuple(cls.used_plugin_groups(cfg.get("experiment"))))
        try:
            result = experiment.run(ctx)
        finally:
            stop_warmup(warmup)
        metrics.update(result or {})
        metrics["status"] = "completed"
    except BaseException as exc:
        if not isinstance(exc, KeyboardInterrupt) and _caused_by_interrupt(exc):
            # Ctrl-C inside compiled code (numba) surfaces as SystemError caused by KeyboardInterrupt
            metrics.update(status="failed", error=f"KeyboardInterrupt: (inside {type(exc).__name__}: {exc})")
            _finish(run_dir, mcap, metrics, started, failing=True)
            log.error("%s interrupted after %.1f s", name, metrics["wall_time_s"])
            raise KeyboardInterrupt from None
        full = disk_full_error(exc, run_dir)
        if isinstance(exc, UserError):  # nothing logged yet: a refusal at start (the command line removes the run)
            exc.refused_at_start = mcap is None or mcap.n_messages == 0
        metrics["status"] = "failed"
        metrics["error"] = str(full or exc) if isinstance(full or exc, UserError) else f"{type(exc).__name__}: {exc}"
        if full is None and not isinstance(exc, (UserError, KeyboardInterrupt)):
            try:
                (run_dir / "error.log").write_text(traceback.format_exc())
            except OSError:
                pass
        _finish(run_dir, mcap, metrics, started, failing=True)
        log.error("%s %s after %.1f s: %s", name, "interrupted" if isinstance(exc, KeyboardInterrupt) else "failed",
                  metrics["wall_time_s"], metrics["error"])
        if full is not None:
            raise full from None
        raise
    _finish(run_dir, mcap, metrics, started, failing=False)
    log.info("%s completed in %.1f s: %s", name, metrics["wall_time_s"], ", ".join(
        f"{k}={v:.4g}" for k, v in metrics.items() if isinstance(v, float) and k != "wall_time_s") or "no scalar metrics")
    return metrics


def _finish(run_dir: Path, mcap: McapLog | None, metrics: dict[str, Any], started: float, *, failing: bool) -> None:
    """Close run.mcap and write the final metrics.json; on a failing run, errors here do not hide the first."""
    metrics["wall_time_s"] = round(time.time() - started, 3)
    try:
        try:
            if mcap is not None:
                mcap.close()
        finally:
            write_json_atomic(run_dir / METRICS_FILE, json_safe(metrics))
    except OSError as exc:
        if failing:
            return
        full = disk_full_error(exc, run_dir)
        if full is not None:
            raise full from None
        raise


def _caused_by_interrupt(exc: BaseException) -> bool:
    """True if a KeyboardInterrupt is among the causes/contexts of ``exc``."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return True
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return False


def mount_point(path: Path) -> Path:
    """The mount point of the file system holding ``path`` (what `df` calls the device's mount)."""
    path = path.resolve()
    try:
        dev = path.stat().st_dev
        while path != path.parent and path.parent.stat().st_dev == dev:
            path = path.parent
    except OSError:
        pass
    return path


def disk_full_error(exc: BaseException, run_dir: Path) -> UserError | None:
    """A :class:`UserError` naming the device if ``exc`` means the disk (or quota) is full, else ``None``."""
    if not (isinstance(exc, OSError) and exc.errno in (errno.ENOSPC, errno.EDQUOT)):
        return None
    what = "no space left" if exc.errno == errno.ENOSPC else "disk quota exceeded"
    return UserError(
        f"{what} on {mount_point(run_dir)} (writing {exc.filename or 'the run directory'}); free space or choose "
        f"hydra.run.dir=... on another disk. What was written before is kept in {run_dir} (metrics.json says failed, "
        f"or still running if there was no room to update it; a run.mcap cut short is repaired with "
        f"`python -m bionav.logs recover {run_dir / LOG_FILE} fixed.mcap` once there is space)."
    )
