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
from typing import Any, Sequence

from hydra.core.config_search_path import ConfigSearchPath
from hydra.core.config_store import ConfigStore
from hydra.core.plugins import Plugins
from hydra.plugins.config_source import ConfigResult, ConfigSource
from hydra.plugins.search_path_plugin import SearchPathPlugin
from omegaconf import DictConfig, OmegaConf

from bionav import registry
from bionav.registry import config_dirs  # noqa: F401  (its home is the registry; re-exported for the Hydra wiring)
from bionav.validation import unknown_key_message  # noqa: F401  (its home is validation; re-exported for cli.py)

#: config groups users select plugins in
PLUGIN_GROUPS = ("homing", "signature", "sensor", "pantilt", "controller", "decoder", "experiment")
#: internal config groups of the experiment plugins' schemas: ``experiment_schema/<name>`` (the ``experiment``
#: node: the plugin's ``Config``) and ``experiment_nodes/<name>/<node>`` (another node it reads, e.g.
#: ``recordings``: its ``group_configs``), both served from the plugin when a preset composes them
EXPERIMENT_SCHEMA_GROUP = "experiment_schema"
EXPERIMENT_NODES_GROUP = "experiment_nodes"


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
        if f"{PluginConfigSource.scheme()}://" not in present:
            search_path.append(provider="bionav-plugins", path=f"{PluginConfigSource.scheme()}://")


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


class PluginConfigSource(ConfigSource):
    """Hydra config source of the plugins' typed configs, loaded only when selected.

    Hydra asks this source which groups and options exist (answered from the entry points,
    :func:`bionav.registry.names_by_group`, without importing plugin modules) and, when a
    plugin is selected (``homing=sift`` or a default), for its node: only then is the plugin's
    module imported and its ``Config`` dataclass turned into a structured config with a
    ``name`` field (:func:`plugin_node_class`). A plugin that fails to load, or whose name two
    distributions claim, gives :class:`BrokenPluginNode`, so that selecting it raises its
    message from :func:`plugin_config`, and listing is never broken by it.

    It also serves the typed schemas of ``bionav.schemas`` (``db_schema``, the SLURM launcher;
    :func:`register_configs`) and those of the experiment plugins (``experiment_schema/<name>``,
    ``experiment_nodes/<name>/<node>``: the ``Config`` of ``bionav.experiments`` entry point
    ``<name>`` and its ``group_configs``): each dataclass becomes a structured config only when
    Hydra loads it, so a command pays for the one experiment it composes, not for all of them,
    also in a launcher's worker process (entry points are read on first use).
    """

    def __init__(self, provider: str, path: str) -> None:
        super().__init__(provider=provider, path=path)

    @staticmethod
    def scheme() -> str:
        return "bionav-plugins"

    def available(self) -> bool:
        return True

    @staticmethod
    def _split(config_path: str) -> tuple[str, str]:
        path = config_path.strip("/")
        if path.endswith(".yaml"):
            path = path[: -len(".yaml")]
        group, _, name = path.rpartition("/")
        return group, name

    def is_group(self, config_path: str) -> bool:
        path = config_path.strip("/")
        return (path == "" or registry.kind_of_group(path) is not None or path in _schema_groups()
                or _experiment_group(path))

    def is_config(self, config_path: str) -> bool:
        group, name = self._split(config_path)
        if f"{group}/{name}".strip("/") in _schemas():
            return True
        if _experiment_group(group):
            return _experiment_schema(group, name) is not None
        kind = registry.kind_of_group(group)
        # a name no entry point declares is answered without importing any plugin (Hydra asks for `sensor/None`)
        return kind is not None and name in registry.entry_points_of(kind) and name in registry.names_in_group(group)

    def list(self, config_path: str, results_filter: Any) -> list[str]:
        from hydra.core.object_type import ObjectType

        path = config_path.strip("/")
        prefix = f"{path}/" if path else ""
        schemas = [key[len(prefix):] for key in _schemas() if key.startswith(prefix) and "/" not in key[len(prefix):]]
        groups = [g for g in _schema_groups() if g.startswith(prefix) and "/" not in g[len(prefix):]]
        groups = [g[len(prefix):] for g in groups] + (list(PLUGIN_GROUPS) if path == "" else [])
        if path == EXPERIMENT_SCHEMA_GROUP:
            schemas = sorted(registry.entry_points_of("experiment"))
        configs = schemas + (sorted(registry.names_in_group(path)) if registry.kind_of_group(path) else [])
        return sorted(set((groups if results_filter in (None, ObjectType.GROUP) else [])
                          + (configs if results_filter in (None, ObjectType.CONFIG) else [])))

    def load_config(self, config_path: str) -> ConfigResult:
        group, name = self._split(config_path)
        schema = _schemas().get(f"{group}/{name}".strip("/"))
        if schema is None and _experiment_group(group):
            schema = _experiment_schema(group, name)
        if schema is not None:  # a typed schema of bionav.schemas or of an experiment, converted now
            return ConfigResult(config=OmegaConf.structured(schema[0]), path=f"{self.scheme()}://{self.path}",
                                provider=schema[1], header={"package": None})
        kind = registry.kind_of_group(group)
        provider = self.provider
        try:
            cls = registry.load_plugin(kind, name)
        except registry.PluginError:  # broken or conflicting: selecting it raises its message later
            node = OmegaConf.structured(BrokenPluginNode(name=name))
        else:
            entry = registry.entry_points_of(kind).get(name)
            provider = entry.distribution if entry is not None else provider
            node = OmegaConf.structured(plugin_node_class(name, cls.Config))
        return ConfigResult(config=node, path=f"{self.scheme()}://{self.path}", provider=provider,
                            header={"package": None})


def _experiment_group(path: str) -> bool:
    """``experiment_schema``, ``experiment_nodes`` or ``experiment_nodes/<an installed experiment>``."""
    if path in (EXPERIMENT_SCHEMA_GROUP, EXPERIMENT_NODES_GROUP):
        return True
    parent, _, name = path.partition("/")
    return parent == EXPERIMENT_NODES_GROUP and "/" not in name and name in registry.entry_points_of("experiment")


def _experiment_schema(group: str, name: str) -> tuple[Any, str] | None:
    """``(dataclass, provider)`` of ``experiment_schema/<name>`` or ``experiment_nodes/<experiment>/<name>``.

    The experiment's plugin is imported here, and only here (a name no entry point declares is
    answered from the entry points); a plugin that fails to load raises its
    :class:`~bionav.errors.PluginError` (a preset that names it cannot compose without it).
    """
    experiment = name if group == EXPERIMENT_SCHEMA_GROUP else group.partition("/")[2]
    entry = registry.entry_points_of("experiment").get(experiment)
    if entry is None or group == EXPERIMENT_NODES_GROUP:
        return None
    cls = registry.load_plugin("experiment", experiment)
    if group == EXPERIMENT_SCHEMA_GROUP:  # with its registry name, as a preset sets experiment.name
        return plugin_node_class(name, cls.Config), entry.distribution
    schema = dict(cls.group_configs).get(name)
    return None if schema is None else (schema, entry.distribution)


@functools.cache
def register_configs() -> None:
    """Register the search-path plugin, the plugin config source and the schemas (once per process).

    Plugins are not imported here (:class:`PluginConfigSource` loads the one selected; the
    names selectable per group are :func:`bionav.registry.names_by_group`).
    """
    Plugins.instance().register(BionavSearchPathPlugin)
    Plugins.instance().register(PluginConfigSource)
    _schemas()


@functools.cache
def _schemas() -> dict[str, tuple[Any, str]]:
    """The typed schemas of ``bionav.schemas``: config path -> (dataclass or instance, provider).

    Keys are ``db_schema`` and what registration functions store without a package; :class:`PluginConfigSource`
    serves them. Read once per process, also in a launcher's worker process (joblib, submitit,
    SLURM), where Hydra restores its plugins but no bionav code has run yet.
    """
    store = _SchemaStore()
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
        else:  # a registration function: hydra/launcher=submitit_slurm, ...
            schema(store)
    return store.nodes


@functools.cache
def _schema_groups() -> frozenset[str]:
    """Config groups holding schemas of ``bionav.schemas``, parents included (once per process, as :func:`_schemas`)."""
    out: set[str] = set()
    for key in _schemas():
        parts = key.split("/")[:-1]
        out |= {"/".join(parts[: i + 1]) for i in range(len(parts))}
    return frozenset(out)


class _SchemaStore:
    """What ``bionav.schemas`` registration functions store into (the ``store`` argument).

    It has :meth:`hydra.core.config_store.ConfigStore.store`'s signature but keeps the
    dataclass as it is; :class:`PluginConfigSource` turns it into a structured config when
    Hydra loads it. A node with a ``package`` goes to Hydra's ConfigStore unchanged.
    """

    def __init__(self) -> None:
        self.nodes: dict[str, tuple[Any, str]] = {}

    def store(self, name: str, node: Any, group: str | None = None, package: str | None = None,
              provider: str | None = None) -> None:
        if package is not None:
            ConfigStore.instance().store(name=name, node=node, group=group, package=package, provider=provider)
            return
        name = name[: -len(".yaml")] if name.endswith(".yaml") else name
        self.nodes[f"{group}/{name}" if group else name] = (node, provider or "bionav")


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


def compose(overrides: Sequence[str] = (), *, config_name: str = "config",
            return_hydra_config: bool = False) -> DictConfig:
    """Compose bionav's configuration outside the command line (tests, tools).

    Parameters
    ----------
    overrides : sequence of str
        Hydra overrides such as ``["homing=mfdid", "db.seed=3"]``.
    return_hydra_config : bool
        Keep the ``hydra`` node (help texts, run directories).
    """
    from hydra import compose as hydra_compose
    from hydra import initialize_config_dir
    from hydra.core.global_hydra import GlobalHydra

    register_configs()
    GlobalHydra.instance().clear()
    own = dict(config_dirs())["bionav"]
    with initialize_config_dir(config_dir=str(own), version_base="1.3"):
        return hydra_compose(config_name=config_name, overrides=list(overrides),
                             return_hydra_config=return_hydra_config)


def plugin_config(kind: str, node: Any, *, key: str | None = None) -> Any:
    """A plugin's class and its typed, checked config: ``(plugin class, config instance)``.

    The node's ``name`` selects the plugin; the rest becomes an instance of the
    plugin's ``Config`` through :func:`bionav.validation.typed_config` (types from
    the dataclass, ranges from its :func:`bionav.validation.bounded` fields).

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
    from bionav.validation import typed_config

    key = key or kind
    plain = OmegaConf.to_container(node, resolve=True) if isinstance(node, DictConfig) else dict(node)
    name = plain.pop("name", None)
    plain.pop("broken", None)
    cls = registry.load_plugin(kind, name)
    return cls, typed_config(plain, cls.Config, key=key, what=f"the {kind} plugin {name!r}")
