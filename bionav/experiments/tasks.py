"""Runs as independent tasks: the split (``experiment.block=[i,n]``) and the merge bookkeeping.

An experiment that can be large (grid homing, the cross-database test) splits its snapshots
into ``n`` blocks: task ``i`` runs every ``n``-th snapshot starting at the ``i``-th, as an
ordinary run with its own directory, lock, metrics.json and run.mcap, so that a launcher can
spread the tasks over cores and nodes and a lost task reruns alone. The experiment module's
``merge(task_dirs, out)`` reads the tasks' logged per-snapshot results back and writes the
unsplit run's files; the helpers here are the parts every merge shares.
``python -m bionav.experiments.merge OUT TASK_DIR...`` is the command.
"""

from __future__ import annotations

import shutil
from pathlib import Path
from typing import Any, Sequence

import yaml

from bionav.errors import UserError
from bionav.experiments.runner import METRICS_FILE, json_safe, read_metrics
from bionav.files import write_json_atomic

#: the override that makes a run one task of a split run
BLOCK_KEY = "experiment.block"


def block_of(block: Sequence[int] | None, indices: Sequence[int], *, what: str = "snapshot") -> list[int]:
    """The snapshot indices of task ``block = [i, n]``: every n-th of ``indices`` from the i-th.

    ``what`` names the items in the message of a block that selects nothing.

    Raises
    ------
    UserError
        ``i`` outside ``0..n-1``, or a block that selects nothing (more tasks than snapshots).
    """
    indices = [int(v) for v in indices]
    if block is None:
        return indices
    i, n = (int(v) for v in block)
    if n < 1 or not 0 <= i < n:
        raise UserError(f"bad value {BLOCK_KEY}=[{i}, {n}]: give [i, n] with 0 <= i < n (task i of n).")
    if i >= len(indices):
        raise UserError(f"{BLOCK_KEY}=[{i}, {n}] selects no {what}: there are {len(indices)}; split into at most "
                        f"{len(indices)} tasks.")
    return indices[i::n]


def read_task(task_dir: Path, earlier: Sequence[dict], *, shared: Sequence[str]) -> dict[str, Any]:
    """A task's metrics, checked: completed, and of the same run as the ``earlier`` tasks (``shared`` keys)."""
    m = read_metrics(task_dir)
    if not m or m.get("status") != "completed":
        raise UserError(f"task {task_dir} has not completed (its metrics.json says "
                        f"{(m or {}).get('status', 'nothing')}); run it again (bionav.resume=true) first.")
    if earlier and any(m.get(k) != earlier[0].get(k) for k in shared):
        diff = [k for k in shared if m.get(k) != earlier[0].get(k)]
        raise UserError(f"task {task_dir} belongs to another run ({', '.join(diff)} differ from the first task).")
    return m


def check_blocks(metas: Sequence[dict]) -> None:
    """The tasks are every block ``[i, n]`` of one split ``n`` (tasks without a block: anything goes)."""
    blocks = {tuple(m["block"]) for m in metas if "block" in m}
    if not blocks:
        return
    splits = {b[1] for b in blocks}
    want = {(i, next(iter(splits))) for i in range(next(iter(splits)))} if len(splits) == 1 else set()
    if blocks != want or len(blocks) != len(metas):
        missing = sorted(want - blocks) if want else "blocks of different splits"
        raise UserError(f"the tasks do not make one whole run: missing or mixed blocks {missing}. Give the "
                        f"directories of every block i of one split n ({BLOCK_KEY}=[i,n]).")


def merge_target(out: Path) -> Path:
    """The merged run's directory, created with its ``plots/``; a completed run there is refused."""
    out = Path(out)
    done = read_metrics(out)
    if done is not None and done.get("status") == "completed":
        raise UserError(f"{out} already holds a completed run; merge into a new directory.")
    (out / "plots").mkdir(parents=True, exist_ok=True)
    return out


def finish_merge(task_dirs: Sequence[Path], out: Path, metrics: dict[str, Any]) -> None:
    """Copy the first task's ``.hydra/`` less its block override, then write metrics.json (last)."""
    hydra_dir = Path(task_dirs[0]) / ".hydra"
    if hydra_dir.is_dir():
        shutil.copytree(hydra_dir, out / ".hydra", dirs_exist_ok=True)
        ov_file = out / ".hydra" / "overrides.yaml"
        if ov_file.is_file():
            overrides = [o for o in (yaml.safe_load(ov_file.read_text()) or [])
                         if not str(o).lstrip("+~").startswith(f"{BLOCK_KEY}=")]
            ov_file.write_text(yaml.safe_dump(overrides))
        cfg_file = out / ".hydra" / "config.yaml"  # the merged run's configuration is the unsplit run's
        if cfg_file.is_file():
            from omegaconf import OmegaConf, open_dict

            cfg = OmegaConf.load(cfg_file)
            if OmegaConf.select(cfg, BLOCK_KEY, default=None) is not None:
                with open_dict(cfg):
                    cfg.experiment.block = None
                cfg_file.write_text(OmegaConf.to_yaml(cfg))
    write_json_atomic(out / METRICS_FILE, json_safe(metrics))
