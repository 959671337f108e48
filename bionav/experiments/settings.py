"""Run settings and the typed ``experiment`` node: what every run's config holds besides its plugins.

* :class:`RunSettings`: the top-level ``seed`` and ``workers`` (:func:`check_run_settings`).
* :func:`experiment_config`: the run's ``experiment`` node typed by the selected experiment's
  ``Config`` (found in the registry, ``bionav.experiments``), defaults filled, every value checked;
  :func:`check_group_nodes`: the other top-level nodes the experiment reads (``layout``,
  ``data``, ``recordings``: :attr:`Experiment.group_configs <bionav.experiments.base.Experiment>`).
* :data:`LEGACY_KEYS` and :func:`config_from_recorded`: configs recorded by earlier versions
  read in today's keys.

Each experiment's dataclass lives in its own folder (``bionav/experiments/<name>/config.py``);
the command line composes it as ``experiment_schema/<name>`` (:mod:`bionav.config` serves it
from the plugin when a command composes it), so Hydra rejects unknown keys and values of the
wrong type at composition, and :func:`experiment_config` checks every value against its range
(:func:`bionav.validation.check_config`), naming the key (``experiment.<key>``).

Units: metres and grid units as named; angles in degrees only in keys ending ``_deg``; times ISO 8601
with zone.
"""

from __future__ import annotations

import dataclasses
import logging
from dataclasses import dataclass
from typing import Any

from omegaconf import DictConfig, OmegaConf, open_dict

from bionav.errors import UserError
from bionav.validation import bounded, typed_config

log = logging.getLogger(__name__)

#: keys of configs recorded by earlier bionav versions -> the one setting that replaced each (issue 28)
LEGACY_KEYS: dict[str, str] = {
    # the controllers' own belief of the wheel distance, before the robot's track width was the one setting
    "controller.track_width": "experiment.track_width",
}


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


def experiment_class(name: str) -> type:
    """The experiment plugin registered as ``name`` (``bionav.experiments``); a PluginError names the choices."""
    from bionav import registry

    return registry.load_plugin("experiment", name)


def experiment_config(cfg: DictConfig) -> Any:
    """The run's ``experiment`` node as an instance of its experiment's ``Config``, every value checked.

    Finds the experiment by ``experiment.name`` in the registry and types the node with
    :func:`bionav.validation.typed_config` (the one config path), in the context of the whole
    config so that defaults such as ``${seed}`` and ``${experiment.grid}`` resolve.

    Parameters
    ----------
    cfg : DictConfig
        The whole run config (``experiment.name`` selects the experiment; interpolations such as
        ``${seed}`` resolve against it, ``seed`` defaulting to 0).

    Returns
    -------
    The checked ``Config`` instance (values of their declared types), or None when the config has
    no ``experiment`` node.

    Raises
    ------
    UserError
        An unknown experiment (the message lists the installed ones), an unknown key (the message
        lists the valid ones and the closest), a value of the wrong type, or a value outside its
        range (key, value and allowed range named).
    """
    node = cfg.get("experiment") if isinstance(cfg, DictConfig) else None
    if node is None:
        return None
    name = str(node.get("name") or "")
    schema = experiment_class(name).Config
    root = cfg if "seed" in cfg else OmegaConf.merge(OmegaConf.create({"seed": 0}), cfg)
    if "name" not in {f.name for f in dataclasses.fields(schema)} and "name" in node:
        root = root.copy()  # the registry name selects the plugin; a Config without a name field does not hold it
        with open_dict(root.experiment):
            del root.experiment["name"]
    return typed_config(None, schema, key="experiment", what=f"experiment={name}", root=root)


def check_group_nodes(cfg: DictConfig, experiment: type) -> dict[str, Any]:
    """The top-level nodes ``experiment`` reads besides its own (``layout``, ``data``, ``recordings``), checked.

    Each node of :attr:`Experiment.group_configs <bionav.experiments.base.Experiment>` present in
    ``cfg`` is typed by its dataclass (:func:`bionav.validation.typed_config`); returns node key ->
    instance.
    """
    out = {}
    for group, schema in dict(getattr(experiment, "group_configs", None) or {}).items():
        node = cfg.get(group) if isinstance(cfg, DictConfig) else None
        if node is None:
            continue
        what = (f"{group}={node.get('name', '?')}" if "name" in node
                else f"experiment={OmegaConf.select(cfg, 'experiment.name', default='?')}")
        out[group] = typed_config(node, schema, key=group, what=what)
    return out
