"""The merge of a split ``experiment=cross_db`` run: its tasks (``experiment.block=[i,n]``) joined into one run.

``python -m bionav.experiments.merge OUT TASK_DIR...`` calls :func:`merge` through the experiment's
plugin (:class:`bionav.experiments.cross_db.CrossDb`); the matrices equal the unsplit run's.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Sequence

import numpy as np

from bionav.errors import UserError
from bionav.experiments.cross_db.plots import MEASURES
from bionav.experiments.cross_db.run import write_results
from bionav.experiments.runner import LOG_FILE
from bionav.experiments.tasks import check_blocks, finish_merge, merge_target, read_task
from bionav.logs.reader import read_attachment, read_messages
from bionav.logs.writer import McapLog

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
    metrics.update(write_results(out, matrices, names, homing=str(metas[0]["homing"]), n_snapshots=n_snapshots,
                                  ms=float(np.mean(ms))))
    metrics.update(status="completed", tasks=len(metas),
                   wall_time_s=round(sum(float(m.get("wall_time_s", 0.0)) for m in metas), 3))
    finish_merge(task_dirs, out, metrics)
    return metrics
