"""``experiment=route_homing`` with a tiny step (issue 32): the number of route views and of agent steps
is bounded before any rendering, so a step of 1e-4 m is one clean message, not a run that never ends."""

from __future__ import annotations

import pytest
from helpers import assert_fails_cleanly, run_bionav


@pytest.mark.parametrize("override, needles", [
    ("db.step_m=1e-4", ("db.step_m=0.0001", "views along", "Ant1_Route1", "default 0.1")),
    ("experiment.agent_step_m=1e-4", ("experiment.agent_step_m=0.0001", "steps on Ant1_Route1", "experiment.agent_step_m >=")),
])
@pytest.mark.slow
def test_a_tiny_step_is_refused_before_rendering(tmp_path, override, needles):
    proc = run_bionav("experiment=route_homing", "db=seville_route", override, f"hydra.run.dir={tmp_path / 'run'}",
                      cwd=tmp_path, timeout=300)
    assert_fails_cleanly(proc, *needles, code=2, max_seconds=120)
    assert not (tmp_path / "cache").exists() or not any((tmp_path / "cache").rglob("*.npz"))  # nothing rendered
