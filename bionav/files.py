"""Files bionav writes: one atomic writer, one cache directory, one cache key.

* :func:`write_atomic` writes text, bytes, or whatever a callback writes to a
  temporary file beside the target and moves it into place with
  ``os.replace``: readers (and concurrent writers of the same content) never
  see a half-written file, and a crash leaves the old file intact. The new
  file's mode follows the process umask, like a plain ``open(path, "w")``.
* :func:`write_json_atomic` is the same for JSON (NumPy scalars and arrays
  become plain numbers and lists).
* :func:`default_cache_dir` is ``$BIONAV_CACHE`` or ``~/.cache/bionav``, the
  home of rendered stand-in databases and cached per-image work.
* :func:`cache_key` is the SHA-256 of a JSON payload and of array bytes, so
  caches are content-addressed and safe to share between runs.
"""

from __future__ import annotations

import hashlib
import json
import os
import secrets
from pathlib import Path
from typing import IO, Any, Callable

import numpy as np

__all__ = ["cache_key", "default_cache_dir", "write_atomic", "write_json_atomic"]


def default_cache_dir() -> Path:
    """``$BIONAV_CACHE`` if set, else ``~/.cache/bionav``."""
    env = os.environ.get("BIONAV_CACHE")
    return Path(env) if env else Path.home() / ".cache" / "bionav"


def cache_key(payload: Any, *arrays: np.ndarray) -> str:
    """SHA-256 (hex) of everything a cached result depends on.

    Parameters
    ----------
    payload : JSON-serialisable
        Parameters; dict keys are sorted and anything JSON cannot encode is
        hashed by its ``str``, so equal parameters give equal keys.
    *arrays : ndarray
        Array inputs, hashed by shape, dtype and bytes (C order).

    Returns
    -------
    str
        64 hexadecimal digits.
    """
    h = hashlib.sha256(json.dumps(payload, sort_keys=True, default=str).encode())
    for array in arrays:
        arr = np.ascontiguousarray(array)
        h.update(str((arr.shape, arr.dtype.str)).encode())
        h.update(arr.tobytes())
    return h.hexdigest()


def write_atomic(path: str | Path, data: str | bytes | Callable[[IO[bytes]], None]) -> Path:
    """Write ``data`` to ``path`` atomically (temporary file + ``os.replace``).

    Parameters
    ----------
    path : path-like
        Target file; missing parent folders are created.
    data : str, bytes or callable
        Text (written as UTF-8), bytes, or a function that writes to the
        binary file handle it is given (e.g. ``lambda f: np.savez(f, **arrays)``).

    Returns
    -------
    Path
        The target path.

    Notes
    -----
    The temporary file is created with mode ``0o666`` minus the umask (not
    the ``0o600`` of :func:`tempfile.mkstemp`) and is removed on any error,
    Ctrl-C included.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.parent / f".{path.name}.{secrets.token_hex(6)}.tmp"
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
    try:
        with os.fdopen(fd, "wb") as f:
            if isinstance(data, str):
                f.write(data.encode("utf-8"))
            elif isinstance(data, (bytes, bytearray, memoryview)):
                f.write(data)
            else:
                data(f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
    return path


def _json_scalar(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f"{type(value).__name__} is not JSON serialisable")


def write_json_atomic(path: str | Path, data: Any, *, indent: int | None = 2) -> Path:
    """Write ``data`` as JSON (plus a final newline) with :func:`write_atomic`.

    NumPy scalars and arrays are written as numbers and lists, paths as strings.
    """
    return write_atomic(path, json.dumps(data, indent=indent, default=_json_scalar) + "\n")
