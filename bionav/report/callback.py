"""Hydra callback writing summary.csv / summary.md at the end of every multirun."""

from __future__ import annotations

import logging
from pathlib import Path
from typing import Any

from hydra.experimental.callback import Callback
from omegaconf import DictConfig

log = logging.getLogger(__name__)


#: the outcome of the last multirun in this process (``python -m bionav -m`` exits 1 when jobs failed)
LAST_SWEEP: dict[str, Any] = {}


def write_sweep_summary(sweep_dir: Path, *, objective: str | None = None) -> tuple[int, int, Path]:
    """Write summary.csv and summary.md (with comparison sections) of ``sweep_dir``.

    Returns
    -------
    n_jobs, n_failed, summary_md_path
    """
    from bionav.report.sections import extra_sections
    from bionav.report.summary import write_summary

    csv_path, md_path, rows = write_summary(sweep_dir, objective=objective)
    sections = extra_sections(sweep_dir, rows)  # comparisons, parameter-homing rankings
    if sections:
        md_path.write_text(md_path.read_text() + "\n" + "\n\n".join(sections) + "\n")
    failed = [r["job"] for r in rows if r.get("status") != "completed"]
    LAST_SWEEP.update(n_jobs=len(rows), n_failed=len(failed), failed=failed, summary=md_path)
    log.info("summary of %d jobs written to %s and %s", len(rows), csv_path, md_path)
    return len(rows), len(failed), md_path


class SweepSummary(Callback):
    """Writes the sweep's summary table, failed jobs included, after the last job."""

    def on_multirun_end(self, config: DictConfig, **kwargs: Any) -> None:
        from omegaconf import OmegaConf

        LAST_SWEEP.clear()
        sweep_dir = Path(str(config.hydra.sweep.dir))
        if not sweep_dir.is_dir():
            return
        write_sweep_summary(sweep_dir, objective=OmegaConf.select(config, "objective.metric", default=None))
        LAST_SWEEP["fail_on_job_error"] = bool(OmegaConf.select(config, "bionav.fail_on_job_error", default=True))
