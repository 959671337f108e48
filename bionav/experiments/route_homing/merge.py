"""The merge of a split ``experiment=route_homing experiment.protocol=ardin2016`` run (``experiment.block=[i,n]``).

``python -m bionav.experiments.merge OUT TASK_DIR...`` calls :func:`merge` through the experiment's plugin
(:class:`bionav.experiments.route_homing.RouteHoming`). Each task ran every n-th group of units (one route,
seed and condition) and wrote their rows (with each unit's index in the whole run) and paths; the merge puts
the rows back in unit order and writes the unsplit run's files
(:func:`bionav.experiments.route_homing.ardin2016.write_ardin_outputs`). Every unit has its own random streams, so
the rows equal those of the unsplit run (CPU times aside).
"""

from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from bionav.errors import UserError
from bionav.experiments.route_homing.ardin2016 import ARDIN_CSV, write_ardin_outputs
from bionav.experiments.route_homing.config import RouteHomingConfig
from bionav.experiments.route_homing.shared import PATH_SCHEMA, PATH_TOPIC
from bionav.experiments.runner import LOG_FILE
from bionav.experiments.tasks import check_blocks, finish_merge, merge_target, read_task

_TASK_SHARED = ("experiment", "protocol", "n_units", "routes", "agents", "seeds", "settings")
_INTS = ("seed", "training_stride", "routes_learned_together", "errors", "error_free", "reached_nest", "steps",
         "n_views", "unit")
_FLOATS = ("position_jitter_m", "heading_noise_deg", "start_offset_m", "camera_height_m", "cpu_s", "views_cpu_s")


def _typed(row: dict) -> dict:
    """A row of ``route_following.csv`` as the run holds it (counts int, measures float, the level as its axis')."""
    out: dict[str, Any] = dict(row)
    out.update({k: int(row[k]) for k in _INTS})
    out.update({k: float(row[k]) for k in _FLOATS})
    level = row["level"]
    out["level"] = None if not row["axis"] else level if row["axis"] == "world" else float(level)
    return out


def _task_rows(task_dir: Path, seed0: int) -> tuple[list[dict], dict, list[dict]]:
    """A task's rows, the paths of its units of the run as configured (first seed), and its logged path messages."""
    from bionav.logs.reader import read_messages

    with (task_dir / ARDIN_CSV).open(newline="") as f:
        rows = [_typed(r) for r in csv.DictReader(f)]
    messages = [msg for _topic, _t, msg in read_messages(task_dir / LOG_FILE, topics=[PATH_TOPIC])]
    if len(messages) != len(rows):
        raise UserError(f"task {task_dir} logged {len(messages)} paths for its {len(rows)} rows; run the task again.")
    paths = {(r["route"], r["agent"]): np.asarray(m["xy"], np.float64) for r, m in zip(rows, messages)
             if not r["axis"] and r["seed"] == seed0}
    return rows, paths, messages


def merge(task_dirs: Sequence[Path], out: Path) -> dict[str, Any]:
    """Merge the tasks (``experiment.block=[i,n]``) of one split ``ardin2016`` run into ``out``; the metrics.

    Raises
    ------
    UserError
        A task missing, not completed, not a task, of another run, or a unit in two tasks or in none.
    """
    from bionav.logs.reader import read_attachment
    from bionav.logs.writer import McapLog

    metas: list[dict] = []
    rows: list[dict] = []
    paths: dict = {}
    messages: list[tuple[dict, dict]] = []
    for d in map(Path, task_dirs):
        meta = read_task(d, metas, shared=_TASK_SHARED)
        if "block" not in meta or meta.get("protocol") != "ardin2016":
            raise UserError(f"{d} is not a task of a split route-following run (no experiment.block in its "
                            "metrics.json); give the run directories of experiment.block=[i,n] runs.")
        metas.append(meta)
        task_rows, task_paths, task_messages = _task_rows(d, int(meta["seeds"][0]))
        rows += task_rows
        paths.update(task_paths)
        messages += list(zip(task_rows, task_messages))
    check_blocks(metas)
    n_units = int(metas[0]["n_units"])
    units = sorted(r["unit"] for r in rows)
    if units != list(range(n_units)):
        raise UserError(f"the tasks hold {len(set(units))} different units of the run's {n_units} (some twice or "
                        "none); give each block i of one split n once.")
    rows.sort(key=lambda r: r["unit"])
    out = merge_target(out)
    meta = metas[0]
    exp = RouteHomingConfig(**meta["settings"])
    with McapLog(out / LOG_FILE) as log:
        config = read_attachment(Path(task_dirs[0]) / LOG_FILE, "config.yaml")
        if config is not None:
            log.attach("config.yaml", config, media_type="application/yaml")
        log.metadata("merge", {"tasks": ",".join(str(Path(d).resolve()) for d in task_dirs)})
        for _row, msg in sorted(messages, key=lambda m: m[0]["unit"]):
            log.write(PATH_TOPIC, msg, schema_name="bionav.RoutePath", schema=PATH_SCHEMA)
    info = {k: meta[k] for k in ("db", "protocol", "position_jitter_m", "step_m")}
    info.update(workers=[m["workers"] for m in metas], wall_s=math.fsum(m["wall_s"] for m in metas))
    metrics = write_ardin_outputs(out, rows, paths, exp=exp, db=meta["run_db"], cache_dir=meta["cache_dir"],
                                  routes=list(meta["routes"]), kinds=dict(meta["kinds"]), run_info=info)
    metrics.update(experiment=meta["experiment"], tasks=len(metas), status="completed",
                   wall_time_s=round(math.fsum(float(m.get("wall_time_s", 0.0)) for m in metas), 3))
    finish_merge(task_dirs, out, metrics)
    return metrics
