"""``experiment.scope=grid`` (``experiment=param_sweep_grid``): every signature x image size x preprocessing
of a sweep grid in one run, on a pool of ``workers`` processes; the same records as the multirun's jobs.
"""

from __future__ import annotations

import dataclasses
import time
from typing import Any

from omegaconf import OmegaConf

from bionav.errors import UserError
from bionav.experiments.param_sweep.levels import evaluate_levels, sweep_levels
from bionav.experiments.param_sweep.run import configuration_rows, pass_through, write_configurations
from bionav.files import user_path



def _grid_values(value: Any, *, what: str) -> list[Any]:
    """The values of one sweep key of a grid: a list, or the sweeper's comma-separated string."""
    import yaml

    if isinstance(value, (list, tuple)) or OmegaConf.is_list(value):
        return list(OmegaConf.to_container(value) if OmegaConf.is_list(value) else value)
    try:
        parsed = yaml.safe_load(f"[{value}]")
    except yaml.YAMLError:
        parsed = None
    if not isinstance(parsed, list) or not parsed:
        raise UserError(f"experiment.grids.<grid>.{what}={value!r} is not a comma-separated list of values; "
                        f"write it as the sweeper does, e.g. {what}: a,b,c.")
    return parsed


def _preprocess_node(name: str) -> dict[str, Any]:
    """The ``preprocess=<name>`` config of bionav's config group, as a plain dict."""
    from importlib import resources

    path = resources.files("bionav.conf") / "preprocess" / f"{name}.yaml"
    if not path.is_file():
        known = sorted(p.name[:-5] for p in (resources.files("bionav.conf") / "preprocess").iterdir()
                       if p.name.endswith(".yaml"))
        raise UserError(f"preprocessing {name!r} of the sweep grid is not one of bionav's: {', '.join(known)}. "
                        f"Fix experiment.grids.<grid>.preprocess.")
    return OmegaConf.to_container(OmegaConf.load(str(path)), resolve=True)


@dataclasses.dataclass(frozen=True)
class _GridTask:
    """One image size x preprocessing of a grid run: every signature of the grid (runs in a worker)."""

    db_node: dict
    data_dir: str
    cache_dir: str
    size: tuple
    preprocess: Any
    signatures: tuple = ()
    homing_cfg: Any = None
    rings: tuple = ()
    n_coeffs: tuple = ()
    step_length: float = 0.5
    success_radius: float = 1.0


def _grid_database(task: _GridTask):
    """The database of one grid unit, exactly as a job of the multirun loads it."""
    from pathlib import Path

    from bionav.db.loading import load_database

    return load_database(dict(task.db_node, image_size=list(task.size)), data_dir=Path(task.data_dir),
                         cache_dir=Path(task.cache_dir), preprocess=task.preprocess)


def _grid_render(task: _GridTask) -> float:
    """Render (or read from the cache) the database at one size; returns the wall time in s."""
    t0 = time.perf_counter()
    _grid_database(dataclasses.replace(task, preprocess=None))
    return time.perf_counter() - t0


def _grid_task(task: _GridTask) -> list[dict[str, Any]]:
    """Rows of every signature of one image size x preprocessing (see :func:`_run_grid`)."""
    from bionav.plugins.homing.parameter import ParameterHoming
    from bionav.plugins.signatures import signature_class

    db = _grid_database(task)
    preprocess = "none" if not task.preprocess else str(task.preprocess.get("name", "custom"))
    rows: list[dict[str, Any]] = []
    for sig_name in task.signatures:
        sig_cls = signature_class(sig_name)
        homing_cfg, sig_cfg = pass_through(task.homing_cfg, sig_name, sig_cls.Config())
        levels = sweep_levels(sig_cls, rings=task.rings, n_coeffs=task.n_coeffs)
        homings, measures, ms = evaluate_levels(ParameterHoming, homing_cfg, sig_cls, sig_cfg, levels, db,
                                                step_length=task.step_length, success_radius=task.success_radius)
        rows += configuration_rows(db, sig_name, preprocess, homings, measures, ms)
    return rows


def run_grid(exp, ctx) -> dict[str, Any]:
    """``experiment.scope=grid``: every signature x image size x preprocessing of the grid in this run.

    Each image size x preprocessing is one task for a pool of ``workers``
    processes (largest images first); a task loads the database exactly as
    the multirun's job would (rendered at that size, then preprocessed) and
    evaluates every signature of the grid on it (:func:`evaluate_levels`).
    Stand-ins not yet in the cache are rendered first, one size per task.
    """
    from bionav.config import plugin_config
    from bionav.experiments.common import worker_pool
    from bionav.machine import usable_cpus
    from bionav.plugins.signatures import signature_class
    from bionav.report.ranking import write_parameter_report

    cfg = ctx.cfg

    if str(cfg.homing.name) != "parameter":
        raise UserError(
            f"experiment=param_sweep sweeps parameter homing, but homing={cfg.homing.name} is selected. "
            f"Drop the homing= override (the experiment selects homing=parameter)."
        )
    _, homing_cfg = plugin_config("homing", cfg.homing)
    grid_name = exp.grid
    grid = exp.grids.get(grid_name) if exp.grids else None
    if grid is None:
        raise UserError(f"experiment.grid={grid_name!r} is not one of the sweep grids "
                        f"({', '.join(exp.grids or [])}); choose one of them.")
    signatures = tuple(str(v) for v in _grid_values(grid.get("signature"), what="signature"))
    for name in signatures:
        signature_class(name)  # a clear error for an unknown name before any work
    sizes = [tuple(int(v) for v in size) for size in _grid_values(grid.get("image_size"), what="image_size")]
    sizes.sort(key=lambda wh: -wh[0] * wh[1])  # largest first: the pool ends with short tasks
    preprocessings = [_preprocess_node(str(v)) for v in _grid_values(grid.get("preprocess"), what="preprocess")]
    base = _GridTask(db_node=OmegaConf.to_container(cfg.db, resolve=True), data_dir=str(cfg.data_dir),
                     cache_dir=str(user_path(str(cfg.cache_dir))), size=sizes[0], preprocess=None, signatures=signatures,
                     homing_cfg=homing_cfg, rings=tuple(int(r) for r in exp.rings),
                     n_coeffs=tuple(int(k) for k in exp.n_coeffs), step_length=exp.step_length,
                     success_radius=exp.success_radius)
    renders = [dataclasses.replace(base, size=size) for size in sizes]
    tasks = [dataclasses.replace(base, size=size, preprocess=pre) for size in sizes for pre in preprocessings]
    # never more processes than tasks or CPUs (worker_pool caps at the CPUs as well; recorded as used)
    workers = max(1, min(int(cfg.get("workers") or 1), len(tasks), usable_cpus()))
    name = str(base.db_node.get("name", "db"))
    rows: list[dict[str, Any]] = []
    t0 = time.perf_counter()
    if workers == 1:
        render_s = sum(_grid_render(t) for t in renders)
        t1 = time.perf_counter()
        for task in ctx.progress(tasks, desc=f"param_sweep grid on {name}", total=len(tasks)):
            rows += _grid_task(task)
    else:
        with worker_pool(workers) as pool:
            render_s = sum(pool.map(_grid_render, renders, chunksize=1))
            t1 = time.perf_counter()
            for part in ctx.progress(pool.imap(_grid_task, tasks), desc=f"param_sweep grid on {name}",
                                     total=len(tasks)):
                rows += part
    sweep_s = time.perf_counter() - t1
    write_configurations(ctx, rows)
    write_parameter_report(ctx.dir)
    best = max(rows, key=lambda r: (r["rr"], -r["aae"]))
    return {
        "db": rows[0]["db"],
        "signature": best["signature"],
        "image_size": best["image_size"],
        "preprocess": best["preprocess"],
        "aae": best["aae"],
        "mae": best["mae"],
        "rr": best["rr"],
        "n_configs": len(rows),
        "render_wall_s": t1 - t0,
        "render_task_s": render_s,
        "sweep_wall_s": sweep_s,
        "workers": workers,
    }
