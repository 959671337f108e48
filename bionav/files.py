"""Files bionav writes: one atomic writer, one cache directory, one cache key.

* :func:`write_atomic` writes text, bytes, or whatever a callback writes to a
  temporary file beside the target and moves it into place with
  ``os.replace``: readers (and concurrent writers of the same content) never
  see a half-written file, and a crash leaves the old file intact. The new
  file's mode follows the process umask, like a plain ``open(path, "w")``.
* :func:`write_json_atomic` is the same for JSON (NumPy scalars and arrays
  become plain numbers and lists), :func:`write_csv_atomic` for CSV tables
  (the one CSV writer).
* :func:`default_cache_dir` is ``$BIONAV_CACHE`` or ``~/.cache/bionav``, the
  home of rendered stand-in databases and cached per-image work.
* :func:`cache_key` is the SHA-256 of a JSON payload and of array bytes, so
  caches are content-addressed and safe to share between runs.
* :func:`user_path`, :func:`not_a_regular_file` and :func:`read_json_file` are
  the bounded reads of user-given data files: ``~`` expanded, never opening a
  FIFO or a device (which would block or never end), a size limit checked
  before reading, UTF-16 and oversized integers explained.
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import os
import secrets
import sys
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any, Callable, Iterable, Sequence

if TYPE_CHECKING:  # numpy is imported where an array is hashed: start-up paths (TAB completion) stay without it
    import numpy as np

__all__ = ["OwnedFolder", "cache_key", "check_cache_dir", "default_cache_dir", "not_a_regular_file", "read_json_file",
           "user_path", "write_atomic", "write_csv_atomic", "write_json_atomic"]


def default_cache_dir() -> Path:
    """``$BIONAV_CACHE`` (``~`` expanded) if set, else ``~/.cache/bionav``.

    Raises
    ------
    UserError
        When ``$BIONAV_CACHE`` cannot hold a cache (:func:`check_cache_dir`).
    """
    env = os.environ.get("BIONAV_CACHE")
    if env is None:
        return Path.home() / ".cache" / "bionav"
    return check_cache_dir(env)


#: the folders of bionav's compiled (numba) kernels: numba caches them in their ``__pycache__`` by default
_KERNEL_DIRS = ("evaluation", "homing", "homing/warping", "robot", "world")


def _writable_dir(path: str | os.PathLike) -> bool:
    """True if ``path`` is (or can be made) a folder where files can be created, as numba checks it."""
    import tempfile

    try:
        os.makedirs(path, exist_ok=True)
        tempfile.TemporaryFile(dir=path).close()
        return True
    except (OSError, ValueError):
        return False


def ensure_numba_cache() -> str | None:
    """Give numba a place to cache bionav's kernels where it would find none; the folder set, or ``None``.

    numba caches compiled kernels in ``NUMBA_CACHE_DIR``, else beside the
    sources (``__pycache__``), else in ``~/.cache/numba``; where none of these
    can be written (a read-only install and a home folder that is not
    writable) it stops at the first import with a ``RuntimeError``. Then
    ``NUMBA_CACHE_DIR`` is set to ``<bionav cache>/numba`` (:func:`default_cache_dir`)
    or, if that cannot be written either, to a folder in the system's temporary
    folder. Called once when :mod:`bionav` is imported (before numba reads its
    settings); a usable setting of the user's is kept.
    """
    import tempfile

    own = os.environ.get("NUMBA_CACHE_DIR")
    if own and _writable_dir(own):
        return None
    package = Path(__file__).resolve().parent
    if all(_writable_dir(package / d / "__pycache__") for d in _KERNEL_DIRS):
        return None
    try:
        user_wide = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "numba"
    except RuntimeError:  # no home folder at all
        user_wide = None
    if user_wide is not None and _writable_dir(user_wide):
        return None
    candidates = [Path(tempfile.gettempdir()) / f"bionav-numba-{os.getuid() if hasattr(os, 'getuid') else 0}"]
    try:
        candidates.insert(0, default_cache_dir() / "numba")
    except Exception:  # BIONAV_CACHE unusable (reported where the cache is used) or no home folder
        pass
    for folder in candidates:
        if _writable_dir(folder):
            os.environ["NUMBA_CACHE_DIR"] = str(folder)
            numba_config = sys.modules.get("numba.core.config")
            if numba_config is not None:  # numba imported before bionav: tell it directly
                numba_config.CACHE_DIR = str(folder)
            return str(folder)
    return None


def numba_cached(kernel: Any) -> bool:
    """True when numba has compiled code of ``kernel`` (a dispatcher) in this process or in its on-disk cache.

    A cheap look (no compiling): before a long loop, whether its first call will compile first.
    """
    if getattr(kernel, "signatures", None):
        return True
    index = getattr(getattr(getattr(kernel, "_cache", None), "_cache_file", None), "_index_path", None)
    return bool(index) and os.path.exists(index)


def check_cache_dir(value: str | os.PathLike) -> Path:
    """The cache folder ``value`` (``~`` expanded) once it is known to be usable; checked before any work.

    Refused: an empty value (it would mean the current folder), a file (or a
    file on the way), a place where no folder can be created or written
    (``/proc``, ``/sys``, a read-only disk). The message names
    ``BIONAV_CACHE`` when that environment variable is set, else ``cache_dir``.

    Raises
    ------
    UserError
        Naming the value, the problem and the fix.
    """
    from bionav.errors import UserError

    name = "BIONAV_CACHE" if "BIONAV_CACHE" in os.environ else "cache_dir"
    fix = ("Set BIONAV_CACHE to a writable folder (e.g. export BIONAV_CACHE=~/.cache/bionav), or unset it to use "
           "~/.cache/bionav." if name == "BIONAV_CACHE" else "Give cache_dir=<a writable folder>.")
    text = os.fspath(value)
    if not text.strip():
        raise UserError(f"{name} is set but empty, so bionav does not know where to keep its render and per-image "
                        f"cache. {fix}")
    path = user_path(text)
    probe = path
    while not probe.exists() and probe != probe.parent:
        probe = probe.parent
    problem = None
    if probe.exists() and not probe.is_dir():
        problem = "it is a file, not a folder" if probe == path else f"{probe} is a file, not a folder"
    elif str(path.absolute()).startswith(("/proc/", "/sys/", "/dev/")) or path.absolute() in (
            Path("/proc"), Path("/sys"), Path("/dev")):
        problem = "it lies in a virtual file system (/proc, /sys or /dev) that cannot hold files"
    elif not os.access(probe, os.W_OK | os.X_OK):
        problem = f"{probe} is not writable"
    if problem:
        raise UserError(f"{name}={text} cannot hold the render and per-image cache: {problem}. {fix}")
    return path


def user_path(value: str | os.PathLike) -> Path:
    """A path the user typed, with a leading ``~`` / ``~user`` expanded (Hydra and YAML do not)."""
    return Path(os.path.expanduser(os.fspath(value)))


def not_a_regular_file(path: str | Path) -> str | None:
    """Why ``path`` cannot be read as a data file, or ``None`` if it is a regular file.

    FIFOs, sockets and devices (``/dev/null``, ``/dev/zero``) are refused
    before they are opened: reading one blocks or never ends. The answer is a
    phrase such as ``"is a FIFO (named pipe)"``.
    """
    import stat

    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        return "does not exist"
    except OSError as exc:
        return f"cannot be read ({exc.strerror or exc})"
    if stat.S_ISREG(mode):
        return None
    if stat.S_ISDIR(mode):
        return "is a folder, not a file"
    if stat.S_ISFIFO(mode):
        return "is a FIFO (named pipe), not a file"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "is a device, not a file"
    if stat.S_ISSOCK(mode):
        return "is a socket, not a file"
    return "is not a regular file"


#: integers with more digits than this are refused in JSON data files (beyond float64's range anyway)
MAX_INT_DIGITS = 308


def _bounded_int(text: str) -> int | float:
    if len(text.lstrip("-")) > MAX_INT_DIGITS:
        raise ValueError(f"an integer of {len(text.lstrip('-'))} digits (beyond the range of a 64-bit float)")
    return int(text)


def read_json_file(path: str | Path, *, what: str, fix: str, max_bytes: int = 256 * 2**20) -> Any:
    """Parse a user's JSON data file, refusing anything that would block, exhaust memory or confuse.

    Parameters
    ----------
    path : path-like
        The file (``~`` expanded).
    what : str
        What the file is, for messages, e.g. ``"the recording"``.
    fix : str
        The sentence telling the user what to do about a bad file.
    max_bytes : int
        Larger files are refused before they are read (bytes).

    Raises
    ------
    UserError
        Naming the file and the problem: not a regular file (FIFO, device,
        folder, missing), larger than ``max_bytes``, UTF-16/32 instead of
        UTF-8, invalid JSON, integers of more than :data:`MAX_INT_DIGITS` digits.
    """
    from bionav.errors import UserError

    path = user_path(path)
    problem = not_a_regular_file(path)
    if problem is None and path.stat().st_size > max_bytes:
        problem = f"is {path.stat().st_size / 2**20:.0f} MiB, more than the {max_bytes / 2**20:.0f} MiB allowed"
    if problem is None:
        try:
            data = path.read_bytes()
        except OSError as exc:
            problem = f"cannot be read ({exc.strerror or exc})"
    if problem is not None:
        raise UserError(f"{what} {path} {problem}. {fix}")
    if data[:2] in (b"\xff\xfe", b"\xfe\xff") or (len(data) > 1 and (data[0] == 0 or data[1] == 0)):
        raise UserError(f"{what} {path} is UTF-16 (or UTF-32) text; JSON files must be UTF-8. Convert it, e.g. "
                        f"`iconv -f UTF-16 -t UTF-8 {path} > fixed.json`, or re-export it as UTF-8. {fix}")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise UserError(f"{what} {path} is not UTF-8 text (byte {exc.start} cannot be decoded); JSON files must "
                        f"be UTF-8. {fix}") from None
    try:
        return json.loads(text, parse_int=_bounded_int)
    except ValueError as exc:
        raise UserError(f"{what} {path} is not valid JSON ({exc}). {fix}") from None
    except RecursionError:  # "[[[[...": deeper than any data file bionav reads
        raise UserError(f"{what} {path} nests lists or objects thousands of levels deep; no data file of bionav "
                        f"does. {fix}") from None


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
    import numpy as np

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
    np = sys.modules.get("numpy")  # a NumPy value exists only where numpy was imported
    if np is not None and isinstance(value, np.generic):
        return value.item()
    if np is not None and isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f"{type(value).__name__} is not JSON serialisable")


def write_json_atomic(path: str | Path, data: Any, *, indent: int | None = 2) -> Path:
    """Write ``data`` as JSON (plus a final newline) with :func:`write_atomic`.

    NumPy scalars and arrays are written as numbers and lists, paths as strings.
    """
    return write_atomic(path, json.dumps(data, indent=indent, default=_json_scalar) + "\n")


def write_csv_atomic(path: str | Path, header: Sequence[Any], rows: Iterable[Sequence[Any]]) -> Path:
    """Write a CSV table (the header row, then ``rows``) with :func:`write_atomic`: the one CSV writer.

    The :mod:`csv` module's default dialect (``excel``): fields separated by
    commas, quoted only when they hold a comma, a quote or a line break, every
    line ending in ``\\r\\n``; UTF-8. A value is written as ``str(value)``
    (format floats before), ``None`` as an empty field. Rows of a mapping:
    ``([row.get(c, "") for c in header] for row in rows)``.

    Returns
    -------
    Path
        The target path.
    """
    text = io.StringIO(newline="")
    writer = csv.writer(text)
    writer.writerow(header)
    writer.writerows(rows)
    return write_atomic(path, text.getvalue())


#: the record of what bionav wrote into an output folder it shares with the user's own files
OWNED_MANIFEST = ".bionav-files.json"


class OwnedFolder:
    """An output folder (``--out``) that bionav shares with the user: it overwrites only what it wrote.

    bionav records the SHA-256 of every file it writes there in
    :data:`OWNED_MANIFEST`; a file of the same name that is not in that record,
    or whose content changed since (the user edited it), is the user's and is
    never overwritten (:meth:`check` refuses, naming it and the fix).

    Parameters
    ----------
    folder : path-like
        The output folder (created by the caller).
    option : str
        How the user names it, for messages (``"--out"``).
    """

    def __init__(self, folder: str | Path, *, option: str = "--out") -> None:
        self.folder, self.option = Path(folder), option
        try:
            data = json.loads((self.folder / OWNED_MANIFEST).read_text(encoding="utf-8"))
        except (OSError, ValueError):
            data = {}
        self.written: dict[str, str] = {str(k): str(v) for k, v in data.items()} if isinstance(data, dict) else {}

    @staticmethod
    def _digest(path: Path) -> str | None:
        try:
            with open(path, "rb") as f:
                return hashlib.file_digest(f, "sha256").hexdigest()
        except OSError:
            return None

    def foreign(self, names: Iterable[str]) -> list[str]:
        """The ``names`` that exist in the folder and were not written there by bionav (as they are now)."""
        out = []
        for name in names:
            path = self.folder / name
            if path.is_symlink() or path.exists():
                if not path.is_file() or path.is_symlink() or self.written.get(name) != self._digest(path):
                    out.append(name)
        return sorted(set(out))

    def check(self, names: Iterable[str]) -> None:
        """Raise :class:`~bionav.errors.UserError` if any of ``names`` is a file bionav did not write."""
        from bionav.errors import UserError

        mine = self.foreign(names)
        if mine:
            shown = ", ".join(mine[:5]) + (f" and {len(mine) - 5} more" if len(mine) > 5 else "")
            raise UserError(
                f"{self.option} {self.folder} holds {shown}, which bionav did not write (or which was changed since), "
                f"and this command would write files of the same name there. Nothing was overwritten: move "
                f"{'them' if len(mine) > 1 else 'it'} elsewhere, or give another {self.option}.")

    def claim(self, name: str) -> None:
        """Record ``name`` (written by bionav just now) as bionav's; call :meth:`save` after the last one."""
        digest = self._digest(self.folder / name)
        if digest is not None:
            self.written[name] = digest

    def write(self, name: str, data: str | bytes) -> Path:
        """Write ``name`` atomically (after :meth:`check`) and record it as bionav's."""
        self.check([name])
        path = write_atomic(self.folder / name, data)
        self.claim(name)
        self.save()
        return path

    def save(self) -> None:
        """Write the record of bionav's files (atomically)."""
        write_json_atomic(self.folder / OWNED_MANIFEST, dict(sorted(self.written.items())))
