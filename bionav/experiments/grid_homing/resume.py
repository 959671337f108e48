"""Continuing an interrupted ``experiment=grid_homing`` run (``bionav.resume=true``) from its logged rows."""

from __future__ import annotations

import dataclasses
import logging
import re
from typing import Any, Sequence

import numpy as np

from bionav.logs.reader import read_recorded_messages

log = logging.getLogger(__name__)

#: the topic each finished snapshot row is logged on (see ``run._row_loggers``)
ROWS_TOPIC = "/grid_homing/snapshot_rows"


def nan_floats(values: Sequence[Any]) -> np.ndarray:
    """``values`` as floats, ``None`` (a JSON null) as NaN."""
    return np.array([np.nan if v is None else float(v) for v in values], dtype=float)


def resumed_rows(ctx, db, wanted: list[int], *, resume: bool) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """With ``resume`` (``bionav.resume=true``): the snapshot rows an earlier attempt of this run logged.

    Returns ``{snapshot index: (angles (N,), compass error (N,))}`` in radians (NaN: none). The runner
    kept that attempt's log as ``run.attempt-<n>.mcap`` (the newest counts); its complete
    ``/grid_homing/snapshot_rows`` messages are read, also from a log a SIGKILL cut off. One row is always
    left to compute (its per-image work gives the timing and the per-image statistics).
    """
    if not resume:
        return {}
    attempts = sorted(ctx.dir.glob("run.attempt-*.mcap"), key=lambda p: int(re.sub(r"\D", "", p.name) or 0))
    if not attempts:
        return {}
    cell = {tuple(p): i for i, p in enumerate(np.asarray(db.positions).tolist())}
    rows = {}
    for _topic, msg in read_recorded_messages(attempts[-1], [ROWS_TOPIC]):
        si = cell.get(tuple(msg.get("snapshot") or ()))
        angles = nan_floats(msg.get("angles") or [])
        if si in wanted and angles.shape == (len(db),):
            compass = msg.get("compass_error")
            rows[si] = (angles, nan_floats(compass) if compass and len(compass) == len(db)
                        else np.full(len(db), np.nan))
    if len(rows) == len(wanted):  # every row was logged: the last one is computed again (timing, statistics)
        rows.pop(wanted[-1])
    if rows:
        log.info("resume: %d of %d snapshot rows come from the earlier attempt (%s); computing the other %d",
                 len(rows), len(wanted), attempts[-1].name, len(wanted) - len(rows))
    return rows


def with_resumed_rows(hv, done: dict, wanted: list[int]):
    """``hv`` (the rows computed now) with the resumed rows ``done``, in the order of ``wanted``."""
    if not done:
        return hv
    new = {int(si): k for k, si in enumerate(hv.snapshot_index)}
    angles = np.stack([hv.angles[new[si]] if si in new else done[si][0] for si in wanted])
    compass = None if hv.compass_error is None else np.stack(
        [hv.compass_error[new[si]] if si in new else done[si][1] for si in wanted])
    return dataclasses.replace(hv, snapshot_index=np.asarray(wanted, dtype=np.int64), angles=angles,
                               compass_error=compass)
