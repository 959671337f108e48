"""Hydra wiring: bionav's config search path and the typed configs of plugins.

* Config folders come from the ``bionav.configs`` entry-point group (bionav's
  own ``bionav/conf/`` is registered there too); a small Hydra ``SearchPathPlugin``
  registered at start-up adds them, so editable installs work (no reliance on
  Hydra's ``hydra_plugins`` namespace scanning).
* Every plugin's ``Config`` dataclass is stored in Hydra's ConfigStore under
  its group (``homing/<name>``, ``signature/<name>``, ...), so
  ``homing=<name> homing.<param>=<value>`` is validated by Hydra with no YAML.
  The stored node adds a ``name`` field holding the registry name.
"""

from __future__ import annotations

import dataclasses
import functools
import warnings
from pathlib import Path
from typing import Any, Sequence

from hydra.core.config_search_path import ConfigSearchPath
from hydra.core.config_store import ConfigStore
from hydra.core.plugins import Plugins
from hydra.plugins.search_path_plugin import SearchPathPlugin
from omegaconf import DictConfig, OmegaConf

from bionav import registry

#: config groups users select plugins in
PLUGIN_GROUPS = ("homing", "signature", "sensor", "pantilt", "controller", "decoder")


def config_dirs() -> list[tuple[str, Path]]:
    """Folders of YAML configs, one per ``bionav.configs`` entry point: ``(name, folder)``.

    A package is located with ``importlib.resources``; bionav's own configs
    are the package ``bionav.conf`` (the folder ``bionav/conf/``).
    """
    import importlib.util
    from importlib.resources import files

    out = []
    for name, package, _dist in registry.config_packages():
        folder = None
        try:
            if importlib.util.find_spec(package) is not None:
                folder = Path(str(files(package)))
        except ModuleNotFoundError:
            folder = None
        if folder is not None and folder.is_dir():
            out.append((name, folder))
    return out


class BionavSearchPathPlugin(SearchPathPlugin):
    """Adds every ``bionav.configs`` folder to Hydra's config search path."""

    def manipulate_search_path(self, search_path: ConfigSearchPath) -> None:
        dirs = config_dirs()
        own = dict(dirs).get("bionav")
        for element in search_path.get_path():
            # ``python -m bionav`` (config_path=None) searches the package itself, where an installed
            # ``bionav/conf`` would show up as a second set of groups named ``conf/...`` in --help and
            # completion: search bionav's own config folder there instead, and only there.
            if element.provider == "main" and own is not None and element.path != f"file://{own}":
                element.path = f"file://{own}"
        present = {element.path for element in search_path.get_path()}
        for name, folder in dirs:
            if f"file://{folder}" not in present:
                search_path.append(provider=f"bionav-{name}", path=f"file://{folder}")


def plugin_node_class(name: str, config_cls: type) -> type:
    """A dataclass extending a plugin's ``Config`` with its registry ``name``."""
    fields = {f.name for f in dataclasses.fields(config_cls)}
    if "name" in fields:
        return config_cls
    return dataclasses.make_dataclass(
        f"{config_cls.__name__}Node",
        [("name", str, dataclasses.field(default=name))],
        bases=(config_cls,),
    )


@dataclasses.dataclass
class BrokenPluginNode:
    """Placeholder for a plugin that failed to load: selecting it gives a clear error later."""

    name: str = ""
    broken: bool = True


@functools.cache
def register_configs() -> dict[str, list[str]]:
    """Register the search-path plugin and all plugin configs (once per process).

    Returns
    -------
    dict
        Config group -> names of the plugins stored in it (broken ones included).
    """
    Plugins.instance().register(BionavSearchPathPlugin)
    store = ConfigStore.instance()
    # typed schemas of config nodes, registered by the rooms that own them (entry points
    # ``bionav.schemas``); e.g. every db preset is merged onto ``db_schema``
    schemas = registry.config_schemas()
    if "db_schema" not in schemas:
        from bionav.errors import UserError

        raise UserError("bionav's entry points are out of date (no 'db_schema' in bionav.schemas); "
                        "re-install it: pip install -e . (or pip install .) in the bionav checkout.")
    for name, schema in schemas.items():
        if isinstance(schema, type):
            store.store(name=name, node=schema, provider="bionav")
        else:  # a registration function: experiment_schema/<name>, hydra/launcher=submitit_slurm, ...
            schema(store)
    names: dict[str, list[str]] = {group: [] for group in PLUGIN_GROUPS}
    for kind in registry.GROUPS:
        with warnings.catch_warnings():
            warnings.simplefilter("default", registry.PluginWarning)
            loaded = registry.plugins_of(kind)
        for name, plugin in loaded.items():
            for group in plugin.config_groups:
                names.setdefault(group, []).append(name)
                if plugin.cls is None:
                    store.store(group=group, name=name, node=BrokenPluginNode(name=name), provider="bionav")
                    continue
                node_cls = plugin_node_class(name, plugin.cls.Config)
                store.store(group=group, name=name, node=node_cls, provider=plugin.entry.distribution)
    return names


def config_options(group: str) -> list[str]:
    """YAML options of a config group across every ``bionav.configs`` package (sorted)."""
    options: set[str] = set()
    for _name, folder in config_dirs():
        if (folder / group).is_dir():
            options |= {p.stem for p in (folder / group).glob("*.yaml")}
    return sorted(options)


def hydra_group_options(group: str) -> list[str]:
    """Options of a config group as Hydra sees them, Hydra's own plugins included (e.g. ``hydra/launcher``)."""
    from hydra import initialize_config_dir
    from hydra.core.global_hydra import GlobalHydra

    register_configs()
    GlobalHydra.instance().clear()
    own = dict(config_dirs())["bionav"]
    with initialize_config_dir(config_dir=str(own), version_base="1.3"):
        return sorted(GlobalHydra.instance().config_loader().get_group_options(group))


def compose(overrides: Sequence[str] = (), *, config_name: str = "config") -> DictConfig:
    """Compose bionav's configuration outside the command line (tests, tools).

    Parameters
    ----------
    overrides : sequence of str
        Hydra overrides such as ``["homing=mfdid", "db.seed=3"]``.
    """
    from hydra import compose as hydra_compose
    from hydra import initialize_config_dir
    from hydra.core.global_hydra import GlobalHydra

    register_configs()
    GlobalHydra.instance().clear()
    own = dict(config_dirs())["bionav"]
    with initialize_config_dir(config_dir=str(own), version_base="1.3"):
        return hydra_compose(config_name=config_name, overrides=list(overrides))


def plugin_config(kind: str, node: Any, *, key: str | None = None) -> Any:
    """Validate a config node against its plugin's ``Config``: ``(plugin class, config instance)``.

    Types come from the dataclass, ranges from its fields' :func:`bionav.validation.bounded`
    declarations (:func:`bionav.validation.check_config`).

    Parameters
    ----------
    kind : str
        Plugin kind (``homing``, ``signature``, ``sensor``, ``controller``).
    node : DictConfig or Mapping
        Config node with a ``name`` key and the plugin's parameters.
    key : str, optional
        The config key users type for this node (``pantilt`` for a sensor
        selected in the ``pantilt`` group); default ``kind``.
    """
    from bionav.errors import UserError
    from bionav.validation import check_config

    key = key or kind

    plain = OmegaConf.to_container(node, resolve=True) if isinstance(node, DictConfig) else dict(node)
    name = plain.pop("name", None)
    plain.pop("broken", None)
    cls = registry.load_plugin(kind, name)
    valid = {f.name for f in dataclasses.fields(cls.Config)}
    unknown = sorted(set(plain) - valid)
    if unknown:
        raise UserError(unknown_key_message(key, unknown[0], sorted(valid), what=f"the {kind} plugin {name!r}"))
    try:
        merged = OmegaConf.merge(OmegaConf.structured(cls.Config), plain)
        config = OmegaConf.to_object(merged)
    except Exception as exc:  # omegaconf validation errors
        where = getattr(exc, "full_key", None)
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise UserError(
            f"bad value for {key}.{where or '<parameter>'} (the {kind} plugin {name!r}): {first}. "
            f"Give {key}.{where or '<parameter>'} a value of the declared type."
        ) from None
    return cls, check_config(config, prefix=key)


def unknown_key_message(node: str, bad: str, valid: Sequence[str], *, what: str | None = None) -> str:
    """One paragraph for a misspelt key: the key, the valid keys of its node, the closest one.

    Parameters
    ----------
    node : str
        Dotted key of the node (``homing``, ``db``, ``experiment.camera``).
    bad : str
        The unknown key (last component).
    valid : sequence of str
        The keys the node has.
    """
    import difflib

    full = f"{node}.{bad}" if node else bad
    close = difflib.get_close_matches(bad, list(valid), n=1, cutoff=0.6)
    hint = f" Did you mean {node + '.' if node else ''}{close[0]}?" if close else ""
    owner = f" ({what})" if what else ""
    keys = ", ".join(valid) or "(none)"
    return f"unknown key {full}: {node or 'the config'}{owner} has no key {bad!r}; its keys are {keys}.{hint}"
