"""Plugin registry: entry points read once, loaded lazily, failures reported.

Modelled on xarray's backend registry. Each *kind* of plugin has an
entry-point group (``bionav.homing``, ``bionav.signatures``,
``bionav.sensors``, ``bionav.controllers``, ``bionav.decoders``,
``bionav.route_agents``, ``bionav.experiments``); bionav's own built-ins are
registered through the same entry points as third-party plugins.

* Entry points are read once per process and cached (:func:`entry_points_of`).
* A plugin's module is imported only when the plugin is asked for
  (:func:`load_plugin`) or when all of a kind are listed (:func:`plugins_of`).
* A plugin that fails to import is a warning when listing and an error naming
  its distribution only when it is selected.
* Two distributions claiming one name in one group make that name (only) an error naming both.
* Lookup accepts a registry name or the plugin class itself.
"""

from __future__ import annotations

import dataclasses
import functools
import importlib.metadata as importlib_metadata
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from bionav.errors import PluginError

#: entry-point group of each plugin kind
GROUPS: dict[str, str] = {
    "homing": "bionav.homing",
    "signature": "bionav.signatures",
    "sensor": "bionav.sensors",
    "controller": "bionav.controllers",
    "decoder": "bionav.decoders",
    "route_agent": "bionav.route_agents",
    "experiment": "bionav.experiments",
}
#: entry-point group of config packages (folders of YAML files)
CONFIG_GROUP = "bionav.configs"
#: entry-point group of structured config schemas (``name = "module:Dataclass"`` or a registration function) served to Hydra
SCHEMA_GROUP = "bionav.schemas"


class PluginWarning(UserWarning):
    """A plugin could not be loaded; it is skipped unless selected."""


@dataclass(frozen=True)
class PluginEntry:
    """One registered plugin.

    Attributes
    ----------
    kind : str
        Plugin kind (``homing``, ``signature``, ``sensor``, ``controller``, ``experiment``, ...).
    name : str
        Registry name (what the user types, e.g. ``homing=sift``).
    value : str
        Entry-point target ``module:attribute``.
    distribution : str
        Name of the installed distribution that declares the entry point.
    version : str
        That distribution's version.
    """

    kind: str
    name: str
    value: str
    distribution: str
    version: str

    def describe(self) -> str:
        return f"{self.name!r} ({self.value}, from {self.distribution} {self.version})"


@dataclass(frozen=True)
class LoadedPlugin:
    """An entry together with the loaded class, or the error that prevented loading."""

    entry: PluginEntry
    cls: type | None
    error: str | None

    @property
    def config_groups(self) -> tuple[str, ...]:
        """The Hydra config groups the plugin is selected in.

        ``sensor`` plugins may say ``pantilt``; a plugin serving several groups
        (``replay``) sets ``config_group`` to a tuple of them.
        """
        if self.cls is None:
            return (self.entry.kind,)
        group = getattr(self.cls, "config_group", self.entry.kind)
        return tuple(group) if isinstance(group, (tuple, list)) else (str(group),)

    @property
    def config_group(self) -> str:
        """The first (main) config group of :attr:`config_groups`."""
        return self.config_groups[0]


def _check_kind(kind: str) -> str:
    if kind not in GROUPS:
        raise PluginError(f"unknown plugin kind {kind!r}; the kinds are {', '.join(sorted(GROUPS))}.")
    return GROUPS[kind]


def _distribution_of(ep: importlib_metadata.EntryPoint) -> tuple[str, str]:
    dist = getattr(ep, "dist", None)
    if dist is None:
        return "unknown", "?"
    return dist.metadata["Name"] or dist.name, dist.version


@functools.cache
def _all_entry_points() -> dict[str, tuple[importlib_metadata.EntryPoint, ...]]:
    eps = importlib_metadata.entry_points()
    return {group: tuple(eps.select(group=group)) for group in (*GROUPS.values(), CONFIG_GROUP, SCHEMA_GROUP)}


def clear_cache() -> None:
    """Forget cached entry points and loaded plugins (after installing a plugin at run time)."""
    _all_entry_points.cache_clear()
    _scan.cache_clear()
    entry_points_of.cache_clear()
    _load_entry.cache_clear()
    _names_by_group.cache_clear()


@functools.cache
def _scan(kind: str) -> tuple[dict[str, PluginEntry], dict[str, str]]:
    group = _check_kind(kind)
    found: dict[str, PluginEntry] = {}
    claims: dict[str, list[PluginEntry]] = {}
    for ep in _all_entry_points()[group]:
        dist, version = _distribution_of(ep)
        entry = PluginEntry(kind, ep.name, ep.value, dist, version)
        same = [c for c in claims.get(ep.name, []) if (c.distribution, c.value) == (dist, ep.value)]
        if not same:  # one distribution seen twice on sys.path is one claim
            claims.setdefault(ep.name, []).append(entry)
        found.setdefault(ep.name, entry)
    conflicts = {}
    for name, entries in claims.items():
        if len(entries) > 1:
            listed = " and ".join(e.describe() for e in entries)
            conflicts[name] = (
                f"{len(entries)} installed distributions register the {kind} plugin {name!r}: {listed}. "
                f"Uninstall one of them (e.g. pip uninstall {entries[-1].distribution}) or rename its entry "
                f"point in group {group!r}; the other {kind} plugins are not affected."
            )
    return found, conflicts


@functools.cache
def entry_points_of(kind: str) -> dict[str, PluginEntry]:
    """Registered plugins of one kind, keyed by name, without importing them.

    A name that two distributions claim is listed (with the first claim) but
    cannot be loaded: :func:`load_plugin` raises the message of
    :func:`conflicts_of`; every other name stays usable.
    """
    return dict(_scan(kind)[0])


def conflicts_of(kind: str) -> dict[str, str]:
    """Names of one kind claimed by several distributions -> a message naming them and the fix."""
    return dict(_scan(kind)[1])


@functools.cache
def _load_entry(entry: PluginEntry) -> LoadedPlugin:
    ep = importlib_metadata.EntryPoint(entry.name, entry.value, GROUPS[entry.kind])
    try:
        cls = ep.load()
    except Exception as exc:  # a broken plugin must not break other commands
        return LoadedPlugin(entry, None, f"{type(exc).__name__}: {exc}")
    problem = _check_plugin_class(entry.kind, cls)
    if problem:
        return LoadedPlugin(entry, None, problem)
    return LoadedPlugin(entry, cls, None)


def _check_plugin_class(kind: str, cls: Any) -> str | None:
    if not isinstance(cls, type):
        return f"entry point target is a {type(cls).__name__}, not a class"
    config = getattr(cls, "Config", None)
    if config is None or not dataclasses.is_dataclass(config):
        return "plugin class has no `Config` dataclass (its typed parameters)"
    if kind == "experiment" and not callable(getattr(cls, "run", None)):
        return "experiment class has no `run(self, ctx)` method"
    return None


def plugins_of(kind: str, *, warn: bool = True) -> dict[str, LoadedPlugin]:
    """Load every plugin of a kind; broken ones are kept with their error.

    Parameters
    ----------
    kind : str
        Plugin kind.
    warn : bool
        Emit a :class:`PluginWarning` for each plugin that failed to load.
    """
    conflicts = conflicts_of(kind)
    loaded = {name: (LoadedPlugin(entry, None, conflicts[name]) if name in conflicts else _load_entry(entry))
              for name, entry in entry_points_of(kind).items()}
    if warn:
        for plugin in loaded.values():
            if plugin.error:
                warnings.warn(
                    f"bionav: the {kind} plugin {plugin.entry.describe()} failed to load and is "
                    f"skipped: {plugin.error}",
                    PluginWarning,
                    stacklevel=2,
                )
    return loaded


def load_plugin(kind: str, name_or_class: str | type) -> type:
    """The plugin class registered under ``name`` (or the class itself, passed through).

    Raises
    ------
    PluginError
        Unknown name (the message lists the available ones) or a plugin that
        failed to load (the message names its distribution and the error).
    """
    _check_kind(kind)
    if isinstance(name_or_class, type):
        problem = _check_plugin_class(kind, name_or_class)
        if problem:
            raise PluginError(f"{name_or_class.__qualname__} cannot be used as a {kind} plugin: {problem}.")
        return name_or_class
    name = str(name_or_class)
    entries = entry_points_of(kind)
    if name not in entries:
        available = ", ".join(sorted(entries)) or "(none installed)"
        raise PluginError(
            f"there is no {kind} plugin named {name!r}. Available: {available}. "
            f"Install the package that provides it, or pick one of these."
        )
    conflict = conflicts_of(kind).get(name)
    if conflict:
        raise PluginError(conflict)
    plugin = _load_entry(entries[name])
    if plugin.cls is None:
        raise PluginError(
            f"the {kind} plugin {plugin.entry.describe()} failed to load: {plugin.error}. "
            f"Fix or reinstall {plugin.entry.distribution} (pip install --force-reinstall "
            f"{plugin.entry.distribution}), or choose another {kind}."
        )
    return plugin.cls


#: plugin kinds whose classes may choose their config group (``config_group``); every other kind's
#: plugins are selected in the group named like the kind, so they are listed without importing them
KINDS_WITH_OWN_GROUPS = frozenset({"sensor"})
#: plugin kinds selected inside an experiment's config, not in a config group -> how a user selects one
KINDS_WITHOUT_GROUP: dict[str, str] = {"route_agent": "experiment.agents=[{name}]"}


def names_in_group(group: str) -> list[str]:
    """Names of the plugins selectable in config group ``group`` (empty: not a plugin group).

    Only a group of a kind in :data:`KINDS_WITH_OWN_GROUPS` (``sensor``, ``pantilt``) imports
    plugin modules; ``homing``, ``signature``, ... are answered from the entry points alone.
    """
    kind = kind_of_group(group)
    if kind is None:
        return []
    if kind not in KINDS_WITH_OWN_GROUPS:
        return sorted(entry_points_of(kind))
    return list(_names_by_group().get(group, ()))


def names_by_group() -> dict[str, list[str]]:
    """Config group -> names of the plugins selected in it, without importing plugins where possible.

    Plugins of kinds other than :data:`KINDS_WITH_OWN_GROUPS` are listed from their entry points
    alone (their group is their kind); sensor plugins are imported, since each class says whether it
    is a ``sensor``, a ``pantilt`` or both. Broken and conflicting plugins are listed too (selecting
    one raises its message). The result is computed once per process.
    """
    return {group: list(names) for group, names in _names_by_group().items()}


@functools.cache
def _names_by_group() -> dict[str, tuple[str, ...]]:
    out: dict[str, list[str]] = {}
    for kind in GROUPS:
        if kind in KINDS_WITHOUT_GROUP:
            continue
        if kind in KINDS_WITH_OWN_GROUPS:
            for name, plugin in plugins_of(kind, warn=False).items():
                for group in plugin.config_groups:
                    out.setdefault(group, []).append(name)
        else:
            out.setdefault(kind, []).extend(entry_points_of(kind))
    return {group: tuple(sorted(set(names))) for group, names in out.items()}


def kind_of_group(group: str) -> str | None:
    """The plugin kind whose plugins are selected in config group ``group`` (None: not a plugin group)."""
    if group in GROUPS:
        return None if group in KINDS_WITHOUT_GROUP else group
    if group == "pantilt":
        return "sensor"
    return None


def config_packages() -> list[tuple[str, str, str]]:
    """Config packages declared in ``bionav.configs``: ``(name, package, distribution)``.

    bionav's own ``conf`` folder comes first, so third-party YAML can add
    options but not silently replace built-in ones.
    """
    out = []
    for ep in _all_entry_points()[CONFIG_GROUP]:
        dist, _ = _distribution_of(ep)
        out.append((ep.name, ep.value, dist))
    out.sort(key=lambda item: (item[0] != "bionav", item[0]))
    return out


def config_dirs() -> list[tuple[str, Path]]:
    """Folders of YAML configs, one per ``bionav.configs`` entry point: ``(name, folder)``.

    A package is located with ``importlib.resources``; bionav's own configs
    are the package ``bionav.conf`` (the folder ``bionav/conf/``).
    """
    import importlib.util
    from importlib.resources import files

    out = []
    for name, package, _dist in config_packages():
        folder = None
        try:
            if importlib.util.find_spec(package) is not None:
                folder = Path(str(files(package)))
        except ModuleNotFoundError:
            folder = None
        if folder is not None and folder.is_dir():
            out.append((name, folder))
    return out


def config_schemas() -> dict[str, Any]:
    """Structured config schemas declared in ``bionav.schemas``: name -> dataclass or registration function.

    A room that owns a config node registers its schema here (bionav's
    ``db_schema`` is :class:`bionav.db.config.DatabaseConfig`), so the Hydra wiring stores them
    without importing that room (the experiments' schemas come from their plugins,
    ``bionav.experiments``). An entry whose
    optional dependency is not installed (e.g. the SLURM launcher without the
    ``slurm`` extra) is skipped.
    """
    out: dict[str, Any] = {}
    for ep in _all_entry_points()[SCHEMA_GROUP]:
        if ep.name in out:
            dist, _ = _distribution_of(ep)
            raise PluginError(f"the config schema {ep.name!r} is declared twice (again by {dist}); uninstall one.")
        try:
            out[ep.name] = ep.load()
        except ModuleNotFoundError as exc:
            if exc.name and exc.name.split(".")[0] != "bionav":
                continue  # it needs an optional dependency (an extra) that is not installed
            dist, _ = _distribution_of(ep)
            raise PluginError(f"the config schema {ep.name!r} of {dist} cannot be loaded ({exc}); "
                              f"reinstall {dist}.") from None
        except Exception as exc:  # a broken third-party schema
            dist, _ = _distribution_of(ep)
            raise PluginError(f"the config schema {ep.name!r} of {dist} cannot be loaded ({exc}); "
                              f"reinstall {dist}.") from None
    return out
