"""Join the tasks of a split grid-homing run: ``python -m bionav.experiments.grid_homing_merge OUT TASK_DIR...``.

A grid-homing run splits into independent tasks by snapshots (``experiment.block=[i,n]``,
:mod:`bionav.experiments.grid_homing`): each task computes every current view's home vector
to its snapshots and their return agents, and logs one ``/grid_homing/home_vectors`` message
per snapshot (angles, angular errors, agent successes, compass errors) at full precision.
This reduce step reads those messages back from every task's ``run.mcap``, orders the
snapshots as the database does, and writes the unsplit run's files into ``OUT``:
``metrics.json`` (AAE*, MAE*, RR*, compass AAE: computed from the same numbers in the same
order, so identical to the unsplit run; ``ms_per_home_vector`` is the pair-weighted mean of
the tasks'), ``per_snapshot.csv``, ``run.mcap`` (every snapshot's home vectors, the tasks'
config attached) and ``plots/per_snapshot.png``. The quiver plots of single snapshots stay in
the task directories. ``.hydra/`` is copied from the first task, less its ``experiment.block``
override, so OUT reads like the unsplit run (``python -m bionav.thesis`` reuses it).
"""

from __future__ import annotations

import argparse
import shutil
import sys
from pathlib import Path
from typing import Any, Sequence

import numpy as np
import yaml

from bionav.errors import UserError
from bionav.evaluation.measures import quality_measures
from bionav.experiments.grid_homing import HOME_VECTOR_SCHEMA, write_per_snapshot_csv
from bionav.experiments.runner import LOG_FILE, METRICS_FILE, json_safe, read_metrics
from bionav.files import write_json_atomic
from bionav.logs.reader import read_attachment, read_messages
from bionav.logs.writer import McapLog

TOPIC = "/grid_homing/home_vectors"
#: metrics every task must share
_SHARED = ("experiment", "homing", "db", "n_images")


def _as_float(values: Sequence[Any]) -> np.ndarray:
    return np.array([np.nan if v is None else float(v) for v in values], dtype=float)


def merge_grid_runs(task_dirs: Sequence[Path], out: Path) -> dict[str, Any]:
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
    if not task_dirs:
        raise UserError("no task directories given; name the run directories of the tasks to merge.")
    metas, rows = [], {}
    currents = None
    for d in map(Path, task_dirs):
        m = read_metrics(d)
        if not m or m.get("status") != "completed":
            raise UserError(f"task {d} has not completed (its metrics.json says "
                            f"{(m or {}).get('status', 'nothing')}); run it again (bionav.resume=true) first.")
        if m.get("experiment") != "grid_homing":
            raise UserError(f"task {d} is not a grid_homing run ({m.get('experiment')}); merge grid_homing tasks only.")
        if metas and any(m.get(k) != metas[0].get(k) for k in _SHARED):
            diff = [k for k in _SHARED if m.get(k) != metas[0].get(k)]
            raise UserError(f"task {d} belongs to another run ({', '.join(diff)} differ from {task_dirs[0]}).")
        metas.append(m)
        for _topic, _t, msg in read_messages(d / LOG_FILE, topics=[TOPIC]):
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
    blocks = {tuple(m["block"]) for m in metas if "block" in m}
    if blocks:
        n = {b[1] for b in blocks}
        want = {(i, next(iter(n))) for i in range(next(iter(n)))} if len(n) == 1 else set()
        if blocks != want or len(blocks) != len(metas):
            missing = sorted(want - blocks) if want else "blocks of different splits"
            raise UserError(f"the tasks do not make one whole run: missing or mixed blocks {missing}. Give the "
                            f"directories of every block i of one split n (experiment.block=[i,n]).")
    order = sorted(rows)
    ae = np.stack([_as_float(rows[i][1]["ae"]) for i in order])
    success = np.stack([np.asarray(rows[i][1]["success"], dtype=bool) for i in order])
    compass = [rows[i][1].get("compass_error") for i in order]
    q = quality_measures(ae, success)

    out = Path(out)
    if read_metrics(out) is not None and read_metrics(out).get("status") == "completed":
        raise UserError(f"{out} already holds a completed run; merge into a new directory.")
    (out / "plots").mkdir(parents=True, exist_ok=True)
    n_pairs = [int(m["n_pairs"]) for m in metas]
    ms = [float(m["ms_per_home_vector"]) for m in metas]
    metrics: dict[str, Any] = {k: metas[0][k] for k in ("experiment", "homing", "db")}
    metrics.update(aae=q.aae, mae=q.mae, rr=q.rr, n_images=metas[0]["n_images"], n_pairs=int(sum(n_pairs)),
                   ms_per_home_vector=float(np.dot(ms, n_pairs) / max(1, sum(n_pairs))))
    metrics.update({k: v for k, v in metas[0].items() if k.endswith("_per_image")})
    if all(c is not None for c in compass):
        metrics["compass_aae"] = float(np.nanmean(np.abs(np.concatenate([_as_float(c) for c in compass]))))
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
            log.write(TOPIC, rows[i][1], schema_name="bionav.HomeVectorField", schema=HOME_VECTOR_SCHEMA)
    from bionav.experiments.homing_plots import plot_per_snapshot_maps

    grid_shape = tuple(int(v) for v in currents.max(axis=0) + 1)
    plot_per_snapshot_maps(out / "plots" / "per_snapshot.png", positions=s_pos, grid_shape=grid_shape,
                           aae_s=q.aae_s, rr_s=q.rr_s,
                           title=f"{metrics['homing']} on {metrics['db']}: AAE*={q.aae:.3f} rad, "
                                 f"MAE*={q.mae:.3f} rad, RR*={q.rr:.3f} ({len(metas)} tasks)")
    hydra_dir = Path(task_dirs[0]) / ".hydra"
    if hydra_dir.is_dir():
        shutil.copytree(hydra_dir, out / ".hydra", dirs_exist_ok=True)
        ov_file = out / ".hydra" / "overrides.yaml"
        if ov_file.is_file():
            overrides = [o for o in (yaml.safe_load(ov_file.read_text()) or [])
                         if not str(o).lstrip("+~").startswith("experiment.block=")]
            ov_file.write_text(yaml.safe_dump(overrides))
    write_json_atomic(out / METRICS_FILE, json_safe(metrics))
    return metrics


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m bionav.experiments.grid_homing_merge",
                                description="Join the tasks (experiment.block=[i,n]) of a split grid-homing run "
                                            "into one run directory with the unsplit run's files.")
    p.add_argument("out", help="directory for the merged run")
    p.add_argument("tasks", nargs="+", help="the tasks' run directories")
    args = p.parse_args(argv)
    try:
        metrics = merge_grid_runs([Path(t) for t in args.tasks], Path(args.out))
    except UserError as exc:
        print(f"grid_homing_merge: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        print(f"grid_homing_merge: error: cannot write {exc.filename or args.out}: {exc.strerror or exc}. "
              f"Free space or choose another OUT; the tasks are untouched.", file=sys.stderr)
        return 1
    print(f"merged {metrics['tasks']} tasks: AAE*={metrics['aae']:.4f} rad, MAE*={metrics['mae']:.4f} rad, "
          f"RR*={metrics['rr']:.4f} -> {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
