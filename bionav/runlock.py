"""One run per run directory: a lock file holding the owner's pid, host and start time.

A second run into a directory whose lock is held by a live process is refused
(:class:`bionav.errors.UserError`); a lock left behind by a crashed run
(SIGKILL, power cut) is recognised as stale -- its process is gone, or its
pid now belongs to another process -- and taken over. The run it guarded is
then marked ``"interrupted"`` in its metrics.json (it said ``"running"`` for
good otherwise; :func:`settle_stale`, :func:`settle_stale_runs`).
"""

from __future__ import annotations

import json
import os
import socket
import time
from pathlib import Path

from bionav.errors import UserError

LOCK_FILE = ".bionav.lock"
METRICS_FILE = "metrics.json"
#: the status of a run whose process died without finishing its record
INTERRUPTED = "interrupted"


def _process_start(pid: int) -> str | None:
    """Start time of a process in clock ticks since boot (Linux), to tell reused pids apart."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    return stat.rsplit(")", 1)[-1].split()[19]


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, owned by someone else
        return True
    return True


def _read(path: Path) -> dict | None:
    from bionav.files import not_a_regular_file

    if not_a_regular_file(path) not in (None, "does not exist"):  # a FIFO must not block: a broken lock
        return {"pid": -1, "host": "?", "started": f"{path} {not_a_regular_file(path)}"}
    try:
        info = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    return info if isinstance(info, dict) else None


def lock_owner(run_dir: str | Path) -> dict | None:
    """The live owner of ``run_dir``'s lock (``pid``, ``host``, ``started``), or ``None`` if free or stale.

    A lock written on another host is reported as live (its process cannot
    be checked from here).
    """
    info = _read(Path(run_dir) / LOCK_FILE)
    if info is None:
        return None
    try:
        pid = int(info.get("pid", -1))
    except (TypeError, ValueError):  # not written by bionav: nobody holds it
        return None
    if info.get("host") != socket.gethostname():
        return info
    if pid <= 0 or not _alive(pid):
        return None
    start = info.get("start_ticks")
    if start is not None and _process_start(pid) not in (None, start):
        return None  # the pid was reused by another process
    return info


#: what a refused run is told to do (the thesis command passes its own, naming --out)
RUN_FIX = "Choose another directory with hydra.run.dir=..., or wait for that run to finish."


def _refusal(run_dir: Path, info: dict, *, what: str = "run directory", fix: str = RUN_FIX) -> UserError:
    where = info.get("host", "?")
    return UserError(
        f"the {what} {run_dir} is in use by another bionav command (pid {info.get('pid')} on {where}, "
        f"started {info.get('started', '?')}); two writers in one directory would overwrite each other's "
        f"files. {fix} If that command is dead (on another host), delete {run_dir / LOCK_FILE}."
    )


def check_free(run_dir: str | Path) -> None:
    """Raise :class:`UserError` if a live run holds ``run_dir`` (checked before Hydra writes there).

    A dead run's lock is settled on the way (:func:`settle_stale`).
    """
    info = lock_owner(run_dir)
    if info is not None and not (info.get("host") == socket.gethostname() and info.get("pid") == os.getpid()):
        raise _refusal(Path(run_dir), info)
    if info is None:
        settle_stale(run_dir)


def settle_stale(run_dir: str | Path) -> bool:
    """Mark the run in ``run_dir`` interrupted if its process died while it said ``"running"``; True if marked.

    A run holds its lock from before its metrics.json says ``"running"`` until
    after the final status is written, so ``"running"`` with no live lock means
    the process was killed (SIGKILL, out of memory, a power cut). The metrics
    keep every value recorded, with ``"status": "interrupted"`` and an ``error``
    saying so; the stale lock is removed. A lock of a live process, or of
    another host, is left alone (False).
    """
    from bionav.files import write_json_atomic

    run_dir = Path(run_dir)
    if lock_owner(run_dir) is not None:
        return False
    info = _read(run_dir / LOCK_FILE) or {}
    metrics = _read(run_dir / METRICS_FILE)
    marked = False
    if isinstance(metrics, dict) and metrics.get("status") == "running":
        pid = info.get("pid", metrics.get("pid", "?"))
        metrics.update(status=INTERRUPTED, error=(
            f"the run's process (pid {pid}) ended without finishing its record (killed, e.g. SIGKILL, out of "
            f"memory or a power cut); what it logged is kept in run.mcap (`python -m bionav.logs recover` repairs "
            f"a cut log)"))
        try:
            write_json_atomic(run_dir / METRICS_FILE, metrics)
            marked = True
        except OSError:  # a read-only copy of a run: reported as it is
            return False
    if info:
        try:
            (run_dir / LOCK_FILE).unlink()
        except OSError:
            pass
    return marked


def settle_stale_runs(root: str | Path) -> int:
    """:func:`settle_stale` for every run below ``root`` that says ``"running"``; the number marked."""
    root = Path(root)
    if not root.is_dir():
        return 0
    dirs = {p.parent for p in root.rglob(METRICS_FILE)} | {p.parent for p in root.rglob(LOCK_FILE)}
    return sum(settle_stale(d) for d in sorted(dirs) if d != root or (d / METRICS_FILE).exists())


class RunLock:
    """Hold ``run_dir/.bionav.lock`` for the lifetime of a run (a context manager).

    Raises
    ------
    UserError
        When another live run holds the directory (``what`` names the
        directory's role and ``fix`` the way out in that message).
    """

    def __init__(self, run_dir: str | Path, *, what: str = "run directory", fix: str = RUN_FIX) -> None:
        self.path = Path(run_dir) / LOCK_FILE
        self._held = False
        self._words = {"what": what, "fix": fix}

    def acquire(self) -> "RunLock":
        me = {
            "pid": os.getpid(),
            "host": socket.gethostname(),
            "started": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
            "start_ticks": _process_start(os.getpid()),
        }
        tmp = self.path.with_name(f"{LOCK_FILE}.{os.getpid()}.tmp")
        tmp.write_text(json.dumps(me))
        try:
            for _ in range(2):
                try:
                    os.link(tmp, self.path)  # atomic: fails if the lock exists; never an empty lock file
                    self._held = True
                    return self
                except FileExistsError:
                    owner = lock_owner(self.path.parent)
                    if owner is not None:
                        raise _refusal(self.path.parent, owner, **self._words) from None
                    settle_stale(self.path.parent)  # stale: the owner crashed; its run is marked interrupted
                    try:
                        self.path.unlink()
                    except FileNotFoundError:
                        pass
            raise _refusal(self.path.parent, _read(self.path) or {}, **self._words)
        finally:
            tmp.unlink(missing_ok=True)

    def release(self) -> None:
        if not self._held:
            return
        self._held = False
        info = _read(self.path)
        if info and info.get("pid") == os.getpid() and info.get("host") == socket.gethostname():
            self.path.unlink(missing_ok=True)

    def __enter__(self) -> "RunLock":
        return self.acquire()

    def __exit__(self, *exc: object) -> None:
        self.release()
