"""``hydra/launcher=submitit_slurm`` that survives cancelled and killed jobs.

Hydra's submitit launcher waits for every job's result file. A job that SLURM
cancels or kills never writes one: with accounting (sacct) the launcher then
raises and the whole sweep ends without a summary; for a task cancelled while
pending, or without accounting, it waits forever. bionav registers this
subclass under the same config name (``submitit_slurm``, same options), so the
documented command is unchanged. It

* watches the jobs itself: a job is finished when its result file exists, when
  submitit's accounting says so, or when it has left the SLURM queue
  (``squeue``) and no result file appeared within ``bionav_grace_s`` seconds;
* turns every job that ended without a result into a *failed* job: its
  ``metrics.json`` says ``"status": "failed"`` with the SLURM state (e.g.
  ``CANCELLED by 0``) unless the job recorded a result itself, and its
  ``.hydra/overrides.yaml`` is written if the job never started, so the sweep's
  summary has one failed row per cancelled job and ``bionav.resume=true`` runs
  it again;
* returns the objective's worst value for it (docs/tuning.md), so a sweeper
  such as Optuna ranks it last instead of stopping.
"""

from __future__ import annotations

import logging
import os
import subprocess
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

from hydra.core.singleton import Singleton
from hydra.core.utils import JobReturn, JobStatus, filter_overrides
from hydra_plugins.hydra_submitit_launcher.config import BaseQueueConf, SlurmQueueConf
from hydra_plugins.hydra_submitit_launcher.submitit_launcher import SlurmLauncher
from omegaconf import OmegaConf, open_dict

log = logging.getLogger(__name__)


@dataclass
class BionavSlurmQueueConf(SlurmQueueConf):
    """Hydra's ``submitit_slurm`` options plus how bionav watches the jobs."""

    _target_: str = "hydra_plugins.bionav_slurm.BionavSlurmLauncher"
    # seconds between checks of the queue (squeue) and of the result files
    bionav_poll_s: float = 2.0
    # seconds a job may be gone from the queue before a missing result counts as failed
    bionav_grace_s: float = 10.0


def queued_job_ids() -> set[str] | None:
    """Ids of the jobs in the SLURM queue (array tasks as ``<array>_<task>``); None if squeue fails."""
    try:
        proc = subprocess.run(["squeue", "-h", "-r", "-o", "%i"], capture_output=True, text=True, errors="replace", timeout=60)
    except (OSError, subprocess.TimeoutExpired):
        return None
    if proc.returncode != 0:
        return None
    return {line.strip() for line in proc.stdout.splitlines() if line.strip()}


def slurm_state(job: Any) -> str:
    """A finished job's SLURM state (``COMPLETED``, ``CANCELLED by 0``, ...): sacct, else scontrol, else UNKNOWN."""
    try:
        state = job.watcher.get_state(job.job_id, mode="force")
    except Exception:  # accounting unavailable
        state = "UNKNOWN"
    if state != "UNKNOWN":
        return state
    try:  # without accounting slurmctld still knows finished jobs for MinJobAge seconds
        proc = subprocess.run(["scontrol", "show", "job", "-o", str(job.job_id)], capture_output=True, text=True,
                              errors="replace", timeout=60)
    except (OSError, subprocess.TimeoutExpired):
        return state
    for field in proc.stdout.split():
        if field.startswith("JobState="):
            return field.partition("=")[2]
    return state


class BionavSlurmLauncher(SlurmLauncher):
    """Hydra's submitit SLURM launcher with cancelled/killed jobs recorded as failed (module docstring).

    Hydra instantiates launchers only from classes registered under the
    ``hydra_plugins`` package name, which bionav does not install (editable
    installs cannot extend that namespace package reliably): :func:`register`
    registers this class under the module name ``hydra_plugins.bionav_slurm``
    (an alias of this module's class in ``sys.modules``). The jobs on the
    nodes only call :meth:`__call__`, inherited unchanged, so the launcher is
    pickled as Hydra's own :class:`SlurmLauncher` (:meth:`__reduce__`).
    """

    def __init__(self, **params: Any) -> None:
        self.poll_s = float(params.pop("bionav_poll_s", 2.0))
        self.grace_s = float(params.pop("bionav_grace_s", 10.0))
        super().__init__(**params)

    def __reduce__(self):
        return (_plain_launcher, (self.__dict__,))

    def launch(self, job_overrides: Sequence[Sequence[str]], initial_job_idx: int) -> Sequence[JobReturn]:
        import submitit

        if self.config is None:
            raise RuntimeError("the SLURM launcher was not set up by Hydra (setup() was not called)")
        own_keys = {"submitit_folder", "max_num_timeout"}
        executor = submitit.AutoExecutor(
            cluster=self._EXECUTOR,
            folder=self.params["submitit_folder"],
            slurm_max_num_timeout=self.params.get("max_num_timeout", 0),
        )
        shared = set(OmegaConf.structured(BaseQueueConf).keys())  # the rest are slurm_<name> for submitit
        executor.update_parameters(
            **{(k if k in shared else f"slurm_{k}"): v for k, v in self.params.items() if k not in own_keys}
        )
        sweep_dir = Path(str(self.config.hydra.sweep.dir))
        sweep_dir.mkdir(parents=True, exist_ok=True)
        if "mode" in self.config.hydra.sweep:
            os.chmod(sweep_dir, mode=int(str(self.config.hydra.sweep.mode), 8))
        log.info("Submitit 'slurm' sweep output dir : %s", sweep_dir)
        arguments = []
        for num, overrides in enumerate(job_overrides, start=initial_job_idx):
            log.info("\t#%d : %s", num, " ".join(filter_overrides(overrides)))
            arguments.append((list(overrides), "hydra.sweep.dir", num, f"job_id_for_{num}", Singleton.get_state()))
        jobs = executor.map_array(self, *zip(*arguments))
        finished = self._wait(jobs)
        returns = []
        for (overrides, _, num, _, _), job, has_ended in zip(arguments, jobs, finished):
            returns.append(self._job_return(job, overrides, num, ended_without_result=not has_ended))
        return returns

    # -- watching ---------------------------------------------------------------
    def _wait(self, jobs: list) -> list[bool]:
        """Wait until every job is finished; per job True if submitit knows it ended, False if it vanished."""
        done = [False] * len(jobs)
        vanished = [False] * len(jobs)
        gone_since: dict[int, float] = {}
        while not all(d or v for d, v in zip(done, vanished)):
            queued = queued_job_ids()
            now = time.monotonic()
            for i, job in enumerate(jobs):
                if done[i] or vanished[i]:
                    continue
                if job.done():
                    done[i] = True
                elif queued is not None and str(job.job_id) not in queued:
                    if now - gone_since.setdefault(i, now) >= self.grace_s:
                        vanished[i] = True
                else:
                    gone_since.pop(i, None)
            if not all(d or v for d, v in zip(done, vanished)):
                time.sleep(self.poll_s)
        return done

    def _job_return(self, job: Any, overrides: list[str], num: int, *, ended_without_result: bool) -> JobReturn:
        from submitit.core.utils import FailedJobError

        if not ended_without_result:
            try:
                return job.results()[0]
            except FailedJobError as exc:  # the job ran and raised (bionav's task catches its own errors)
                lines = [line for line in str(exc).strip().splitlines() if line.strip()]
                return self._failed_return(
                    overrides, num, f"SLURM job {job.job_id} raised an error: {lines[-1] if lines else exc!r}; its "
                    f"output is in {Path(job.paths.stdout).parent}.")
            except Exception as exc:  # no result file: cancelled, killed, timed out, out of memory
                reason = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        else:
            reason = "it left the queue without a result"
        state = slurm_state(job)
        started = Path(job.paths.stdout).exists()
        if not started and state == "UNKNOWN":
            message = f"SLURM job {job.job_id} was cancelled or removed from the queue before it started"
        else:
            message = (
                f"SLURM job {job.job_id} ended as {state} without a result ({reason}): it was cancelled or killed "
                f"(scancel, time or memory limit, node failure); its output is in {Path(job.paths.stdout).parent}"
            )
        return self._failed_return(overrides, num, message + ". Re-run the sweep with bionav.resume=true to run it again.")

    def _failed_return(self, overrides: list[str], num: int, message: str) -> JobReturn:
        from bionav.experiments.objective import objective_from_config
        from bionav.experiments.runner import is_completed
        from bionav.files import write_json_atomic

        if self.hydra_context is None or self.config is None:
            raise RuntimeError("the SLURM launcher was not set up by Hydra (setup() was not called)")
        sweep_config = self.hydra_context.config_loader.load_sweep_config(self.config, list(overrides))
        with open_dict(sweep_config.hydra.job):
            sweep_config.hydra.job.num = num
        job_dir = Path(str(sweep_config.hydra.sweep.dir)) / str(sweep_config.hydra.sweep.subdir)
        job_dir.mkdir(parents=True, exist_ok=True)
        record = job_dir / ".hydra" / "overrides.yaml"
        if not record.exists():
            record.parent.mkdir(exist_ok=True)
            record.write_text(OmegaConf.to_yaml(OmegaConf.create(list(overrides))))
        if not is_completed(job_dir):
            write_json_atomic(job_dir / "metrics.json", {"status": "failed", "error": message})
        log.error("job %d failed: %s", num, message)
        try:
            objective = objective_from_config(sweep_config.get("objective"))
        except Exception:
            objective = None
        ret = JobReturn(
            overrides=list(overrides),
            cfg=sweep_config,
            hydra_cfg=None,
            working_dir=str(job_dir),
            task_name=str(sweep_config.hydra.job.name),
            status=JobStatus.COMPLETED,
            _return_value=objective.worst if objective else None,
        )
        return ret


BionavSlurmLauncher.__module__ = "hydra_plugins.bionav_slurm"


def _plain_launcher(state: dict) -> SlurmLauncher:
    """Hydra's launcher with the given state: what a job on a node unpickles (it only calls it)."""
    launcher = SlurmLauncher.__new__(SlurmLauncher)
    launcher.__dict__.update(state)
    return launcher


def register(store=None) -> None:
    """Store this launcher as ``hydra/launcher=submitit_slurm`` (after Hydra's own plugin registered it).

    Called through the ``bionav.schemas`` entry point ``submitit_slurm`` with Hydra's ConfigStore.
    """
    import sys
    import types

    import hydra_plugins
    from hydra.core.config_store import ConfigStore
    from hydra.core.plugins import Plugins

    module = sys.modules.get(BionavSlurmLauncher.__module__)
    if module is None:  # what Hydra imports to instantiate the launcher (see the class docstring)
        module = types.ModuleType(BionavSlurmLauncher.__module__, "bionav's SLURM launcher (bionav.launcher)")
        module.BionavSlurmLauncher = BionavSlurmLauncher
        sys.modules[module.__name__] = module
        setattr(hydra_plugins, module.__name__.rpartition(".")[2], module)
    Plugins.instance().register(BionavSlurmLauncher)

    ConfigStore.instance().store(
        group="hydra/launcher", name="submitit_slurm", node=BionavSlurmQueueConf(), provider="bionav"
    )
