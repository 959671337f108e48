"""Hydra callback writing summary.csv / summary.md at the end of every multirun."""

from __future__ import annotations

import logging
from pathlib import Path
from typing import Any

from hydra.experimental.callback import Callback
from omegaconf import DictConfig

log = logging.getLogger(__name__)


class SweepSummary(Callback):
    """Writes the sweep's summary table, failed jobs included, after the last job."""

    def on_multirun_end(self, config: DictConfig, **kwargs: Any) -> None:
        from bionav.report.summary import write_summary

        sweep_dir = Path(str(config.hydra.sweep.dir))
        if not sweep_dir.is_dir():
            return
        csv_path, md_path, rows = write_summary(sweep_dir)
        from bionav.report.sections import extra_sections

        sections = extra_sections(sweep_dir, rows)  # comparisons, parameter-homing rankings
        if sections:
            md_path.write_text(md_path.read_text() + "\n" + "\n\n".join(sections) + "\n")
        failed = [r["job"] for r in rows if r.get("status") != "completed"]
        log.info("summary of %d jobs written to %s and %s", len(rows), csv_path, md_path)
        if failed:
            log.warning("%d job(s) failed: %s (see their metrics.json)", len(failed), ", ".join(failed))
