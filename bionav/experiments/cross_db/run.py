"""``experiment=cross_db``: snapshots from one database, current views from another (thesis 5.1.4).

Writes ``cross_db.csv`` (for each measure, rows = snapshot database, columns =
current-view database), heatmaps like thesis fig. 5.6, and metrics.json with
AAE*, MAE*, RR* averaged over all off-diagonal database pairs. With
``experiment.block=[i,n]`` a run is task i of n (every n-th snapshot for all database pairs, or, with
more tasks than snapshots, every n-th (snapshot, pair) unit: :func:`task_units`);
:func:`bionav.experiments.cross_db.merge.merge` joins the tasks (``python -m bionav.experiments.merge``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Sequence

import numpy as np
from omegaconf import DictConfig, OmegaConf

from bionav.errors import UserError
from bionav.evaluation.agent import evaluate_agents
from bionav.evaluation.measures import angular_errors, ideal_home_angles, quality_measures
from bionav.evaluation.pairs import home_vector_matrix, prepare_images
from bionav.experiments.common import db_preset, load_configured_database, make_homing, prepared_cache
from bionav.experiments.cross_db.config import CrossDbConfig
from bionav.experiments.cross_db.plots import MEASURES, plot_cross_db
from bionav.experiments.tasks import block_of
from bionav.files import write_csv_atomic

#: settings of cfg.db that apply to every member of the family
SHARED_DB_KEYS = ("image_size", "seed", "noise", "rotate_current", "rotation_seed")


def family_nodes(cfg: DictConfig, family) -> list[dict]:
    """The ``db`` node of every database of ``family``: its preset plus the run's :data:`SHARED_DB_KEYS`."""
    shared = {k: OmegaConf.to_container(cfg.db, resolve=True).get(k) for k in SHARED_DB_KEYS}
    nodes = []
    for name in family:
        node = db_preset(str(name))
        node.update({k: v for k, v in shared.items() if v is not None})
        if isinstance(node.get("path"), str) and "${data_dir}" in node["path"]:
            node["path"] = node["path"].replace("${data_dir}", str(cfg.data_dir))
        nodes.append(node)
    return nodes


def run(exp: CrossDbConfig, ctx) -> dict[str, Any]:
    """Run ``experiment=cross_db`` with the checked ``exp`` (the rest of the config in ``ctx.cfg``)."""
    cfg = ctx.cfg
    nodes = family_nodes(cfg, exp.family)
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

    metrics = write_results(ctx.dir, matrices, names, homing=str(cfg.homing.name),
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


def write_results(run_dir: Path, matrices: dict[str, np.ndarray], names: list[str], *, homing: str,
                   n_snapshots: int, ms: float) -> dict[str, Any]:
    """cross_db.csv, plots/cross_db.png and the metrics of the measure matrices (rows: snapshot database)."""
    n = len(names)
    (run_dir / "plots").mkdir(parents=True, exist_ok=True)
    write_csv_atomic(run_dir / "cross_db.csv", ["measure", "snapshot_db", *names],
                     ([key, names[i], *[f"{v:.6f}" for v in matrices[key][i]]] for key in MEASURES for i in range(n)))
    plot_cross_db(run_dir / "plots" / "cross_db.png", matrices, names, f"cross-database test, homing={homing}")
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
