"""The command line and the runs already recorded: resume only the same run, never rewrite a finished one.

Used by :mod:`bionav.cli` before Hydra starts (so that a refused command writes
nothing) and inside each job:

* :func:`check_run_dir` -- a run directory given with ``hydra.run.dir``: a
  finished run is refused without ``bionav.resume=true``; with it, the
  requested configuration must equal the recorded one
  (:func:`bionav.runrecord.config_differences`), and a finished run of the
  same configuration is shown, not run again (Hydra is not started, so nothing
  in the directory is rewritten);
* :func:`check_sweep_dir` -- the same for a sweep directory: each job of the
  sweep (as Hydra's basic sweeper numbers them) against the job recorded under
  its number;
* :func:`check_job` -- inside a job, its configuration against the record in
  its directory (any sweeper; Hydra left an existing record untouched,
  :func:`bionav.runrecord.record_subdir`);
* :func:`point_latest` -- ``outputs/latest`` (``multirun/latest``) pointing at the
  newest run (sweep) started in the default place; :func:`forget_refused`
  removes the directory of a run refused at start.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path
from typing import Any, Sequence

from bionav.errors import UserError
from bionav.runrecord import (config_differences, differences_text, has_record, plain_config, read_status,
                              recorded_config, recorded_overrides)

#: the link to the newest run below the default output folders
LATEST = "latest"


def _refuse_other(path: Path, diffs, *, key: str) -> UserError:
    return UserError(
        f"bionav.resume=true continues only a run of the same configuration, and {path} holds a run of another "
        f"one: {differences_text(diffs)}. Its files are kept as they are. Run this configuration into another "
        f"directory ({key}=...), or resume with the recorded values."
    )


def check_run_dir(path: Path, cfg: Any, *, resume: bool) -> bool:
    """Check a single run's directory before Hydra starts; True when it holds this finished run (show it).

    ``cfg`` is the composed configuration (None when the command line was not composed here).

    Raises
    ------
    UserError
        A finished run without ``bionav.resume=true``; with it, a run of another configuration, or a
        record without its configuration.
    """
    if "${" in str(path) or not path.is_dir():
        return False
    status = read_status(path)
    if not resume:
        if status == "completed":
            raise UserError(
                f"the run directory {path} holds a finished run (metrics.json says completed); a new run there "
                f"would overwrite it. Choose another directory with hydra.run.dir=..., or add bionav.resume=true to "
                f"keep it and show its results.")
        return False
    if cfg is None:  # not composed here (e.g. --config-dir): the job compares it (check_job)
        return False
    recorded = recorded_config(path)
    if recorded is None:
        if has_record(path):
            raise UserError(
                f"bionav.resume=true: {path} holds a run without its recorded configuration (.hydra/config.yaml), "
                f"so bionav cannot tell whether this command asks for the same run; its files are kept. Run into "
                f"another directory with hydra.run.dir=...")
        return False
    diffs = config_differences(plain_config(cfg), recorded)
    if diffs:
        raise _refuse_other(path, diffs, key="hydra.run.dir")
    return status == "completed"


def check_job(run_dir: Path, cfg: Any, *, resume: bool) -> None:
    """Inside a job: with ``bionav.resume=true``, its configuration must be the one recorded in ``run_dir``."""
    if not resume:
        return
    recorded = recorded_config(run_dir)
    if recorded is None:
        return
    diffs = config_differences(plain_config(cfg), recorded)
    if diffs:
        raise _refuse_other(run_dir, diffs, key="hydra.sweep.dir")


def _pairs(overrides: Sequence[str]) -> set[tuple[str, str]]:
    """Canonical ``(key, value)`` of overrides, without Hydra's own keys and the keys that do not change results
    (:data:`bionav.runrecord.NEUTRAL_KEYS`)."""
    from hydra.core.override_parser.overrides_parser import OverridesParser

    from bionav.runrecord import NEUTRAL_KEYS

    out = set()
    for o in OverridesParser.create().parse_overrides([str(o) for o in overrides]):
        key = o.key_or_group
        if key.startswith(("hydra.", "hydra/")) or any(key == n or key.startswith(f"{n}.") for n in NEUTRAL_KEYS):
            continue
        out.add((key, str(o.get_value_element_as_str())))
    return out


def planned_jobs(words: Sequence[str], params: dict | None) -> list[list[str]] | None:
    """The overrides of each job of a basic sweep, in Hydra's order (None: not a basic sweep)."""
    from hydra._internal.core_plugins.basic_sweeper import BasicSweeper
    from hydra.core.override_parser.overrides_parser import OverridesParser

    if any(w.split("=", 1)[0].lstrip("+~") in ("hydra/sweeper", "hydra.sweep.subdir") for w in words):
        return None
    task = [w for w in words if not w.split("=", 1)[0].lstrip("+~").startswith(("hydra.", "hydra/"))]
    conf = [f"{k}={v}" for k, v in (params or {}).items()] + task
    try:
        overrides = OverridesParser.create().parse_overrides(conf)
        return [job for batch in BasicSweeper.split_arguments(overrides, None) for job in batch]
    except Exception:  # interval sweeps and the like: each job checks itself (check_job)
        return None


def check_sweep_dir(path: Path, words: Sequence[str], params: dict | None, *, resume: bool) -> None:
    """Check a sweep directory before Hydra starts (see :func:`check_run_dir`)."""
    if "${" in str(path) or not path.is_dir():
        return
    if not resume:
        finished = (path / "summary.csv").is_file() or any(
            read_status(job) == "completed" for job in path.glob("*") if job.is_dir())
        if finished:
            raise UserError(
                f"the sweep directory {path} holds a sweep with finished jobs; a new sweep there would overwrite "
                f"them. Choose another directory with hydra.sweep.dir=..., or finish that sweep with the same "
                f"command plus bionav.resume=true (finished jobs are kept).")
        return
    jobs = planned_jobs(words, params)
    if jobs is None:
        return
    for num, job in enumerate(jobs):
        recorded = recorded_overrides(path / str(num))
        if recorded is None:
            continue
        asked, had = _pairs(job), _pairs(recorded)
        if asked != had:
            diffs = [(k, dict(asked).get(k), dict(had).get(k)) for k in sorted({k for k, _ in asked ^ had})]
            raise UserError(
                f"bionav.resume=true continues only the same sweep, and job {num} in {path} was run with other "
                f"overrides: {differences_text(diffs)}. Its files are kept as they are. Give the sweep's original "
                f"command (same keys and values, same order of values), or sweep into another directory "
                f"(hydra.sweep.dir=...).")


def keep_record(cfg: Any, run_dir: Path, *, multirun: bool) -> None:
    """Inside a job: write its record (``.hydra/``; Hydra was told not to), or check and keep a resumed run's.

    With ``bionav.resume=true`` and a run recorded in ``run_dir``, the job's configuration must be the
    recorded one (:func:`check_job`); a finished run's files, its log included, are left as they are.
    ``outputs/latest`` (``multirun/latest``) is pointed at this run (sweep).
    """
    from hydra.core.hydra_config import HydraConfig
    from omegaconf import OmegaConf

    from bionav.runrecord import write_record

    hc = HydraConfig.get()
    resume = bool(OmegaConf.select(cfg, "bionav.resume", default=False))
    if hc.output_subdir is None:  # `python -m bionav` sets hydra.output_subdir=null: the record is bionav's
        if resume and has_record(run_dir):
            if read_status(run_dir) == "completed":
                _detach_file_logs(run_dir)
            try:
                check_job(run_dir, cfg, resume=True)
            except UserError:
                _detach_file_logs(run_dir)  # another run's directory: not even its log is written to
                raise
        else:
            write_record(run_dir, cfg, HydraConfig.instance().cfg, list(hc.overrides.task))
    point_latest(Path(str(hc.sweep.dir)) if multirun else run_dir)


def _detach_file_logs(run_dir: Path) -> None:
    """Stop Hydra's job log from writing into ``run_dir`` (a finished run that a resumed sweep passes)."""
    import logging

    root = logging.getLogger()
    for handler in list(root.handlers):
        if isinstance(handler, logging.FileHandler) and Path(handler.baseFilename).parent == run_dir.absolute():
            root.removeHandler(handler)
            handler.close()


def show_finished(run_dir: Path) -> None:
    """``bionav.resume=true`` into a finished run of the same configuration: its results, nothing rewritten."""
    from bionav.experiments.runner import read_metrics
    from bionav.report.table import format_metrics

    metrics = read_metrics(run_dir) or {}
    metrics["resumed"] = True
    print(format_metrics(metrics))
    print("(bionav.resume=true: this run had finished with the same configuration; its results are shown, "
          "nothing was run or rewritten)")
    print(f"run directory: {run_dir.absolute()}")


def point_latest(target: Path) -> None:
    """Point ``<parent of the date folder>/latest`` at ``target`` when it lies in ``outputs/`` or ``multirun/``.

    The link is relative (``latest -> 2026-11-28/10-05-39``) and replaced atomically; a ``latest`` that
    is not a link (the user's own file or folder) is left alone.
    """
    target = Path(target).absolute()
    for root in (Path.cwd() / "outputs", Path.cwd() / "multirun"):
        if root not in target.parents:
            continue
        link = root / LATEST
        if link.exists() and not link.is_symlink():
            return
        tmp = root / f".{LATEST}.{os.getpid()}"
        try:
            tmp.unlink(missing_ok=True)
            tmp.symlink_to(os.path.relpath(target, root))
            os.replace(tmp, link)
        except OSError:  # a file system without links: the run itself is unaffected
            tmp.unlink(missing_ok=True)
        return


#: files a run writes before its experiment starts (a run refused at start leaves only these)
_START_FILES = {".hydra", "metrics.json", "run.mcap", ".bionav.lock", "error.log"}


def forget_refused(run_dir: Path, *, existed: bool, job_log: str) -> bool:
    """Remove the directory of a run refused at start (it holds only what Hydra and the start wrote).

    ``existed``: the directory was there before this command (then nothing is removed). Returns
    True when the directory was removed; ``outputs/latest`` then points at the run before, if any.
    """
    if existed or not run_dir.is_dir():
        return False
    names = {p.name for p in run_dir.iterdir()}
    if not names <= _START_FILES | {job_log}:
        return False
    shutil.rmtree(run_dir, ignore_errors=True)
    outputs = Path.cwd() / "outputs"
    link = outputs / LATEST
    if link.is_symlink() and not link.exists():  # it pointed here: back to the newest run left, if any
        runs = sorted(p for p in outputs.glob("*/*") if p.is_dir() and not p.is_symlink())
        if runs:
            point_latest(runs[-1])
        else:
            link.unlink(missing_ok=True)
    date = run_dir.absolute().parent
    if date.parent == outputs:  # the default outputs/<date>/<time>: an empty date folder (and outputs/) goes too
        for folder in (date, outputs):
            try:
                folder.rmdir()
            except OSError:
                break
    return True
