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


@pytest.mark.slow
def test_offsets_without_the_route_itself_are_refused_before_the_run(tmp_path):
    """experiment.offsets_m must include 0: RouteHomingConfig.validate, checked where the config enters."""
    proc = run_bionav("experiment=route_homing", "experiment.offsets_m=[-0.2,0.2]", f"hydra.run.dir={tmp_path / 'run'}",
                      cwd=tmp_path)
    assert_fails_cleanly(proc, "experiment.offsets_m=[-0.2, 0.2] must include 0 (the route itself)",
                         "experiment.offsets_m=[-0.2,0.0,0.2]", code=2)
    assert not (tmp_path / "run").exists() or not any((tmp_path / "run").iterdir())  # no run directory written
