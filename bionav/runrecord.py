"""What a run directory records, and whether a command may continue it.

A run directory of ``python -m bionav`` holds the run's configuration as Hydra
composed it (``.hydra/config.yaml``, with ``overrides.yaml`` and ``hydra.yaml``)
and its outcome (``metrics.json``: ``running``, ``completed``, ``failed`` or
``interrupted``). ``bionav.resume=true`` -- and ``python -m bionav.thesis``
when it reuses runs -- may continue or reuse a run only when the configuration
asked for is the recorded one:

* :func:`recorded_config` reads ``.hydra/config.yaml`` (size-capped, one
  message for a damaged file);
* :func:`config_differences` compares a requested configuration with it, key by
  key (dotted keys such as ``homing.name``; values as written, interpolations
  unresolved), ignoring :data:`NEUTRAL_KEYS`, which do not change results;
* :func:`differences_text` names the differing keys in one sentence;
* :func:`write_record` writes the record as Hydra would (``python -m bionav``
  tells Hydra not to, ``hydra.output_subdir=null``, and writes it itself only
  where no run is recorded yet, so a resumed run's record is never rewritten).
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any, Mapping, Sequence

#: Hydra's record of a run, below its directory
RECORD_DIR = ".hydra"
CONFIG_FILE = "config.yaml"
METRICS_FILE = "metrics.json"
#: config keys (and their sub-keys) that do not change a run's results: ignored when runs are compared
NEUTRAL_KEYS = ("bionav.resume", "bionav.fail_on_job_error", "bionav.cache_prepared", "workers", "cache_dir",
                "hydra")


def read_status(run_dir: str | os.PathLike) -> str | None:
    """The ``status`` of a run directory's metrics.json (``None``: no readable metrics.json)."""
    from bionav.files import not_a_regular_file

    path = Path(run_dir) / METRICS_FILE
    if not_a_regular_file(path) is not None:
        return None
    try:
        metrics = json.loads(path.read_text(encoding="utf-8", errors="replace"))
    except (OSError, ValueError):
        return None
    return str(metrics.get("status")) if isinstance(metrics, dict) else None


def has_record(run_dir: str | os.PathLike) -> bool:
    """True when ``run_dir`` holds a run's record (its metrics.json or its ``.hydra/config.yaml``)."""
    run_dir = Path(run_dir)
    return (run_dir / METRICS_FILE).exists() or (run_dir / RECORD_DIR / CONFIG_FILE).exists()


def recorded_config(run_dir: str | os.PathLike) -> dict | None:
    """The configuration recorded in ``run_dir/.hydra/config.yaml`` as a plain dict (``None`` if absent).

    Raises
    ------
    UserError
        When the file is too large, not UTF-8 or not a YAML mapping.
    """
    from omegaconf import OmegaConf

    from bionav.datafile import read_user_text
    from bionav.errors import UserError

    path = Path(run_dir) / RECORD_DIR / CONFIG_FILE
    if not path.exists():
        return None
    fix = (f"The run in {run_dir} cannot be continued or reused; run into another directory "
           "(hydra.run.dir=..., --out ...).")
    text = read_user_text(path, what="The recorded configuration", fix=fix, kind="config")
    try:
        cfg = OmegaConf.create(text)
    except Exception as exc:  # OmegaConf's YAML errors have many types
        raise UserError(f"The recorded configuration {path} is not YAML ({type(exc).__name__}). {fix}") from None
    if not OmegaConf.is_dict(cfg):
        raise UserError(f"The recorded configuration {path} is not a mapping of keys. {fix}")
    return OmegaConf.to_container(cfg, resolve=False)


def recorded_overrides(run_dir: str | os.PathLike) -> list[str] | None:
    """The overrides recorded in ``run_dir/.hydra/overrides.yaml`` (``None`` if absent or not Hydra's list)."""
    import yaml

    from bionav.files import not_a_regular_file

    path = Path(run_dir) / RECORD_DIR / "overrides.yaml"
    if not_a_regular_file(path) is not None or path.stat().st_size > 2**20:
        return None
    try:
        items = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, ValueError, yaml.YAMLError):
        return None
    return [str(i) for i in items] if isinstance(items, list) else None


def plain_config(cfg: Any) -> dict:
    """A composed configuration (DictConfig or mapping) as a plain dict, interpolations unresolved."""
    from omegaconf import OmegaConf

    if OmegaConf.is_config(cfg):
        return OmegaConf.to_container(cfg, resolve=False)
    return dict(cfg)


def _flat(value: Any, prefix: str = "") -> dict[str, Any]:
    if isinstance(value, Mapping) and (value or not prefix):
        out: dict[str, Any] = {}
        for k, v in value.items():
            out.update(_flat(v, f"{prefix}{k}."))
        return out
    return {prefix[:-1]: value}


def _neutral(key: str, neutral: tuple[str, ...]) -> bool:
    return any(key == n or key.startswith(f"{n}.") for n in neutral)


def config_differences(requested: Mapping, recorded: Mapping, *,
                       neutral: tuple[str, ...] = NEUTRAL_KEYS) -> list[tuple[str, Any, Any]]:
    """``(key, requested value, recorded value)`` for every dotted key whose values differ.

    A key missing on one side has the value ``None`` there (a ``None`` on both
    sides is no difference). Keys in ``neutral`` (and below them) are ignored.
    """
    a, b = _flat(requested), _flat(recorded)
    out = []
    for key in sorted(set(a) | set(b)):
        if _neutral(key, neutral):
            continue
        if a.get(key) != b.get(key):
            out.append((key, a.get(key), b.get(key)))
    return out


def _show(value: Any) -> str:
    text = "(not set)" if value is None else json.dumps(value) if isinstance(value, (list, dict)) else str(value)
    return text if len(text) <= 40 else text[:37] + "..."


def differences_text(diffs: list[tuple[str, Any, Any]], *, limit: int = 6) -> str:
    """``homing.name (mfdid asked for, sift recorded), ...`` for the first ``limit`` differences.

    Where a node's ``name`` differs (another plugin, another experiment), its other keys are
    not listed: they differ because the node does.
    """
    renamed = [k[: -len(".name")] for k, _, _ in diffs if k.endswith(".name")]
    kept = [d for d in diffs if d[0].endswith(".name") or not any(d[0].startswith(f"{n}.") for n in renamed)]
    kept.sort(key=lambda d: not d[0].endswith(".name"))
    shown = [f"{k} ({_show(new)} asked for, {_show(old)} recorded)" for k, new, old in kept[:limit]]
    more = f" and {len(kept) - limit} more" if len(kept) > limit else ""
    return ", ".join(shown) + more


def write_record(run_dir: str | os.PathLike, task_cfg: Any, hydra_cfg: Any, overrides: Sequence[str]) -> None:
    """Write ``.hydra/config.yaml``, ``hydra.yaml`` and ``overrides.yaml`` as Hydra's job set-up does.

    Parameters
    ----------
    task_cfg : DictConfig
        The job's configuration (without ``hydra``), saved unresolved.
    hydra_cfg : DictConfig
        The whole configuration of Hydra (its ``hydra`` node under ``hydra``).
    overrides : sequence of str
        The job's overrides (``hydra.overrides.task``).
    """
    from omegaconf import OmegaConf, open_dict

    from bionav.files import write_atomic

    folder = Path(run_dir) / RECORD_DIR
    hydra_cfg = OmegaConf.create(OmegaConf.to_container(hydra_cfg, resolve=False))
    with open_dict(hydra_cfg):
        hydra_cfg.hydra.output_subdir = RECORD_DIR  # where the record is, as if Hydra had written it
    for name, node in ((CONFIG_FILE, task_cfg), ("hydra.yaml", hydra_cfg), ("overrides.yaml", list(overrides))):
        write_atomic(folder / name, OmegaConf.to_yaml(node if OmegaConf.is_config(node) else OmegaConf.create(node)))
