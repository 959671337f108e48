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

bionav checks every plugin config in :func:`bionav.config.plugin_config`, the
``db`` node in :func:`bionav.db.loading.as_database_config` and the experiment
node in :func:`bionav.experiments.configs.experiment_config`; the command line
runs all of them before a run directory is created.

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
    allow_inf: bool = False,
) -> Any:
    """A dataclass field with a declared range (see the module docstring).

    List defaults are copied per instance (pass a list as ``default``; it is
    turned into a ``default_factory``).
    """
    rng = Range(ge=ge, gt=gt, le=le, lt=lt, choices=tuple(choices) if choices is not None else None,
                length=length, item=item, allow_inf=allow_inf)
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
