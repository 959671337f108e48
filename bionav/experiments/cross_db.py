"""``experiment=cross_db``: snapshots from one database, current views from another (thesis 5.1.4).

Writes ``cross_db.csv`` (for each measure, rows = snapshot database, columns =
current-view database), heatmaps like thesis fig. 5.6, and metrics.json with
AAE*, MAE*, RR* averaged over all off-diagonal database pairs. With
``experiment.block=[i,n]`` a run is task i of n (every n-th snapshot for all database pairs, or, with
more tasks than snapshots, every n-th (snapshot, pair) unit: :func:`task_units`);
:func:`merge` joins the tasks (``python -m bionav.experiments.merge``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Sequence

import numpy as np
import yaml
from omegaconf import DictConfig, OmegaConf

from bionav.errors import UserError
from bionav.evaluation.agent import evaluate_agents
from bionav.evaluation.measures import angular_errors, ideal_home_angles, quality_measures
from bionav.evaluation.pairs import home_vector_matrix, prepare_images
from bionav.experiments.common import load_configured_database, make_homing, prepared_cache
from bionav.experiments.configs import experiment_config
from bionav.experiments.runner import LOG_FILE
from bionav.experiments.tasks import block_of, check_blocks, finish_merge, merge_target, read_task
from bionav.files import write_csv_atomic
from bionav.logs.reader import read_attachment, read_messages
from bionav.logs.writer import McapLog
from bionav.report.figures import pyplot, save_figure

#: settings of cfg.db that apply to every member of the family
SHARED_DB_KEYS = ("image_size", "seed", "noise", "rotate_current", "rotation_seed")
MEASURES = ("aae", "mae", "rr")


def db_preset(name: str) -> dict:
    """The ``bionav/conf/db/<name>.yaml`` preset from any config folder."""
    from bionav.config import config_dirs

    for _n, folder in config_dirs():
        path = folder / "db" / f"{name}.yaml"
        if path.is_file():
            return yaml.safe_load(path.read_text()) or {}
    raise UserError(f"the cross_db family names the database {name!r}, which has no preset (bionav/conf/db/{name}.yaml).")


def family_nodes(cfg: DictConfig) -> list[dict]:
    shared = {k: OmegaConf.to_container(cfg.db, resolve=True).get(k) for k in SHARED_DB_KEYS}
    nodes = []
    for name in experiment_config(cfg, "cross_db").family:
        node = db_preset(str(name))
        node.update({k: v for k, v in shared.items() if v is not None})
        if isinstance(node.get("path"), str) and "${data_dir}" in node["path"]:
            node["path"] = node["path"].replace("${data_dir}", str(cfg.data_dir))
        nodes.append(node)
    return nodes


def _plot(path, matrices: dict[str, np.ndarray], names: list[str], title: str) -> None:
    plt = pyplot()

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.8))
    labels = {"aae": "AAE* (rad)", "mae": "MAE* (rad)", "rr": "RR*"}
    for ax, key in zip(axes, MEASURES):
        m = matrices[key]
        # light = good, as thesis fig. 5.6
        cmap = "gray" if key == "rr" else "gray_r"
        im = ax.imshow(m, cmap=cmap, vmin=0, vmax=1 if key == "rr" else max(np.nanmax(m), 1e-9))
        ax.set_xticks(range(len(names)), names, rotation=60, ha="right", fontsize=7)
        ax.set_yticks(range(len(names)), names, fontsize=7)
        ax.set_xlabel("current-view database")
        ax.set_ylabel("snapshot database")
        ax.set_title(labels[key])
        for i in range(len(names)):
            for j in range(len(names)):
                ax.text(j, i, f"{m[i, j]:.2f}", ha="center", va="center", fontsize=6, color="tab:red")
        fig.colorbar(im, ax=ax, shrink=0.8)
    fig.suptitle(title)
    save_figure(fig, path, dpi=110)


def run(cfg: DictConfig, ctx) -> dict[str, Any]:
    exp = experiment_config(cfg, "cross_db")
    nodes = family_nodes(cfg)
    names = [str(n) for n in exp.family]
    dbs = [load_configured_database(cfg, node) for node in ctx.progress(nodes, desc="databases")]
    first = dbs[0]
    for name, db in zip(names, dbs):
        if tuple(db.grid_shape) != tuple(first.grid_shape) or db.geometry != first.geometry:
            raise UserError(
                f"cross_db needs one grid and image geometry for the whole family, but {name} differs from "
                f"{names[0]} ({db.grid_shape} vs {first.grid_shape}); choose databases of one family."
            )
    method = make_homing(cfg, ctx, first.geometry, raw_horizon_radius_px=first.meta.get("raw_horizon_radius_px"))
    stride = max(1, exp.snapshot_stride)
    pos = first.positions
    all_snaps = np.flatnonzero((pos[:, 0] % stride == 0) & (pos[:, 1] % stride == 0))
    n = len(dbs)
    snaps_of = task_units(exp.block, all_snaps, n)
    used = {k for pair in snaps_of for k in pair}  # a task of fewer pairs prepares only their databases
    cache = prepared_cache(cfg)
    prepared = [prepare_images(method, list(db.images), workers=int(cfg.workers), cache=cache) if k in used else None
                for k, db in enumerate(dbs)]

    matrices = {k: np.full((n, n), np.nan) for k in MEASURES}
    per_pair_ms = []
    for (i, j), snap_idx in snaps_of.items():
        hv = home_vector_matrix(
            method, dbs[i], dbs[j], snapshot_index=snap_idx, workers=int(cfg.workers),
            prepared=(prepared[i], prepared[j]), device=str(cfg.get("device") or "cpu"),
        )
        ae = angular_errors(hv.angles, ideal_home_angles(dbs[i].positions[snap_idx], dbs[j].positions))
        success, _ = evaluate_agents(
            dbs[j], hv, step_length=exp.step_length, success_radius=exp.success_radius
        )
        q = quality_measures(ae, success)
        matrices["aae"][i, j], matrices["mae"][i, j], matrices["rr"][i, j] = q.aae, q.mae, q.rr
        per_pair_ms.append(hv.ms_per_home_vector)
        ctx.log.write(
            "/cross_db/cell",
            {"snapshot_db": names[i], "current_db": names[j], "aae": q.aae, "mae": q.mae, "rr": q.rr,
             "aae_s": q.aae_s, "mae_s": q.mae_s, "rr_s": q.rr_s, "snapshots": dbs[i].positions[snap_idx],
             "snapshot_index": snap_idx, "ms_per_home_vector": hv.ms_per_home_vector},
            schema_name="bionav.CrossDbCell",
        )

    metrics = _write_results(ctx.dir, matrices, names, homing=str(cfg.homing.name),
                             n_snapshots=max(len(v) for v in snaps_of.values()), ms=float(np.mean(per_pair_ms)))
    if exp.block is not None:
        metrics["block"] = [int(v) for v in exp.block]
        metrics["family"] = names
    return metrics


def task_units(block: Sequence[int] | None, snapshots: Sequence[int], n_databases: int) -> dict[tuple[int, int],
                                                                                                   np.ndarray]:
    """The snapshots of each database pair that task ``block = [i, n]`` holds.

    Up to as many tasks as snapshots (``n <= len(snapshots)``), task ``i`` holds every ``n``-th
    snapshot from the ``i``-th for every database pair. Beyond that the units (snapshot, pair) are
    listed snapshot by snapshot, the pairs (snapshot database, current-view database) row-major
    within each, and task ``i`` takes every ``n``-th unit from the ``i``-th: tasks of fewer pairs,
    so that a family with few snapshots still splits into many tasks of equal size. Both go through
    :func:`bionav.experiments.tasks.block_of`. Without a block: every pair, every snapshot.

    Returns
    -------
    dict
        ``(i, j) -> snapshot indices`` (ascending) for the pairs the task holds, in row-major order.
    """
    pairs = [(i, j) for i in range(n_databases) for j in range(n_databases)]
    snapshots = [int(s) for s in snapshots]
    if block is None or int(block[1]) <= len(snapshots):
        mine = np.asarray(block_of(block, snapshots), dtype=int)
        return {p: mine for p in pairs}
    units = [(s, p) for s in snapshots for p in pairs]
    out: dict[tuple[int, int], list[int]] = {}
    for k in block_of(block, range(len(units)), what="(snapshot, database pair) unit"):
        s, p = units[k]
        out.setdefault(p, []).append(s)
    return {p: np.asarray(sorted(out[p]), dtype=int) for p in pairs if p in out}


def _write_results(run_dir: Path, matrices: dict[str, np.ndarray], names: list[str], *, homing: str,
                   n_snapshots: int, ms: float) -> dict[str, Any]:
    """cross_db.csv, plots/cross_db.png and the metrics of the measure matrices (rows: snapshot database)."""
    n = len(names)
    (run_dir / "plots").mkdir(parents=True, exist_ok=True)
    write_csv_atomic(run_dir / "cross_db.csv", ["measure", "snapshot_db", *names],
                     ([key, names[i], *[f"{v:.6f}" for v in matrices[key][i]]] for key in MEASURES for i in range(n)))
    _plot(run_dir / "plots" / "cross_db.png", matrices, names, f"cross-database test, homing={homing}")
    off = ~np.eye(n, dtype=bool)

    def mean_off(key: str) -> float:  # over the pairs present (a task of fewer pairs leaves the others NaN)
        v = matrices[key][off]
        v = v[np.isfinite(v)]
        return float(np.mean(v)) if v.size else float("nan")

    return {
        "homing": homing,
        "aae": mean_off("aae"),
        "mae": mean_off("mae"),
        "rr": mean_off("rr"),
        "n_databases": n,
        "n_snapshots": int(n_snapshots),
        "ms_per_home_vector": ms,
    }


# --------------------------------------------------------------------------- tasks of a split run
_CELL_TOPIC = "/cross_db/cell"
_TASK_SHARED = ("experiment", "homing", "n_databases")


def merge(task_dirs: Sequence[Path], out: Path) -> dict[str, Any]:
    """Merge the tasks (``experiment.block=[i,n]``) of one split cross-database run into ``out``.

    Each task logged, per database pair, the per-snapshot AAE_s, MAE_s and RR_s of its block of
    snapshots with their database indices; per pair these are put back in snapshot order and
    reduced as :func:`bionav.evaluation.measures.quality_measures` does (mean, median, mean),
    so the matrices and metrics equal the unsplit run's. ``ms_per_home_vector`` is the mean of
    the tasks' per-pair times.

    Raises
    ------
    UserError
        A task missing, not completed, of another run, or a snapshot in two tasks.
    """
    metas: list[dict] = []
    cells: dict[tuple[str, str], dict[int, tuple[float, float, float]]] = {}
    names: list[str] = []
    ms: list[float] = []
    for d in map(Path, task_dirs):
        metas.append(read_task(d, metas, shared=_TASK_SHARED))
        for _topic, _t, msg in read_messages(d / LOG_FILE, topics=[_CELL_TOPIC]):
            key = (str(msg["snapshot_db"]), str(msg["current_db"]))
            for name in key:
                if name not in names:
                    names.append(name)
            rows = cells.setdefault(key, {})
            for idx, a, m, r in zip(msg["snapshot_index"], msg["aae_s"], msg["mae_s"], msg["rr_s"]):
                if int(idx) in rows:
                    raise UserError(f"snapshot {idx} of {key[0]} -> {key[1]} is in two tasks; give each block once.")
                rows[int(idx)] = (float(a), float(m), float(r))
            ms.append(float(msg["ms_per_home_vector"]))
    check_blocks(metas)
    family = metas[0].get("family")
    if family and sorted(family) == sorted(names):
        names = [str(v) for v in family]  # the family's order (tasks of fewer pairs may list them otherwise)
    n = len(names)
    if len(cells) != n * n:
        raise UserError(f"the tasks hold {len(cells)} of the {n * n} database pairs; give the directories of "
                        f"complete cross_db tasks.")
    out = merge_target(out)
    matrices = {k: np.full((n, n), np.nan) for k in MEASURES}
    n_snapshots = 0
    with McapLog(out / LOG_FILE) as log:
        config = read_attachment(Path(task_dirs[0]) / LOG_FILE, "config.yaml")
        if config is not None:
            log.attach("config.yaml", config, media_type="application/yaml")
        log.metadata("merge", {"tasks": ",".join(str(Path(d).resolve()) for d in task_dirs)})
        for (si, sname) in enumerate(names):
            for (cj, cname) in enumerate(names):
                rows = cells[(sname, cname)]
                order = sorted(rows)
                aae_s, mae_s, rr_s = (np.array([rows[k][c] for k in order]) for c in range(3))
                q = (float(np.mean(aae_s)), float(np.median(mae_s)), float(np.mean(rr_s)))
                matrices["aae"][si, cj], matrices["mae"][si, cj], matrices["rr"][si, cj] = q
                n_snapshots = len(order)
                log.write(_CELL_TOPIC, {"snapshot_db": sname, "current_db": cname, "aae": q[0], "mae": q[1],
                                        "rr": q[2], "aae_s": aae_s, "mae_s": mae_s, "rr_s": rr_s,
                                        "snapshot_index": order}, schema_name="bionav.CrossDbCell")
    metrics = {"experiment": "cross_db"}
    metrics.update(_write_results(out, matrices, names, homing=str(metas[0]["homing"]), n_snapshots=n_snapshots,
                                  ms=float(np.mean(ms))))
    metrics.update(status="completed", tasks=len(metas),
                   wall_time_s=round(sum(float(m.get("wall_time_s", 0.0)) for m in metas), 3))
    finish_merge(task_dirs, out, metrics)
    return metrics
