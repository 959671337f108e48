"""Typed configs of the experiments: one dataclass per ``experiment=<name>``, defaults in one place.

Each dataclass is registered as ``experiment_schema/<name>`` (:func:`register`;
:func:`bionav.config.register_configs` serves it to Hydra when a command composes it); the
preset ``conf/experiment/<name>.yaml`` puts it under ``experiment`` first in its defaults list and then sets only what differs or
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

import logging
from dataclasses import dataclass

from omegaconf import DictConfig, OmegaConf

from bionav.errors import UserError
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
from bionav.validation import bounded, typed_config

__all__ = [
    "EXPERIMENT_CONFIGS", "GROUP_CONFIGS", "ROUTE_METHODS", "ROUTE_PROTOCOLS", "CleaningCameraConfig",
    "CleaningConfig", "CleaningOracleConfig", "ContrastLdaConfig", "ContrastScanConfig", "CrossDbConfig",
    "DataConfig", "GridHomingConfig", "LayoutConfig", "LearnSamplesConfig", "ParamSweepConfig",
    "PolCompassConfig", "PolFilterConfig", "PolPartialConfig", "PolRecordingsConfig", "PolScanConfig",
    "PolSkyConfig", "PolVsEmConfig", "RecordingsConfig", "RouteHomingConfig", "RunSettings",
    "SkyConditionConfig", "SkylineHomingConfig", "LEGACY_KEYS", "check_group_nodes", "check_run_settings",
    "config_from_recorded", "experiment_config", "register",
]

log = logging.getLogger(__name__)

#: keys of configs recorded by earlier bionav versions -> the one setting that replaced each (issue 28)
LEGACY_KEYS: dict[str, str] = {
    # the controllers' own belief of the wheel distance, before the robot's track width was the one setting
    "controller.track_width": "experiment.track_width",
}


#: other option groups with a typed schema: group -> dataclass (checked by :func:`check_group_nodes`)
GROUP_CONFIGS: dict[str, type] = {"layout": LayoutConfig, "data": DataConfig}


def check_group_nodes(cfg: DictConfig) -> None:
    """Check the ``layout`` and ``data`` nodes (when present) against :data:`GROUP_CONFIGS`."""
    for group, schema in GROUP_CONFIGS.items():
        node = cfg.get(group) if isinstance(cfg, DictConfig) else None
        if node is not None:
            typed_config(node, schema, key=group, what=f"{group}={node.get('name', '?')}")


@dataclass
class RunSettings:
    """Top-level keys of every run (``conf/config.yaml``): ``seed=``, ``workers=``, ``device=``."""

    seed: int = bounded(0, ge=0, le=2**32 - 1)
    workers: int = bounded(2, ge=1, le=1024)
    device: str = bounded("cpu", choices=("cpu", "cuda"))


def check_run_settings(cfg: DictConfig) -> RunSettings:
    """The top-level ``seed``, ``workers`` and ``device`` as :class:`RunSettings` (key, value and range named);
    ``device=cuda`` also needs numba-cuda and a GPU (:func:`bionav.gpu.check_device`)."""
    values = {f: cfg.get(f) for f in ("seed", "workers", "device")} if isinstance(cfg, DictConfig) else {}
    settings = typed_config({f: v for f, v in values.items() if v is not None}, RunSettings, key="",
                            what="the run settings")
    if settings.device != "cpu":
        from bionav.gpu import check_device

        check_device(settings.device)
    return settings


def config_from_recorded(cfg: DictConfig, *, source: str, recorded_by: str | None = None) -> DictConfig:
    """A config recorded by an earlier bionav (a log's attached ``config.yaml``) in today's keys.

    Every :data:`LEGACY_KEYS` key the config sets moves to the one setting that
    replaced it (``controller.track_width`` -> ``experiment.track_width``), and
    one info line says so; a config without legacy keys comes back unchanged.

    Parameters
    ----------
    cfg : DictConfig
        The recorded config (resolved, as :mod:`bionav.experiments.runner`
        attaches it); not modified.
    source : str
        Where it was read (the log's path), named in messages.
    recorded_by : str, optional
        The bionav version that recorded it (the log's ``plugins`` metadata),
        named in the error.

    Returns
    -------
    DictConfig
        A copy with the legacy keys replaced.

    Raises
    ------
    UserError
        A legacy key and the setting that replaced it both set, to different
        values: the run used two values that bionav no longer distinguishes.
    """
    moved = []
    for old, new in LEGACY_KEYS.items():
        value = OmegaConf.select(cfg, old, default=None)
        if value is None:
            continue
        if not moved:
            cfg = OmegaConf.create(OmegaConf.to_container(cfg, resolve=True))
        current = OmegaConf.select(cfg, new, default=None)
        if current is not None and current != value:
            by = f" ({recorded_by})" if recorded_by else ""
            raise UserError(
                f"{source} was recorded with {old}={value} and {new}={current}, two values that are one setting "
                f"today ({new}); this bionav cannot reproduce that run. Replay it with the bionav version that "
                f"recorded it{by}."
            )
        parent, _, leaf = old.rpartition(".")
        node = OmegaConf.select(cfg, parent) if parent else cfg
        del node[leaf]
        OmegaConf.update(cfg, new, value, force_add=True)
        moved.append(f"{old}={value} -> {new}")
    if moved:
        log.info("%s: recorded with legacy keys, read as today's: %s", source, "; ".join(moved))
    return cfg


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
    """Store every experiment's dataclass as ``experiment_schema/<name>`` in ``store`` (default Hydra's ConfigStore).

    :func:`bionav.config.register_configs` passes a store that keeps the dataclasses as they are and
    turns one into a structured config only when Hydra composes it (start-up stays fast).
    """
    from hydra.core.config_store import ConfigStore

    store = store or ConfigStore.instance()
    for name, cls in EXPERIMENT_CONFIGS.items():
        store.store(group="experiment_schema", name=name, node=cls, provider="bionav")
    # the top-level recordings.* node of experiment=pol_recordings
    store.store(name="recordings_schema", node=RecordingsConfig, provider="bionav")


def experiment_config(cfg: DictConfig, name: str | None = None) -> DictConfig:
    """The run's ``experiment`` node typed by its dataclass, defaults filled, every value checked.

    Finds the dataclass by the experiment's name and types the node with
    :func:`bionav.validation.typed_config` (the one config path), in the
    context of the whole config so that defaults such as ``${seed}`` and
    ``${experiment.grid}`` resolve; the checked instance is handed back as a
    structured node, so experiments read it as attributes (``exp.step_length``,
    already a ``float``) or as a mapping (``exp.sky.get("time")``).

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
        A structured node of the checked :data:`EXPERIMENT_CONFIGS` ``[name]``
        instance (values of their declared types; ``OmegaConf.to_object`` gives
        the instance); an experiment without a dataclass gets its node back
        unchanged.

    Raises
    ------
    UserError
        An unknown key (the message lists the valid ones and the closest), a
        value of the wrong type, or a value outside its range (key, value and
        allowed range named).
    """
    node = cfg.get("experiment") if isinstance(cfg, DictConfig) else None
    if node is not None and node.get("name") is not None:
        name = str(node.get("name"))
    schema = EXPERIMENT_CONFIGS.get(name or "")
    if schema is None:
        return node
    root = cfg if "seed" in cfg else OmegaConf.merge(OmegaConf.create({"seed": 0}), cfg)
    return OmegaConf.structured(typed_config(None, schema, key="experiment", what=f"experiment={name}", root=root))
