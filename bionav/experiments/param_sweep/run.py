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
from typing import Any

import numpy as np
from omegaconf import DictConfig, OmegaConf

from bionav.db.database import ImageDatabase
from bionav.errors import UserError
from bionav.experiments.param_sweep.config import ParamSweepConfig
from bionav.experiments.param_sweep.levels import evaluate_levels, sweep_levels
from bionav.experiments.param_sweep.plots import plot_levels

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


def _signature_setup(cfg: DictConfig):
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
    homing_cfg, sig_cfg = pass_through(homing_cfg, sig_name, sig_cfg)
    return ParameterHoming, homing_cfg, sig_name, sig_cls, sig_cfg


def pass_through(homing_cfg, sig_name: str, sig_cfg):
    """homing.rings/n_coeffs/bins pass through to the signature's base config; the sweep varies R or K on top."""
    names = {f.name for f in dataclasses.fields(sig_cfg)}
    passed = {k: getattr(homing_cfg, k) for k in ("rings", "n_coeffs", "bins") if getattr(homing_cfg, k) is not None}
    sig_cfg = dataclasses.replace(sig_cfg, **{k: v for k, v in passed.items() if k in names})
    homing_cfg = dataclasses.replace(homing_cfg, signature=sig_name, rings=None, n_coeffs=None, bins=None)
    return homing_cfg, sig_cfg


def _finite(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def configuration_rows(db: ImageDatabase, sig_name: str, preprocess: str, homings, measures, ms: float) -> list[dict[str, Any]]:
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


def write_configurations(ctx, rows: list[dict[str, Any]]) -> None:
    for row in rows:
        ctx.log.write(
            "/param_sweep/configuration", row, schema_name="bionav.ParameterConfiguration", schema=CONFIGURATION_SCHEMA
        )
    with open(ctx.dir / ROWS_FILE, "w") as f:
        for row in rows:
            f.write(json.dumps(row) + "\n")


def run(exp: ParamSweepConfig, ctx) -> dict[str, Any]:
    """One job of ``experiment=param_sweep`` (``experiment.scope=job``) with the checked ``exp`` (the rest of the
    config in ``ctx.cfg``); ``scope=grid`` is :func:`bionav.experiments.param_sweep.grid.run_grid`."""
    from bionav.experiments.common import load_configured_database

    cfg = ctx.cfg
    homing_cls, homing_cfg, sig_name, sig_cls, sig_cfg = _signature_setup(cfg)
    db = load_configured_database(cfg)
    levels = sweep_levels(sig_cls, rings=list(exp.rings), n_coeffs=list(exp.n_coeffs))
    preprocess = str(OmegaConf.select(cfg, "preprocess.name", default="none"))
    size = f"{db.geometry.width}x{db.geometry.height}"
    homings, measures, ms = evaluate_levels(
        homing_cls, homing_cfg, sig_cls, sig_cfg, levels, db,
        step_length=exp.step_length, success_radius=exp.success_radius,
    )
    rows = configuration_rows(db, sig_name, preprocess, homings, measures, ms)
    write_configurations(ctx, rows)
    plot_levels(ctx.plots / "levels.png", rows, title=f"[{sig_name}] on {db.name}, {size}, {preprocess}")

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
