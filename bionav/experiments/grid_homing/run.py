"""``experiment=grid_homing``: all-pairs homing on a grid database (thesis 3.2, 5.1).

Writes metrics.json (aae, mae, rr, n_images, n_pairs, ms_per_home_vector,
compass_aae for methods with a compass), per_snapshot.csv, run.mcap (home
vectors per snapshot, agent paths of the plotted snapshots) and plots/.
With ``experiment.block=[i,n]`` a run is task i of n (every n-th snapshot);
:func:`bionav.experiments.grid_homing.merge.merge` joins the tasks into the unsplit run's files
(``python -m bionav.experiments.merge``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from omegaconf import OmegaConf

from bionav.errors import UserError
from bionav.evaluation.agent import evaluate_agents
from bionav.evaluation.measures import angular_errors, ideal_home_angles, quality_measures
from bionav.evaluation.pairs import home_vector_matrix
from bionav.experiments.common import load_configured_database, make_homing, prepared_cache
from bionav.experiments.grid_homing.config import GridHomingConfig
from bionav.experiments.grid_homing.plots import plot_fields
from bionav.experiments.grid_homing.resume import ROWS_TOPIC, resumed_rows, with_resumed_rows
from bionav.experiments.tasks import block_of
from bionav.files import write_csv_atomic

HOME_VECTOR_SCHEMA = {
    "type": "object",
    "properties": {
        "snapshot": {"type": "array", "items": {"type": "integer"}, "description": "snapshot cell (x, y)"},
        "currents": {"type": "array", "description": "current-view cells (x, y)"},
        "angles": {"type": "array", "description": "home directions, radians CCW in the grid frame (null: none)"},
        "ae": {"type": "array", "description": "angular errors, radians"},
        "success": {"type": "array", "description": "agent reached the snapshot"},
        "compass_error": {"type": ["array", "null"],
                          "description": "estimated minus true rotation, radians (null: no compass)"},
    },
}

HOME_VECTOR_ROW_SCHEMA = {
    "type": "object",
    "description": "one snapshot's home vectors, logged as soon as computed (currents: every cell in database order)",
    "properties": {
        "snapshot": {"type": "array", "items": {"type": "integer"}, "description": "snapshot cell (x, y)"},
        "angles": {"type": "array", "description": "home directions, radians CCW in the grid frame (null: none)"},
        "ae": {"type": "array", "description": "angular errors, radians (null: none)"},
        "compass_error": {"type": "array", "description": "estimated minus true rotation, radians (null: none)"},
    },
}


HOME_VECTOR_PARTIAL_SCHEMA = {
    "type": "object",
    "description": ("home vectors of a snapshot's row still being computed, logged about every 2 s (the whole row "
                    "follows on /grid_homing/snapshot_rows when finished)"),
    "properties": {
        "snapshot": {"type": "array", "items": {"type": "integer"}, "description": "snapshot cell (x, y)"},
        "currents": {"type": "array", "description": "current-view cells (x, y) of these pairs"},
        "angles": {"type": "array", "description": "home directions, radians CCW in the grid frame (null: none)"},
        "ae": {"type": "array", "description": "angular errors, radians (null: none)"},
        "compass_error": {"type": "array", "description": "estimated minus true rotation, radians (null: none)"},
    },
}


def _finite_or_none(values) -> list[float | None]:
    return [float(a) if np.isfinite(a) else None for a in np.asarray(values, dtype=float)]


def write_per_snapshot_csv(path: Path, positions: np.ndarray, measures) -> None:
    """``per_snapshot.csv``: AAE_s and MAE_s (radians) and RR_s of every snapshot cell ``(x, y)``."""
    write_csv_atomic(path, ["x", "y", "aae_s", "mae_s", "rr_s"],
                     ([int(x), int(y), f"{a:.6f}", f"{m:.6f}", f"{r:.6f}"]
                      for (x, y), a, m, r in zip(positions, measures.aae_s, measures.mae_s, measures.rr_s)))


def _row_loggers(ctx, db):
    """``on_row`` and ``on_partial`` of :func:`home_vector_matrix`: rows and partial rows into ``run.mcap``."""

    def log_row(si: int, angles: np.ndarray, compass: np.ndarray) -> None:
        """Each snapshot's home vectors as soon as they are computed (a crash loses no finished row)."""
        ae_row = angular_errors(angles[None], ideal_home_angles(db.positions[[si]], db.positions))[0]
        ctx.log.write(
            ROWS_TOPIC,
            {"snapshot": db.positions[si], "angles": _finite_or_none(angles), "ae": _finite_or_none(ae_row),
             "compass_error": _finite_or_none(compass)},
            schema_name="bionav.HomeVectorRow",
            schema=HOME_VECTOR_ROW_SCHEMA,
        )

    def log_partial(si: int, currents: np.ndarray, angles: np.ndarray, compass: np.ndarray) -> None:
        """Pairs of a row still being computed, every ~2 s (a crash loses at most that much of a long row)."""
        ae = angular_errors(angles[None], ideal_home_angles(db.positions[[si]], db.positions[currents]))[0]
        ctx.log.write(
            "/grid_homing/partial_rows",
            {"snapshot": db.positions[si], "currents": db.positions[currents], "angles": _finite_or_none(angles),
             "ae": _finite_or_none(ae), "compass_error": _finite_or_none(compass)},
            schema_name="bionav.HomeVectorPartialRow",
            schema=HOME_VECTOR_PARTIAL_SCHEMA,
        )
        ctx.log.flush()  # to the file now: the ~2 s of this period are all a crash can lose

    return log_row, log_partial


def _log_fields(ctx, db, hv, ae, success, paths) -> None:
    """Every snapshot's home-vector field (angles and AE in radians, grid frame) and the agents' paths."""
    for row, si in enumerate(hv.snapshot_index):
        ctx.log.write(
            "/grid_homing/home_vectors",
            {
                "snapshot": db.positions[si],
                "currents": db.positions,
                "angles": _finite_or_none(hv.angles[row]),
                "ae": _finite_or_none(ae[row]),
                "success": success[row],
                "compass_error": None if hv.compass_error is None else _finite_or_none(hv.compass_error[row]),
            },
            schema_name="bionav.HomeVectorField",
            schema=HOME_VECTOR_SCHEMA,
        )
    for row, p in paths.items():
        ctx.log.write(
            "/grid_homing/agent_paths",
            {"snapshot": db.positions[hv.snapshot_index[row]], "paths": [path.tolist() for path in p]},
            schema_name="bionav.AgentPaths",
        )


def run(exp: GridHomingConfig, ctx) -> dict[str, Any]:
    """Run ``experiment=grid_homing`` with the checked ``exp`` (the rest of the config in ``ctx.cfg``)."""
    cfg = ctx.cfg
    db = load_configured_database(cfg)
    method = make_homing(cfg, ctx, db.geometry, raw_horizon_radius_px=db.meta.get("raw_horizon_radius_px"))
    snapshots = None if exp.snapshots is None else list(exp.snapshots)
    if snapshots is not None and max(snapshots) >= len(db):
        raise UserError(
            f"bad value experiment.snapshots={snapshots}: database {db.name!r} has {len(db)} images, so the "
            f"snapshot indices must be 0..{len(db) - 1}; drop the larger ones (null = every image)."
        )

    if exp.block is not None:
        snapshots = block_of(exp.block, range(len(db)) if snapshots is None else snapshots)

    log_row, log_partial = _row_loggers(ctx, db)
    wanted = list(range(len(db))) if snapshots is None else [int(v) for v in snapshots]
    done = resumed_rows(ctx, db, wanted, resume=bool(OmegaConf.select(cfg, "bionav.resume", default=False)))
    for si in (si for si in wanted if si in done):  # the new log holds every row, the earlier attempt's too
        log_row(si, *done[si])
    hv = home_vector_matrix(
        method, db, snapshot_index=[si for si in wanted if si not in done], workers=int(cfg.workers),
        progress=ctx.progress, cache=prepared_cache(cfg), on_row=log_row, on_partial=log_partial,
        device=str(cfg.get("device") or "cpu"),
    )
    hv = with_resumed_rows(hv, done, wanted)
    s_pos = db.positions[hv.snapshot_index]
    ae = angular_errors(hv.angles, ideal_home_angles(s_pos, db.positions))
    n_plots = min(exp.n_quiver_plots, len(hv.snapshot_index))
    plotted = set(np.linspace(0, len(hv.snapshot_index) - 1, n_plots).round().astype(int).tolist()) if n_plots else set()
    success, paths = evaluate_agents(
        db, hv, step_length=exp.step_length, success_radius=exp.success_radius, record=plotted
    )
    q = quality_measures(ae, success)

    _log_fields(ctx, db, hv, ae, success, paths)
    write_per_snapshot_csv(ctx.dir / "per_snapshot.csv", s_pos, q)
    plot_fields(ctx.plots, str(cfg.homing.name), db, hv, q, s_pos, success, paths, plotted)
    metrics: dict[str, Any] = {
        "homing": str(cfg.homing.name),
        "db": db.name,
        "aae": q.aae,
        "mae": q.mae,
        "rr": q.rr,
        "n_images": len(db),
        "n_pairs": hv.n_pairs,
        "ms_per_home_vector": hv.ms_per_home_vector,
    }
    if done:  # rows of the earlier attempt: their pairs count, the time per home vector is this attempt's
        metrics.update(n_pairs=hv.n_pairs + len(done) * (len(db) - 1), resumed_rows=len(done))
    if exp.block is not None:
        metrics["block"] = [int(v) for v in exp.block]
    metrics.update({f"{k}_per_image": v for k, v in hv.prepared_stats.items()})
    if hv.compass_error is not None:
        metrics["compass_aae"] = float(np.nanmean(np.abs(hv.compass_error)))
    return metrics
