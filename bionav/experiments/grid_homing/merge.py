"""The merge of a split ``experiment=grid_homing`` run: its tasks (``experiment.block=[i,n]``) joined into one run.

``python -m bionav.experiments.merge OUT TASK_DIR...`` calls :func:`merge` through the experiment's
plugin (:class:`bionav.experiments.grid_homing.GridHoming`); the measures equal the unsplit run's.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Sequence

import numpy as np

from bionav.errors import UserError
from bionav.evaluation.measures import quality_measures
from bionav.experiments.grid_homing.plots import plot_per_snapshot_maps
from bionav.experiments.grid_homing.resume import nan_floats
from bionav.experiments.grid_homing.run import HOME_VECTOR_SCHEMA, write_per_snapshot_csv
from bionav.experiments.runner import LOG_FILE
from bionav.experiments.tasks import check_blocks, finish_merge, merge_target, read_task
from bionav.logs.reader import read_attachment, read_messages
from bionav.logs.writer import McapLog

_HV_TOPIC = "/grid_homing/home_vectors"
#: metrics every task of one run shares
_TASK_SHARED = ("experiment", "homing", "db", "n_images")


def merge(task_dirs: Sequence[Path], out: Path) -> dict[str, Any]:
    """Merge the task directories of one split grid-homing run into ``out``.

    Parameters
    ----------
    task_dirs : sequence of Path
        Completed run directories of ``experiment=grid_homing experiment.block=[i,n]``, one per
        ``i`` (every block of one ``n``), or any completed runs whose snapshots do not overlap.
    out : Path
        Directory for the merged files (created; must not hold a completed run).

    Returns
    -------
    dict
        The merged metrics (also written to ``out/metrics.json``).

    Raises
    ------
    UserError
        A task missing, not completed, of another run, or two tasks with the same snapshot.
    """
    metas, rows = [], {}
    currents = None
    for d in map(Path, task_dirs):
        metas.append(read_task(d, metas, shared=_TASK_SHARED))
        for _topic, _t, msg in read_messages(d / LOG_FILE, topics=[_HV_TOPIC]):
            cur = np.asarray(msg["currents"], dtype=int)
            if currents is None:
                currents = cur
            elif cur.shape != currents.shape or np.any(cur != currents):
                raise UserError(f"task {d} has other current views than {task_dirs[0]}; merge tasks of one run only.")
            hit = np.flatnonzero(np.all(cur == np.asarray(msg["snapshot"], dtype=int), axis=1))
            if hit.size != 1:
                raise UserError(f"task {d}: snapshot {msg['snapshot']} is not one of the current views.")
            index = int(hit[0])
            if index in rows:
                raise UserError(f"snapshot {msg['snapshot']} is in two tasks ({rows[index][0]} and {d}); "
                                f"give each block once.")
            rows[index] = (d, msg)
    check_blocks(metas)
    order = sorted(rows)
    ae = np.stack([nan_floats(rows[i][1]["ae"]) for i in order])
    success = np.stack([np.asarray(rows[i][1]["success"], dtype=bool) for i in order])
    compass = [rows[i][1].get("compass_error") for i in order]
    q = quality_measures(ae, success)

    out = merge_target(out)
    n_pairs = [int(m["n_pairs"]) for m in metas]
    ms = [float(m["ms_per_home_vector"]) for m in metas]
    metrics: dict[str, Any] = {k: metas[0][k] for k in ("experiment", "homing", "db")}
    metrics.update(aae=q.aae, mae=q.mae, rr=q.rr, n_images=metas[0]["n_images"], n_pairs=int(sum(n_pairs)),
                   ms_per_home_vector=float(np.dot(ms, n_pairs) / max(1, sum(n_pairs))))
    metrics.update({k: v for k, v in metas[0].items() if k.endswith("_per_image")})
    if all(c is not None for c in compass):
        metrics["compass_aae"] = float(np.nanmean(np.abs(np.concatenate([nan_floats(c) for c in compass]))))
    metrics.update(status="completed", tasks=len(metas),
                   wall_time_s=round(sum(float(m.get("wall_time_s", 0.0)) for m in metas), 3))

    s_pos = currents[order]
    write_per_snapshot_csv(out / "per_snapshot.csv", s_pos, q)
    with McapLog(out / LOG_FILE) as log:
        config = read_attachment(Path(task_dirs[0]) / LOG_FILE, "config.yaml")
        if config is not None:
            log.attach("config.yaml", config, media_type="application/yaml")
        log.metadata("merge", {"tasks": ",".join(str(Path(d).resolve()) for d in task_dirs)})
        for i in order:
            log.write(_HV_TOPIC, rows[i][1], schema_name="bionav.HomeVectorField", schema=HOME_VECTOR_SCHEMA)
    grid_shape = tuple(int(v) for v in currents.max(axis=0) + 1)
    plot_per_snapshot_maps(out / "plots" / "per_snapshot.png", positions=s_pos, grid_shape=grid_shape,
                           aae_s=q.aae_s, rr_s=q.rr_s,
                           title=f"{metrics['homing']} on {metrics['db']}: AAE*={q.aae:.3f} rad, "
                                 f"MAE*={q.mae:.3f} rad, RR*={q.rr:.3f} ({len(metas)} tasks)")
    finish_merge(task_dirs, out, metrics)
    return metrics
