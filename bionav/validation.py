"""Typed ranges for config dataclasses: declared once per field, checked where values enter.

A config dataclass (a plugin's ``Config``, :class:`~bionav.db.config.DatabaseConfig`,
an experiment's config) declares the allowed values of a field with
:func:`bounded`::

    @dataclass
    class Config:
        sigma: float = bounded(1.6, gt=0.0, le=10.0)
        n_features: int = bounded(0, ge=0, le=100_000)
        combine: str = bounded("average", choices=("average", "max"))
        image_size: Optional[list[int]] = bounded(None, length=2, item=Range(ge=8, le=8192))

:func:`check_config` checks an instance: every numeric field must be finite
(NaN is never a valid value; infinity only where the range allows it), inside
its declared range, strings among their choices, lists of the declared
length with items in range; nested dataclasses are checked recursively. The
error is a :class:`~bionav.errors.UserError` naming the key as the user types
it (``homing.sigma``), the bad value and the allowed range.

:func:`typed_config` is the one path from a config node (an OmegaConf node, a
mapping or an instance) to its typed dataclass: it merges the node onto the
dataclass (unknown keys and values of the wrong type named), checks every
declared range (:func:`check_config`), refuses keys the node's dataclass says
it does not use (its ``unused_keys`` hook, e.g. ``db.grid_shape`` on a
synthetic database) and checks relations between fields (its ``validate``
hook, e.g. ``min < max``). Every error is one :class:`~bionav.errors.UserError`
naming the key as the user types it, the bad value and what is allowed.
Plugin configs (:func:`bionav.config.plugin_config`), the ``db`` node
(:func:`bionav.db.loading.as_database_config`), the experiment node
(:func:`bionav.experiments.settings.experiment_config`) and the other typed
groups all go through it; the command line runs all of them before a run
directory is created, and nothing downstream re-checks or re-casts a value.
A class that also accepts instances from Python code (``HomingMethod(config,
...)``) checks them with :func:`checked_config`, which skips an instance
:func:`typed_config` has already checked (unless its values changed since), so
each value is checked once on either door.

:func:`check_allocation` bounds an array allocation against the memory of
the machine before it is made.
"""

from __future__ import annotations

import dataclasses
import math
import os
from dataclasses import MISSING, dataclass
from typing import Any, Sequence

from bionav.errors import UserError

METADATA_KEY = "range"


@dataclass(frozen=True)
class Range:
    """Allowed values of one config field.

    Attributes
    ----------
    ge, gt, le, lt : float, optional
        Inclusive / exclusive lower and upper bounds of a number.
    choices : tuple of str, optional
        Allowed strings (compared exactly).
    length : int or (int, int), optional
        Exact length, or ``(min, max)`` length, of a list value.
    item : Range, optional
        Range of each item of a list value.
    items : tuple of Range, optional
        Range of the item at each position of a list of fixed ``length``
        (e.g. an image size ``[W, H]`` with its own bounds for W and H).
    names : tuple of str, optional
        Names of the positions in messages (``("W", "H")``).
    allow_inf : bool
        Whether ``inf``/``-inf`` pass (NaN never does).
    """

    ge: float | None = None
    gt: float | None = None
    le: float | None = None
    lt: float | None = None
    choices: tuple | None = None
    length: int | tuple[int, int] | None = None
    item: "Range | None" = None
    items: "tuple[Range, ...] | None" = None
    names: tuple[str, ...] | None = None
    allow_inf: bool = False

    def describe(self, *, integer: bool = False) -> str:
        """The allowed values in words, e.g. ``a finite number > 0 and <= 10`` (``an integer ...``)."""
        if self.choices is not None:
            return "one of " + ", ".join(str(c) for c in self.choices)
        parts = []
        if self.length is not None:
            if isinstance(self.length, tuple):
                parts.append(f"a list of {self.length[0]} to {self.length[1]} items")
            else:
                parts.append(f"a list of {self.length} items")
            if self.item is not None:
                parts.append("each " + self.item.describe(integer=integer))
            if self.items is not None:
                names = self.names or tuple(f"item {i + 1}" for i in range(len(self.items)))
                parts += [f"{n} {r.describe(integer=integer)}" for n, r in zip(names, self.items)]
            return ", ".join(parts)
        bounds = []
        if self.ge is not None:
            bounds.append(f">= {_fmt(self.ge)}")
        if self.gt is not None:
            bounds.append(f"> {_fmt(self.gt)}")
        if self.le is not None:
            bounds.append(f"<= {_fmt(self.le)}")
        if self.lt is not None:
            bounds.append(f"< {_fmt(self.lt)}")
        text = "an integer" if integer else ("a finite number" if not self.allow_inf else "a number (not NaN)")
        return text + (" " + " and ".join(bounds) if bounds else "")

    def problem(self, value: Any) -> str | None:
        """Why ``value`` is not allowed, or None when it is."""
        if self.choices is not None:
            return None if value in self.choices else "is not an allowed choice"
        if self.length is not None and isinstance(value, (list, tuple)):
            lo, hi = self.length if isinstance(self.length, tuple) else (self.length, self.length)
            if not lo <= len(value) <= hi:
                return f"has {len(value)} item(s)"
            if self.item is not None:
                for v in value:
                    why = self.item.problem(v)
                    if why:
                        return f"has an item {v!r} that {why}"
            if self.items is not None:
                names = self.names or tuple(f"item {i + 1}" for i in range(len(self.items)))
                for n, r, v in zip(names, self.items, value):
                    why = r.problem(v)
                    if why:
                        return f"has {n}={v!r} that {why}"
            return None
        if self.length is not None:
            return "is not a list"
        return _number_problem(value, self)


def _fmt(x: float) -> str:
    return f"{x:g}" if isinstance(x, float) else str(x)


def _number_problem(value: Any, rng: Range | None) -> str | None:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    x = float(value)
    if math.isnan(x):
        return "is not a number (NaN)"
    if math.isinf(x) and not (rng is not None and rng.allow_inf):
        return "is infinite"
    if rng is None:
        return None
    if rng.ge is not None and not x >= rng.ge:
        return "is too small"
    if rng.gt is not None and not x > rng.gt:
        return "is too small"
    if rng.le is not None and not x <= rng.le:
        return "is too large"
    if rng.lt is not None and not x < rng.lt:
        return "is too large"
    return None


def bounded(
    default: Any = MISSING,
    *,
    default_factory: Any = MISSING,
    ge: float | None = None,
    gt: float | None = None,
    le: float | None = None,
    lt: float | None = None,
    choices: Sequence[str] | None = None,
    length: int | tuple[int, int] | None = None,
    item: Range | None = None,
    items: Sequence[Range] | None = None,
    names: Sequence[str] | None = None,
    allow_inf: bool = False,
) -> Any:
    """A dataclass field with a declared range (see the module docstring).

    List defaults are copied per instance (pass a list as ``default``; it is
    turned into a ``default_factory``).
    """
    rng = Range(ge=ge, gt=gt, le=le, lt=lt, choices=tuple(choices) if choices is not None else None,
                length=length, item=item, items=tuple(items) if items is not None else None,
                names=tuple(names) if names is not None else None, allow_inf=allow_inf)
    if isinstance(default, (list, dict)):
        value = default
        default, default_factory = MISSING, (lambda: type(value)(value))
    return dataclasses.field(default=default, default_factory=default_factory, metadata={METADATA_KEY: rng})


def range_of(field: dataclasses.Field) -> Range | None:
    """The :class:`Range` declared for a dataclass field (None when undeclared)."""
    return field.metadata.get(METADATA_KEY) if field.metadata else None


def _default_text(field: dataclasses.Field) -> str:
    if field.default is not MISSING:
        return repr(field.default) if not isinstance(field.default, str) else field.default
    if field.default_factory is not MISSING:
        try:
            return repr(field.default_factory())
        except Exception:  # pragma: no cover - a factory needing arguments
            return "?"
    return "?"


def _show(value: Any) -> str:
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    if isinstance(value, (list, tuple)):
        return "[" + ",".join(_show(v) for v in value) + "]"
    return str(value)


def check_config(config: Any, *, prefix: str) -> Any:
    """Check every field of a config dataclass instance against its declared range.

    Parameters
    ----------
    config : dataclass instance
        The config (nested dataclasses are checked too, with ``prefix.<field>``).
    prefix : str
        The key of the config as the user types it (``homing``, ``db``, ``experiment``).

    Returns
    -------
    The same ``config`` (for chaining).

    Raises
    ------
    UserError
        Naming ``prefix.<field>``, the bad value, the allowed values and the default.
    """
    if not dataclasses.is_dataclass(config) or isinstance(config, type):
        return config
    for field in dataclasses.fields(config):
        value = getattr(config, field.name, None)
        key = f"{prefix}.{field.name}" if prefix else field.name
        if dataclasses.is_dataclass(value) and not isinstance(value, type):
            check_config(value, prefix=key)
            continue
        if value is None or (isinstance(value, str) and "${" in value):
            continue  # unset, or an interpolation not resolved yet (checked once resolved)
        rng = range_of(field)
        why = rng.problem(value) if rng is not None else None
        if why is None and rng is None:
            why = _number_problem(value, None)
            if why is None and isinstance(value, (list, tuple)):
                bad = [v for v in value if _number_problem(v, None)]
                why = f"has an item {bad[0]!r} that is not finite" if bad else None
        if why is None and rng is not None and rng.length is None and isinstance(value, (list, tuple)):
            for v in value:  # a scalar range on a list field applies to each item
                inner = rng.problem(v)
                if inner:
                    why = f"has an item {v!r} that {inner}"
                    break
        if why:
            items = value if isinstance(value, (list, tuple)) else [value]
            integer = bool(items) and all(isinstance(v, int) and not isinstance(v, bool) for v in items)
            allowed = rng.describe(integer=integer) if rng is not None else "a finite number"
            raise UserError(
                f"bad value {key}={_show(value)}: it {why}; allowed: {allowed}. "
                f"Set {key} to an allowed value (default: {_default_text(field)})."
            )
    return config


#: attribute :func:`typed_config` leaves on the instances it checked: their values then (``dataclasses.astuple``)
_CHECKED_VALUES = "_bionav_checked_values"


def _mark_checked(config: Any) -> None:
    """Remember that ``config`` (and every nested config in it) passed :func:`typed_config` with these values."""
    for field in dataclasses.fields(config):
        value = getattr(config, field.name, None)
        if dataclasses.is_dataclass(value) and not isinstance(value, type):
            _mark_checked(value)
    try:
        object.__setattr__(config, _CHECKED_VALUES, dataclasses.astuple(config))
    except (AttributeError, TypeError):  # a dataclass with __slots__: checked again where it is used
        pass


def checked_config(config: Any, *, prefix: str) -> Any:
    """``config`` with its declared ranges checked, once: the check of classes that also take Python instances.

    An instance that :func:`typed_config` returned (the command line, a
    config file) and whose values have not changed since is handed back as it
    is; any other instance (built in Python, or changed after it was checked)
    goes through :func:`check_config`.

    Parameters
    ----------
    config : dataclass instance
        The config.
    prefix : str
        The key of the config as the user types it (``homing``), named in messages.

    Returns
    -------
    The same ``config``.

    Raises
    ------
    UserError
        As :func:`check_config`.
    """
    if dataclasses.is_dataclass(config) and not isinstance(config, type):
        seen = getattr(config, _CHECKED_VALUES, None)
        try:
            unchanged = seen is not None and seen == dataclasses.astuple(config)
        except ValueError:  # a field changed to an array after the check: its == is element-wise
            unchanged = False
        if unchanged:
            return config
    return check_config(config, prefix=prefix)


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
    what : str, optional
        What the node configures, said in parentheses (``experiment=cleaning``).
    """
    import difflib

    full = f"{node}.{bad}" if node else bad
    close = difflib.get_close_matches(bad, list(valid), n=1, cutoff=0.6)
    hint = f" Did you mean {node + '.' if node else ''}{close[0]}?" if close else ""
    owner = f" ({what})" if what else ""
    keys = ", ".join(valid) or "(none)"
    return f"unknown key {full}: {node or 'the config'}{owner} has no key {bad!r}; its keys are {keys}.{hint}"


def _schema_file(schema: type) -> str:
    """The source file of a config dataclass as users find it (``bionav/experiments/configs/grid.py``)."""
    import sys

    module = schema.__module__
    file = getattr(sys.modules.get(module), "__file__", None) or ""
    return module.replace(".", "/") + ("/__init__.py" if file.endswith("__init__.py") else ".py")


def _joined(prefix: str, key: str) -> str:
    return f"{prefix}.{key}" if prefix and key else (prefix or key)


def _omegaconf_message(exc: Exception, schema: type, *, key: str, what: str, rooted: bool) -> str:
    """The one message for an OmegaConf merge error: unknown key, missing value or wrong type."""
    from omegaconf import DictConfig, OmegaConf

    full = str(getattr(exc, "full_key", "") or "")
    if rooted and full.startswith(key + "."):
        full = full[len(key) + 1:]  # relative to the node
    elif rooted and full == key:
        full = ""
    kind = type(exc).__name__
    if kind in ("ConfigKeyError", "ConfigAttributeError") and full:
        parent, _, bad = full.rpartition(".")
        where = OmegaConf.structured(schema)
        if parent:
            where = OmegaConf.select(where, parent)
        valid = [str(k) for k in where.keys()] if isinstance(where, DictConfig) else []
        return unknown_key_message(_joined(key, parent), bad, valid, what=what)
    name = _joined(key, full)
    if kind == "MissingMandatoryValue" and full:
        return f"{name} has no value ({what} needs it); add {name}=<value> on the command line."
    value = getattr(exc, "value", None)
    shown = f"={_show(value)}" if value is not None else ""
    first = str(exc).splitlines()[0] if str(exc) else kind
    return (f"bad value {name}{shown} ({what}): {first}. Give {name} a value of the declared type "
            f"(see {schema.__name__} in {_schema_file(schema)}).")


def typed_config(node: Any, schema: type, *, key: str, what: str | None = None, root: Any = None) -> Any:
    """A config node as an instance of its dataclass, every value checked: the one config path.

    The node is merged onto ``schema`` (OmegaConf types each value: an integer
    field holds an ``int``, a float field a ``float``), then
    :func:`check_config` checks every declared range; a dataclass may add two
    hooks, both called here and nowhere else:

    * ``unused_keys(self) -> (set_but_unused, used)``: keys (dotted for
      nested ones, ``camera.width``) given a value that this instance does
      not use (``db.grid_shape`` on a synthetic database, whose grid is its
      own) and the keys it does use;
    * ``validate(self)``: relations between fields (``min < max``), raising
      :class:`~bionav.errors.UserError`.

    Callers use the returned values as they are: nothing re-checks a declared
    range or re-casts a typed value afterwards.

    Parameters
    ----------
    node : DictConfig, Mapping, schema instance or None
        The config node (interpolations such as ``${data_dir}`` are resolved
        against the config it belongs to). ``None`` gives the defaults.
    schema : type
        Its dataclass.
    key : str
        The key users type for the node (``db``, ``homing``, ``layout``;
        ``""`` for top-level keys); messages name ``<key>.<field>``.
    what : str, optional
        What the node configures, said in messages (``db=sim_original``,
        ``the homing plugin 'sift'``); default ``key``.
    root : DictConfig, optional
        The whole config, when the dataclass' defaults interpolate other keys
        (``${seed}``, ``${experiment.grid}``): the node is then ``root[key]``
        typed in place, and ``node`` is ignored.

    Returns
    -------
    An instance of ``schema``.

    Raises
    ------
    UserError
        One paragraph: an unknown key (the node's keys listed, the closest
        named), a missing or ill-typed value, a value outside its declared
        range (:func:`check_config`), a key this instance does not use (the
        keys it uses listed), or a relation between fields broken.
    """
    from omegaconf import OmegaConf
    from omegaconf.errors import OmegaConfBaseException

    what = what or key or "the config"
    if isinstance(node, schema) and root is None:
        instance = node
    else:
        try:
            if root is not None:
                tree = OmegaConf.merge(OmegaConf.create({key: OmegaConf.structured(schema)}), root)
                typed = tree[key]
            else:
                plain = OmegaConf.to_container(node, resolve=True) if OmegaConf.is_config(node) else dict(node or {})
                typed = OmegaConf.merge(OmegaConf.structured(schema), plain)
            instance = OmegaConf.to_object(typed)
        except OmegaConfBaseException as exc:
            raise UserError(_omegaconf_message(exc, schema, key=key, what=what, rooted=root is not None)) from None
    check_config(instance, prefix=key)
    unused_keys = getattr(instance, "unused_keys", None)
    if callable(unused_keys):
        unused, used = unused_keys()
        if unused:
            bad = unused[0]
            name = _joined(key, bad)
            value = instance
            for part in bad.split("."):  # a nested key: camera.width
                value = getattr(value, part)
            raise UserError(
                f"{name}={_show(value)} is not used by {what}; it uses: {', '.join(used)}. "
                f"Remove {name} from the command line, or choose another {key or 'setting'} that uses it."
            )
    validate = getattr(instance, "validate", None)
    if callable(validate):
        validate()
    if dataclasses.is_dataclass(instance):
        _mark_checked(instance)
    return instance


def available_memory_bytes() -> int:
    """Memory available to a new allocation (``MemAvailable``, else physical memory)."""
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    try:
        return int(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):  # pragma: no cover - non-POSIX
        return 8 << 30


def format_bytes(n: float) -> str:
    """``1.2 TiB`` style size."""
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if abs(n) < 1024 or unit == "PiB":
            return f"{n:.1f} {unit}" if unit != "B" else f"{int(n)} B"
        n /= 1024.0
    return f"{n:.1f} PiB"  # pragma: no cover


def check_allocation(nbytes: float, *, what: str, fix: str, fraction: float = 0.8) -> None:
    """Refuse an allocation larger than ``fraction`` of the available memory.

    Parameters
    ----------
    nbytes : float
        Size of the planned allocation in bytes.
    what : str
        What would be allocated (``"1000 images of 100000 x 20000 pixels"``).
    fix : str
        How to make it smaller (names the key).
    """
    limit = fraction * available_memory_bytes()
    if nbytes > limit:
        raise UserError(
            f"{what} would need {format_bytes(nbytes)} of memory, but only "
            f"{format_bytes(available_memory_bytes())} is available; {fix}."
        )
