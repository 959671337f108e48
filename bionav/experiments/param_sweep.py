"""``experiment=param_sweep``: the parameter-homing sweep of thesis 5.2.1 (tables 5.5-5.7).

One job evaluates one signature on one database at one image size and
preprocessing, for every ring count ``R`` (ring-based signatures) or every
number of Fourier coefficients ``K`` (DFT-based signatures) of the sweep;
[image] has a single configuration. The Hydra multirun over signature x image
size x preprocessing (x database) is declared in ``bionav/conf/experiment/param_sweep.yaml``
(``experiment.grid=full`` is the thesis grid, ``experiment.grid=ci`` a reduced one).

For every configuration the signatures are computed once per image
(:meth:`ParameterHoming.prepare`), the home vectors of all pairs come from
matrix operations on them (:meth:`ParameterHoming.all_pairs_angles`, the
batch path of the all-pairs runner, identical to the per-pair
:meth:`ParameterHoming.home_vector`), and AAE*, MAE*, RR* follow
thesis 3.2 (:mod:`bionav.evaluation`).

Files in the run directory
--------------------------
``param_sweep.jsonl``
    One JSON object per configuration: database, signature, rings, n_coeffs,
    bins, image size, preprocessing, gradient, rotation invariance, ``rr``,
    ``aae``, ``mae``, and the per-snapshot ``positions``, ``aae_s``, ``rr_s``.
    :mod:`bionav.report.ranking` builds the ranking tables from these files.
``plots/levels.png``
    RR* and AAE* against R or K.
``metrics.json``
    The best configuration of the job (by RR*, ties by AAE*): ``rr``, ``aae``,
    ``mae``, ``best_rings`` / ``best_n_coeffs``, ``n_configs``.
"""

from __future__ import annotations

import dataclasses
import json
import math
import time
from typing import Any, Sequence

import numpy as np
from omegaconf import DictConfig, OmegaConf

from bionav.db.database import ImageDatabase
from bionav.errors import UserError
from bionav.evaluation.pairs import home_vector_matrix
from bionav.experiments.configs import experiment_config
from bionav.files import user_path
from bionav.report.figures import pyplot, save_figure

ROWS_FILE = "param_sweep.jsonl"

CONFIGURATION_SCHEMA = {
    "type": "object",
    "properties": {
        "signature": {"type": "string"},
        "rings": {"type": ["integer", "null"]},
        "n_coeffs": {"type": ["integer", "null"]},
        "rr": {"type": "number", "description": "RR* (0..1)"},
        "aae": {"type": "number", "description": "AAE*, radians"},
        "mae": {"type": "number", "description": "MAE*, radians"},
        "aae_s": {"type": "array", "description": "AAE_s per snapshot, radians"},
        "rr_s": {"type": "array", "description": "RR_s per snapshot"},
    },
}


def sweep_levels(signature_cls: type, *, rings: Sequence[int], n_coeffs: Sequence[int]) -> list[dict[str, int]]:
    """The configurations one job evaluates: one dict of signature parameters each.

    DFT signatures (a ``n_coeffs`` parameter) vary ``K`` over ``n_coeffs``;
    ring signatures (a ``rings`` parameter) vary ``R`` over ``rings``; a
    signature with neither ([image]) has one configuration ``{}``.
    """
    names = {f.name for f in dataclasses.fields(signature_cls.Config)}
    if "n_coeffs" in names:
        return [{"n_coeffs": int(k)} for k in n_coeffs]
    if "rings" in names:
        return [{"rings": int(r)} for r in rings]
    return [{}]


def evaluate_configuration(homing, db: ImageDatabase, *, step_length: float = 0.5, success_radius: float = 1.0):
    """AAE*/MAE*/RR* of one parameter-homing configuration on one database.

    The plain per-configuration path (the reference of :func:`evaluate_levels`,
    which the experiment runs): signatures are computed once per image; home
    vectors of all pairs by the all-pairs runner through the method's batch
    path (:meth:`ParameterHoming.all_pairs_angles`); agents row by row
    (:func:`bionav.evaluation.agent.run_agents`) and measures as thesis 3.2.

    Returns
    -------
    measures : bionav.evaluation.measures.QualityMeasures
    hv : HomeVectorMatrix
        With ``prepare_s`` set to the per-image time.
    """
    from bionav.evaluation.agent import evaluate_agents
    from bionav.evaluation.measures import angular_errors, ideal_home_angles, quality_measures

    t0 = time.perf_counter()
    use_raw = db.raw is not None and getattr(homing.signature, "uses_raw", False)
    prepared = [homing.prepare(img, raw=db.raw(i) if use_raw else None) for i, img in enumerate(db.images)]
    prepare_s = time.perf_counter() - t0
    hv = home_vector_matrix(homing, db, prepared=(prepared, prepared))
    hv = dataclasses.replace(hv, prepare_s=prepare_s)
    ae = angular_errors(hv.angles, ideal_home_angles(db.positions, db.positions))
    success, _ = evaluate_agents(db, hv, step_length=step_length, success_radius=success_radius, batch=False)
    return quality_measures(ae, success), hv


def evaluate_levels(
    homing_cls: type,
    homing_cfg: Any,
    signature_cls: type,
    signature_cfg: Any,
    levels: Sequence[dict[str, int]],
    db: ImageDatabase,
    *,
    step_length: float = 0.5,
    success_radius: float = 1.0,
):
    """AAE*/MAE*/RR* of every configuration of one job, sharing the work between them.

    The same measures as :func:`evaluate_configuration` per level, computed
    together: DFT signatures (``coefficient_index``) are computed once per
    image with the largest ``K`` and the potentials (or matched-filter
    gradients) of every ``K`` are partial sums over the coefficients; other
    signatures are computed per level. The agent trials of all levels run in
    one compiled batch (:func:`bionav.evaluation.agent.agent_success`).

    Returns
    -------
    homings : list of ParameterHoming
        One per level.
    measures : list of QualityMeasures
        One per level.
    ms_per_home_vector : float
        Wall time of the whole job per configuration and home vector, ms.
    """
    from bionav.evaluation.agent import agent_success
    from bionav.evaluation.measures import angular_errors, ideal_home_angles, quality_measures
    from bionav.evaluation.pairs import neighbour_table

    t0 = time.perf_counter()
    homings = [
        homing_cls(homing_cfg, geometry=db.geometry, signature=signature_cls(dataclasses.replace(signature_cfg, **lv)))
        for lv in levels
    ]
    use_raw = db.raw is not None and getattr(homings[0].signature, "uses_raw", False)
    headings, neighbours = db.headings, neighbour_table(db)
    ks = [lv.get("n_coeffs") for lv in levels]
    nested = len(levels) > 1 and None not in ks and all(hasattr(h.signature, "coefficient_index") for h in homings)
    if nested:
        top = homings[int(np.argmax(ks))]
        prepared = [top.prepare(img, raw=db.raw(i) if use_raw else None) for i, img in enumerate(db.images)]
        shape = np.asarray(db.images[0]).shape[:2]
        angles = top.all_pairs_angles_by_coefficients(prepared, n_coeffs=ks, image_shape=shape, headings=headings,
                                                      neighbours=neighbours)
    else:
        stack = []
        for homing in homings:
            prepared = [homing.prepare(img, raw=db.raw(i) if use_raw else None) for i, img in enumerate(db.images)]
            stack.append(homing.all_pairs_angles(prepared, headings=headings, neighbours=neighbours))
        angles = np.stack(stack)
    ideal = ideal_home_angles(db.positions, db.positions)
    angles[:, np.isnan(ideal)] = np.nan  # a snapshot's own cell (as the all-pairs runner)
    success = agent_success(angles, db.positions, db.positions, grid_shape=db.grid_shape, step_length=step_length,
                            success_radius=success_radius)
    measures = [quality_measures(angular_errors(a, ideal), ok) for a, ok in zip(angles, success)]
    n_pairs = int(np.sum(~np.isnan(ideal)))
    ms = 1e3 * (time.perf_counter() - t0) / max(n_pairs * len(levels), 1)
    return homings, measures, ms


def _signature_setup(cfg: DictConfig, ctx):
    from bionav.config import plugin_config
    from bionav.plugins.homing.parameter import ParameterHoming
    from bionav.plugins.signatures import signature_class

    if str(cfg.homing.name) != "parameter":
        raise UserError(
            f"experiment=param_sweep sweeps parameter homing, but homing={cfg.homing.name} is selected. "
            f"Drop the homing= override (the experiment selects homing=parameter)."
        )
    _, homing_cfg = plugin_config("homing", cfg.homing)
    if cfg.get("signature"):
        sig_cls, sig_cfg = plugin_config("signature", cfg.signature)
        sig_name = str(cfg.signature.name)
    else:
        sig_cls = signature_class(homing_cfg.signature)
        sig_cfg = sig_cls.Config()
        sig_name = str(homing_cfg.signature)
    homing_cfg, sig_cfg = _pass_through(homing_cfg, sig_name, sig_cfg)
    return ParameterHoming, homing_cfg, sig_name, sig_cls, sig_cfg


def _pass_through(homing_cfg, sig_name: str, sig_cfg):
    """homing.rings/n_coeffs/bins pass through to the signature's base config; the sweep varies R or K on top."""
    names = {f.name for f in dataclasses.fields(sig_cfg)}
    passed = {k: getattr(homing_cfg, k) for k in ("rings", "n_coeffs", "bins") if getattr(homing_cfg, k) is not None}
    sig_cfg = dataclasses.replace(sig_cfg, **{k: v for k, v in passed.items() if k in names})
    homing_cfg = dataclasses.replace(homing_cfg, signature=sig_name, rings=None, n_coeffs=None, bins=None)
    return homing_cfg, sig_cfg


def _finite(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def _rows(db: ImageDatabase, sig_name: str, preprocess: str, homings, measures, ms: float) -> list[dict[str, Any]]:
    """One configuration record per level (see the module docstring)."""
    size = f"{db.geometry.width}x{db.geometry.height}"
    rows = []
    for homing, q in zip(homings, measures):
        sig = homing.signature
        rows.append({
            "db": db.name,
            "signature": sig_name,
            "rings": getattr(sig.config, "rings", None),
            "n_coeffs": getattr(sig.config, "n_coeffs", None),
            "bins": getattr(sig.config, "bins", None),
            "image_size": size,
            "preprocess": preprocess,
            "gradient": homing.gradient,
            "rotation_invariant": bool(getattr(sig, "rotation_invariant", False)),
            "rr": float(q.rr),
            "aae": float(q.aae),
            "mae": float(q.mae),
            "ms_per_home_vector": ms,
            "grid_shape": [int(v) for v in db.grid_shape],
            "positions": db.positions.tolist(),
            "aae_s": [_finite(v) for v in q.aae_s],
            "rr_s": [_finite(v) for v in q.rr_s],
        })
    return rows


def _write_rows(ctx, rows: list[dict[str, Any]]) -> None:
    for row in rows:
        ctx.log.write(
            "/param_sweep/configuration", row, schema_name="bionav.ParameterConfiguration", schema=CONFIGURATION_SCHEMA
        )
    with open(ctx.dir / ROWS_FILE, "w") as f:
        for row in rows:
            f.write(json.dumps(row) + "\n")


def run(cfg: DictConfig, ctx) -> dict[str, Any]:
    from bionav.experiments.common import load_configured_database

    exp = experiment_config(cfg, "param_sweep")
    if exp.scope == "grid":
        return _run_grid(cfg, ctx, exp)
    homing_cls, homing_cfg, sig_name, sig_cls, sig_cfg = _signature_setup(cfg, ctx)
    db = load_configured_database(cfg)
    levels = sweep_levels(sig_cls, rings=list(exp.rings), n_coeffs=list(exp.n_coeffs))
    preprocess = str(OmegaConf.select(cfg, "preprocess.name", default="none"))
    size = f"{db.geometry.width}x{db.geometry.height}"
    homings, measures, ms = evaluate_levels(
        homing_cls, homing_cfg, sig_cls, sig_cfg, levels, db,
        step_length=exp.step_length, success_radius=exp.success_radius,
    )
    rows = _rows(db, sig_name, preprocess, homings, measures, ms)
    _write_rows(ctx, rows)
    _plot_levels(ctx.plots / "levels.png", rows, title=f"[{sig_name}] on {db.name}, {size}, {preprocess}")

    best = max(rows, key=lambda r: (r["rr"], -r["aae"]))
    metrics: dict[str, Any] = {
        "db": db.name,
        "signature": sig_name,
        "gradient": best["gradient"],
        "rotation_invariant": best["rotation_invariant"],
        "image_size": size,
        "preprocess": preprocess,
        "aae": best["aae"],
        "mae": best["mae"],
        "rr": best["rr"],
        "n_configs": len(rows),
        "n_images": len(db),
        "ms_per_home_vector": float(np.mean([r["ms_per_home_vector"] for r in rows])),
    }
    for key in ("rings", "n_coeffs"):
        if best[key] is not None and key in levels[0]:
            metrics[f"best_{key}"] = best[key]
    return metrics


# --- experiment.scope=grid: the whole grid in one run ------------------------------------------


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
        homing_cfg, sig_cfg = _pass_through(task.homing_cfg, sig_name, sig_cls.Config())
        levels = sweep_levels(sig_cls, rings=task.rings, n_coeffs=task.n_coeffs)
        homings, measures, ms = evaluate_levels(ParameterHoming, homing_cfg, sig_cls, sig_cfg, levels, db,
                                                step_length=task.step_length, success_radius=task.success_radius)
        rows += _rows(db, sig_name, preprocess, homings, measures, ms)
    return rows


def _run_grid(cfg: DictConfig, ctx, exp) -> dict[str, Any]:
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
    _write_rows(ctx, rows)
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


def _plot_levels(path, rows: list[dict[str, Any]], *, title: str) -> None:
    plt = pyplot()

    key = "n_coeffs" if rows[0]["n_coeffs"] is not None and len(rows) > 1 else "rings"
    x = [r[key] if r[key] is not None else 0 for r in rows]
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.plot(x, [r["rr"] for r in rows], "o-", label="RR*")
    ax.plot(x, [r["aae"] for r in rows], "s--", label="AAE* (rad)")
    ax.set_xlabel("number of Fourier coefficients K" if key == "n_coeffs" else "number of rings R")
    ax.set_ylabel("RR* (fraction) | AAE* (rad)")
    ax.set_ylim(0, max(1.0, max(r["aae"] for r in rows) * 1.05))
    ax.legend()
    ax.grid(alpha=0.3)
    ax.set_title(title, fontsize=9)
    save_figure(fig, path, dpi=110)
