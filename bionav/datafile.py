"""The one reader of files users hand bionav: capped before reading, every field checked after.

Calibrations, recordings, logs to replay, meshes, CSV tables and recorded
configurations all enter through here:

* :func:`checked_path` refuses, before anything is opened, a file that does not
  exist, is not a regular file (a FIFO or ``/dev/zero`` would block or never
  end) or is larger than the cap of its kind (:data:`MAX_BYTES`);
* :func:`read_user_bytes`, :func:`read_user_text` and :func:`read_user_json`
  read such a file whole (JSON through :func:`bionav.files.read_json_file`:
  UTF-16 and oversized integers explained);
* :class:`FileFields` checks what was read, field by field: present, a number
  or a rectangular array of numbers of the expected shape, finite (NaN and
  infinity never pass), within its range (a :class:`bionav.validation.Range`),
  integers where indices are meant, and indices within their table.

Every refusal is one :class:`~bionav.errors.UserError` naming the file, the
field, the allowed values and the fix, e.g. ``The POL-OP calibration cal.json:
field 'gain' holds nan at [0, 2]; allowed: a finite number > 0 and <= 100.
Recalibrate with recordings.calibration=auto.``
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from bionav.errors import UserError
from bionav.validation import Range

__all__ = ["MAX_BYTES", "FileFields", "checked_path", "read_user_bytes", "read_user_json", "read_user_text"]

#: the largest file of each kind bionav reads (bytes); larger ones are refused before they are opened
MAX_BYTES: dict[str, int] = {
    "calibration": 16 * 2**20,
    "recording": 64 * 2**20,
    "config": 16 * 2**20,
    "table": 256 * 2**20,
    "metadata": 2**20,
    "image": 1024 * 2**20,
    "mesh": 4 * 2**30,
    "log": 16 * 2**30,
}


def _size_text(n: float) -> str:
    for unit, scale in (("GiB", 2**30), ("MiB", 2**20), ("kiB", 2**10)):
        if n >= scale:
            return f"{n / scale:.0f} {unit}"
    return f"{n:.0f} bytes"


def checked_path(path: str | os.PathLike, *, what: str, fix: str, kind: str | None = None,
                 max_bytes: int | None = None) -> Path:
    """``path`` (``~`` expanded) once it is known to be a regular file within the size cap.

    Parameters
    ----------
    path : path-like
        The file the user named.
    what : str
        What the file is, for the message (``"The POL-OP calibration"``).
    fix : str
        The sentence telling the user what to do.
    kind : str, optional
        A key of :data:`MAX_BYTES`; the cap of that kind.
    max_bytes : int, optional
        The cap in bytes (overrides ``kind``).

    Raises
    ------
    UserError
        Missing, not a regular file (folder, FIFO, device, socket), unreadable, or too large.
    """
    from bionav.files import not_a_regular_file, user_path

    p = user_path(path)
    problem = not_a_regular_file(p)
    cap = max_bytes if max_bytes is not None else MAX_BYTES[kind] if kind is not None else None
    if problem is None and cap is not None:
        size = p.stat().st_size
        if size > cap:
            problem = f"is {_size_text(size)}, more than the {_size_text(cap)} such a file may have"
    if problem is None and not os.access(p, os.R_OK):
        problem = "cannot be read (permission denied)"
    if problem is not None:
        raise UserError(f"{what} {p} {problem}. {fix}")
    return p


def read_user_bytes(path: str | os.PathLike, *, what: str, fix: str, kind: str | None = None,
                    max_bytes: int | None = None) -> bytes:
    """The bytes of a user's file, after :func:`checked_path` (read errors become one message)."""
    p = checked_path(path, what=what, fix=fix, kind=kind, max_bytes=max_bytes)
    try:
        return p.read_bytes()
    except OSError as exc:
        raise UserError(f"{what} {p} cannot be read ({exc.strerror or exc}). {fix}") from None


def read_user_text(path: str | os.PathLike, *, what: str, fix: str, kind: str | None = None,
                   max_bytes: int | None = None, encoding: str = "utf-8-sig") -> str:
    """The text of a user's file (``encoding``, BOM removed), after :func:`checked_path`."""
    data = read_user_bytes(path, what=what, fix=fix, kind=kind, max_bytes=max_bytes)
    try:
        return data.decode(encoding)
    except UnicodeDecodeError as exc:
        raise UserError(f"{what} {path} is not {encoding.replace('-sig', '').upper()} text (byte {exc.start} "
                        f"cannot be decoded). {fix}") from None


def read_user_json(path: str | os.PathLike, *, what: str, fix: str, kind: str | None = None,
                   max_bytes: int | None = None) -> Any:
    """A user's JSON file, parsed (:func:`bionav.files.read_json_file` after :func:`checked_path`)."""
    from bionav.files import read_json_file

    p = checked_path(path, what=what, fix=fix, kind=kind, max_bytes=max_bytes)
    cap = max_bytes if max_bytes is not None else MAX_BYTES[kind] if kind is not None else 256 * 2**20
    return read_json_file(p, what=what, fix=fix, max_bytes=cap)


def _index_text(index: tuple[int, ...]) -> str:
    return f"[{', '.join(str(int(i)) for i in index)}]" if len(index) != 1 else f"[{int(index[0])}]"


class FileFields:
    """The fields of a parsed user file (a mapping), each checked as it is taken.

    Parameters
    ----------
    data : mapping
        The parsed file (a JSON object, a YAML mapping); anything else is refused.
    source : str
        The file as messages name it, e.g. ``"The POL-OP calibration cal.json"``.
    fix : str
        The sentence telling the user what to do about a bad field.
    """

    def __init__(self, data: Any, *, source: str, fix: str) -> None:
        self.source, self.fix = source, fix
        if not isinstance(data, Mapping):
            self.fail("<top level>", f"is a JSON {type(data).__name__}, not an object of named fields")
        self.data = data

    def fail(self, field: str, problem: str, allowed: str | None = None) -> None:
        """Raise the one message: file, field, problem, allowed values, fix."""
        tail = f"; allowed: {allowed}" if allowed else ""
        raise UserError(f"{self.source}: field {field!r} {problem}{tail}. {self.fix}")

    def has(self, field: str) -> bool:
        return field in self.data and self.data[field] is not None

    def array(self, field: str, *, shape: Sequence[int | None] | None = None, valid: Range | None = None,
              integer: bool = False, none: float | None = None, optional: bool = False,
              default: Any = None) -> np.ndarray:
        """Field ``field`` as a float64 (or int64, ``integer``) array, checked.

        Parameters
        ----------
        shape : sequence of int or None, optional
            The expected shape; ``None`` entries take any length.
        valid : Range, optional
            Allowed values of every element (NaN and infinity never pass, unless
            ``none`` fills JSON ``null`` with NaN: then NaN is allowed).
        integer : bool
            Elements must be whole numbers (indices, counts); returned as int64.
        none : float, optional
            Value standing for JSON ``null`` elements (default: ``null`` is refused).
        optional : bool
            A missing field gives ``default`` instead of an error.
        """
        if not self.has(field):
            if optional:
                return default
            self.fail(field, "is missing")
        raw = self.data[field]
        described = (valid or Range()).describe(integer=integer)
        try:
            values = np.array(_fill_none(raw, none), dtype=float)
        except (TypeError, ValueError, OverflowError) as exc:
            problem = ("is a ragged list (rows of different lengths)" if "inhomogeneous" in str(exc)
                       or "sequence" in str(exc) else "is not a list of numbers")
            self.fail(field, problem, described)
        if values.dtype == object:  # pragma: no cover - numpy >= 1.24 raises above
            self.fail(field, "is a ragged list (rows of different lengths)", described)
        if shape is not None:
            expected = tuple(shape)
            if values.ndim != len(expected) or any(e is not None and s != e for s, e in zip(values.shape, expected)):
                want = " x ".join("N" if e is None else str(e) for e in expected) or "a single number"
                self.fail(field, f"has shape {' x '.join(map(str, values.shape)) or 'scalar'}, expected {want}")
        self._check_values(field, values, valid, integer=integer, allow_nan=none is not None and np.isnan(none))
        return values.astype(np.int64) if integer else values

    def number(self, field: str, *, valid: Range | None = None, integer: bool = False, optional: bool = False,
               default: Any = None) -> float | int:
        """Field ``field`` as one checked number (``int`` with ``integer``)."""
        value = self.array(field, shape=(), valid=valid, integer=integer, optional=optional, default=default)
        if value is default and not self.has(field):
            return default
        return int(value) if integer else float(value)

    def indices(self, field: str, *, size: int, what: str = "unit") -> np.ndarray:
        """Field ``field`` as distinct integer indices into a table of ``size`` entries (0..size-1)."""
        values = self.array(field, shape=(None,), valid=Range(ge=0, le=size - 1), integer=True)
        if np.unique(values).size != values.size:
            self.fail(field, f"names a {what} twice", f"distinct {what} numbers 0..{size - 1}")
        return values

    def _check_values(self, field: str, values: np.ndarray, valid: Range | None, *, integer: bool,
                      allow_nan: bool) -> None:
        described = (valid or Range()).describe(integer=integer)
        bad = ~np.isfinite(values)
        if allow_nan:
            bad &= ~np.isnan(values)
        if bad.any():
            at = tuple(np.argwhere(bad)[0])
            self.fail(field, f"holds {float(values[at]):g}{' at ' + _index_text(at) if at else ''}", described)
        finite = np.where(np.isfinite(values), values, 0.0)
        if integer and np.any(finite != np.round(finite)):
            at = tuple(np.argwhere(finite != np.round(finite))[0])
            self.fail(field, f"holds {float(values[at]):g}{' at ' + _index_text(at) if at else ''}, not a whole number",
                      described)
        if valid is None:
            return
        outside = np.zeros(values.shape, bool)
        for bound, op in ((valid.ge, np.less), (valid.gt, np.less_equal), (valid.le, np.greater),
                          (valid.lt, np.greater_equal)):
            if bound is not None:
                outside |= op(finite, bound) & np.isfinite(values)
        if outside.any():
            at = tuple(np.argwhere(outside)[0])
            self.fail(field, f"holds {float(values[at]):g}{' at ' + _index_text(at) if at else ''}", described)


def _fill_none(value: Any, fill: float | None) -> Any:
    """``value`` with JSON ``null`` elements replaced by ``fill`` (left as they are when ``fill`` is None)."""
    if fill is None:
        return value
    if value is None:
        return fill
    if isinstance(value, (list, tuple)):
        return [_fill_none(v, fill) for v in value]
    return value
