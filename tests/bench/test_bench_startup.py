"""``python -m bionav.bench.startup``: the start-up timings of issue 28 (targets live in the bench, not here)."""

import json

import pytest
from helpers import run_bionav


@pytest.mark.slow
def test_startup_bench_times_help_cfg_and_completion(tmp_path):
    proc = run_bionav("--json", "--repeat", "1", cwd=tmp_path, module="bionav.bench.startup")
    assert proc.returncode == 0, proc.stderr
    rows = {r["benchmark"]: r for r in map(json.loads, proc.stdout.splitlines())}
    assert set(rows) == {"help", "cfg_job", "tab_group", "tab_key"}
    for r in rows.values():
        assert 0 < r["cpu_s"] and 0 < r["wall_s"] and r["rounds"] == 1
    # the group completion is answered without Hydra: less CPU than composing the config
    assert rows["tab_group"]["cpu_s"] < rows["cfg_job"]["cpu_s"]
