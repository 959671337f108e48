"""Typed configs of the experiments: one dataclass per ``experiment=<name>``, defaults in one place.

Each dataclass is stored in Hydra's ConfigStore as ``experiment_schema/<name>``
(:func:`register`); the preset ``conf/experiment/<name>.yaml`` puts it under
``experiment`` first in its defaults list and then sets only what differs or
what refers to other keys. Hydra therefore rejects unknown keys and values of
the wrong type at composition; :func:`experiment_config` fills the defaults
for configs built without Hydra and checks every value against its range
(:func:`bionav.validation.check_config`), naming the key (``experiment.<key>``).

Units: metres and grid units as named; angles in degrees only in keys ending
``_deg``; times ISO 8601 with zone.

The dataclasses live in one module per family (``grid``, ``spectral``,
``polarization``, ``cleaning``, ``route``) and are re-exported here, the one
import path of the experiments and of plugin authors
(``from bionav.experiments.configs import GridHomingConfig``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from omegaconf import DictConfig, OmegaConf

from bionav.experiments.configs.cleaning import (
    CleaningCameraConfig,
    CleaningConfig,
    CleaningOracleConfig,
    LayoutConfig,
)
from bionav.experiments.configs.grid import CrossDbConfig, GridHomingConfig, ParamSweepConfig
from bionav.experiments.configs.polarization import (
    PolCompassConfig,
    PolFilterConfig,
    PolPartialConfig,
    PolRecordingsConfig,
    PolScanConfig,
    PolSkyConfig,
    PolVsEmConfig,
    RecordingsConfig,
)
from bionav.experiments.configs.route import ROUTE_METHODS, ROUTE_PROTOCOLS, RouteHomingConfig
from bionav.experiments.configs.spectral import (
    ContrastLdaConfig,
    ContrastScanConfig,
    DataConfig,
    LearnSamplesConfig,
    SkyConditionConfig,
    SkylineHomingConfig,
)
from bionav.validation import bounded, check_config

__all__ = [
    "EXPERIMENT_CONFIGS", "GROUP_CONFIGS", "ROUTE_METHODS", "ROUTE_PROTOCOLS", "CleaningCameraConfig",
    "CleaningConfig", "CleaningOracleConfig", "ContrastLdaConfig", "ContrastScanConfig", "CrossDbConfig",
    "DataConfig", "GridHomingConfig", "LayoutConfig", "LearnSamplesConfig", "ParamSweepConfig",
    "PolCompassConfig", "PolFilterConfig", "PolPartialConfig", "PolRecordingsConfig", "PolScanConfig",
    "PolSkyConfig", "PolVsEmConfig", "RecordingsConfig", "RouteHomingConfig", "RunSettings",
    "SkyConditionConfig", "SkylineHomingConfig", "check_group_nodes", "check_run_settings",
    "experiment_config", "register", "typed_node",
]


def _schema_file(schema: type) -> str:
    """The source file of a config dataclass as users find it (``bionav/experiments/configs/grid.py``)."""
    return schema.__module__.replace(".", "/") + ".py"


#: other option groups with a typed schema: group -> dataclass (checked by :func:`check_group_nodes`)
GROUP_CONFIGS: dict[str, type] = {"layout": LayoutConfig, "data": DataConfig}


def typed_node(node: Any, schema: type, *, prefix: str, what: str) -> DictConfig:
    """``node`` merged onto ``schema``: unknown keys and wrong types named, every value range-checked.

    Parameters
    ----------
    node : DictConfig or Mapping
        The (resolved) config node.
    schema : type
        Its dataclass.
    prefix : str
        The key users type for the node (``layout``).
    what : str
        Said in messages (``layout=short_lanes``).
    """
    from omegaconf.errors import OmegaConfBaseException

    from bionav.config import unknown_key_message
    from bionav.errors import UserError

    plain = OmegaConf.to_container(node, resolve=True) if isinstance(node, DictConfig) else dict(node)
    try:
        typed = OmegaConf.merge(OmegaConf.structured(schema), plain)
        instance = OmegaConf.to_object(typed)
    except OmegaConfBaseException as exc:
        key = str(getattr(exc, "full_key", "") or "")
        if type(exc).__name__ in ("ConfigKeyError", "ConfigAttributeError") and key:
            parent, bad = key.rsplit(".", 1) if "." in key else ("", key)
            where = OmegaConf.select(OmegaConf.structured(schema), parent) if parent else OmegaConf.structured(schema)
            valid = [str(k) for k in where.keys()] if isinstance(where, DictConfig) else []
            full_parent = f"{prefix}.{parent}" if parent else prefix
            raise UserError(unknown_key_message(full_parent, bad, valid, what=what)) from None
        if type(exc).__name__ == "MissingMandatoryValue" and key:
            raise UserError(f"{prefix}.{key} has no value ({what} needs it); add {prefix}.{key}=<value> "
                            "on the command line.") from None
        raise UserError(
            f"bad value for {prefix}.{key or '<key>'} ({what}): {str(exc).splitlines()[0]}. "
            f"Give it a value of the declared type (see {schema.__name__} in {_schema_file(schema)})."
        ) from None
    check_config(instance, prefix=prefix)
    return typed


def check_group_nodes(cfg: DictConfig) -> None:
    """Check the ``layout`` and ``data`` nodes (when present) against :data:`GROUP_CONFIGS`."""
    for group, schema in GROUP_CONFIGS.items():
        node = cfg.get(group) if isinstance(cfg, DictConfig) else None
        if node is not None:
            typed_node(node, schema, prefix=group, what=f"{group}={node.get('name', '?')}")


@dataclass
class RunSettings:
    """Top-level keys of every run (``conf/config.yaml``): ``seed=``, ``workers=``."""

    seed: int = bounded(0, ge=0, le=2**32 - 1)
    workers: int = bounded(2, ge=1, le=1024)


def check_run_settings(cfg: DictConfig) -> None:
    """Check the top-level ``seed`` and ``workers`` against :class:`RunSettings` (key, value, range)."""
    from bionav.errors import UserError

    values = {}
    for f in ("seed", "workers"):
        value = cfg.get(f) if isinstance(cfg, DictConfig) else None
        if value is None:
            continue
        if isinstance(value, bool) or not isinstance(value, int):
            raise UserError(f"bad value {f}={value}: it must be an integer; allowed: "
                            f"{RunSettings.__dataclass_fields__[f].metadata['range'].describe(integer=True)}.")
        values[f] = value
    check_config(RunSettings(**values), prefix="")


#: experiment name -> its config dataclass
EXPERIMENT_CONFIGS: dict[str, type] = {
    "grid_homing": GridHomingConfig,
    "cross_db": CrossDbConfig,
    "param_sweep": ParamSweepConfig,
    "contrast_lda": ContrastLdaConfig,
    "contrast_scan": ContrastScanConfig,
    "skyline_homing": SkylineHomingConfig,
    "pol_compass": PolCompassConfig,
    "cleaning": CleaningConfig,
    "pol_recordings": PolRecordingsConfig,
    "route_homing": RouteHomingConfig,
}


def register(store=None) -> None:
    """Store every experiment's dataclass as ``experiment_schema/<name>`` in Hydra's ConfigStore."""
    from hydra.core.config_store import ConfigStore

    store = store or ConfigStore.instance()
    for name, cls in EXPERIMENT_CONFIGS.items():
        store.store(group="experiment_schema", name=name, node=cls, provider="bionav")
    # the top-level recordings.* node of experiment=pol_recordings
    store.store(name="recordings_schema", node=RecordingsConfig, provider="bionav")


def experiment_config(cfg: DictConfig, name: str | None = None) -> DictConfig:
    """The run's ``experiment`` node typed by its dataclass, defaults filled, every value checked.

    Parameters
    ----------
    cfg : DictConfig
        The whole run config (``experiment.name`` selects the dataclass;
        interpolations such as ``${seed}`` resolve against it, ``seed``
        defaulting to 0).
    name : str, optional
        The experiment to assume when the node has no ``name`` (an experiment
        module passes its own).

    Returns
    -------
    DictConfig
        A structured node (attribute access, ``.get``, typed assignment) of
        :data:`EXPERIMENT_CONFIGS` ``[name]``; an experiment without a
        dataclass gets its node back unchanged.

    Raises
    ------
    UserError
        An unknown key (the message lists the valid ones and the closest), a
        value of the wrong type, or a value outside its range (key, value and
        allowed range named).
    """
    from omegaconf.errors import OmegaConfBaseException

    from bionav.config import unknown_key_message
    from bionav.errors import UserError

    node = cfg.get("experiment") if isinstance(cfg, DictConfig) else None
    if node is not None and node.get("name") is not None:
        name = str(node.get("name"))
    schema = EXPERIMENT_CONFIGS.get(name or "")
    if schema is None:
        return node
    try:
        root = OmegaConf.merge(OmegaConf.create({"seed": 0, "experiment": OmegaConf.structured(schema)}), cfg)
        exp = root.experiment
        instance = OmegaConf.to_object(exp)
    except OmegaConfBaseException as exc:
        key = str(getattr(exc, "full_key", "") or "")
        kind = type(exc).__name__
        if kind in ("ConfigKeyError", "ConfigAttributeError") and key:
            parent, bad = key.rsplit(".", 1) if "." in key else ("", key)
            where = OmegaConf.select(OmegaConf.structured(schema), parent.partition(".")[2]) if "." in parent \
                else OmegaConf.structured(schema)
            valid = [str(k) for k in where.keys()] if isinstance(where, DictConfig) else []
            raise UserError(unknown_key_message(parent, bad, valid, what=f"experiment={name}")) from None
        if kind == "MissingMandatoryValue" and key:
            raise UserError(f"{key} has no value (experiment={name} needs it); add {key}=<value> "
                            "on the command line.") from None
        raise UserError(
            f"bad value for {key or 'experiment'} (experiment={name}): {str(exc).splitlines()[0]}. "
            f"Give it a value of the declared type (see {schema.__name__} in {_schema_file(schema)})."
        ) from None
    check_config(instance, prefix="experiment")
    return exp
