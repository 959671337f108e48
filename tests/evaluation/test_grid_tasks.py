"""Issue 29 item 1: a grid-homing run split into tasks by snapshots gives the unsplit run's results.

The tasks (``experiment.block=[i,n]``) run through ``python -m bionav`` on the thesis runner's
pool, ``python -m bionav.experiments.merge`` joins them; AAE*, MAE*, RR*, the
compass AAE, the pair count and per_snapshot.csv must equal the unsplit run's exactly.
"""

from __future__ import annotations

import json

import pytest
from helpers import round_room, run_bionav

from bionav.db.export import export_database
from bionav.thesis.runs import Runner, RunSpec, index_runs, tool_env

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def folder_db(tmp_path_factory) -> list[str]:
    """The round room (19 cells, one missing) exported as a Vardy folder: its db overrides."""
    return export_database(round_room(), tmp_path_factory.mktemp("grid_tasks") / "db")


def test_split_run_merges_to_the_unsplit_results(folder_db, tmp_path):
    overrides = (*folder_db, "homing=minwarping")
    whole = run_bionav(*overrides, f"hydra.run.dir={tmp_path / 'whole'}", "workers=1", cwd=tmp_path)
    assert whole.returncode == 0, whole.stderr[-2000:]
    expected = json.loads((tmp_path / "whole" / "metrics.json").read_text())

    out = tmp_path / "report"
    runner = Runner(out=out, jobs=2, echo=lambda s: None, env=tool_env())
    spec = RunSpec(overrides, group="grid", blocks=3)
    result = runner.run_all([spec])[spec.key]
    assert result.ok, result.error
    merged = json.loads((result.dir / "metrics.json").read_text())
    for key in ("aae", "mae", "rr", "compass_aae", "n_pairs", "n_images", "homing", "db"):
        assert merged[key] == expected[key], key  # bit for bit: the same numbers in the same order
    assert merged["tasks"] == 3
    assert (result.dir / "per_snapshot.csv").read_text() == (tmp_path / "whole" / "per_snapshot.csv").read_text()
    assert (result.dir / "plots" / "per_snapshot.png").is_file()
    assert index_runs(out)[spec.key] == result.dir  # the merged directory reads as the unsplit run

    # a lost task reruns alone: delete one task's results, run again
    tasks = sorted((out / "runs" / "grid-tasks").glob("*/metrics.json"))
    assert len(tasks) == 3
    tasks[1].unlink()
    for d in out.rglob("metrics.json"):
        if d.parent == result.dir:
            d.unlink()  # the merged run too, so that the runner has to rebuild it
    lines = []
    again = Runner(out=out, jobs=2, echo=lines.append, env=tool_env()).run_all([spec])[spec.key]
    assert again.ok and json.loads((again.dir / "metrics.json").read_text())["aae"] == expected["aae"]
    assert any("2 found completed" in line and "1 to run" in line for line in lines), lines


def test_merge_refuses_an_incomplete_split(folder_db, tmp_path):
    overrides = (*folder_db, "homing=mfdid")
    for i in (0, 2):
        proc = run_bionav(*overrides, f"experiment.block=[{i},3]", f"hydra.run.dir={tmp_path / f'b{i}'}",
                          cwd=tmp_path)
        assert proc.returncode == 0, proc.stderr[-2000:]
    merge = run_bionav(str(tmp_path / "m"), str(tmp_path / "b0"), str(tmp_path / "b2"), cwd=tmp_path,
                       module="bionav.experiments.merge")
    assert merge.returncode == 2 and "Traceback" not in merge.stderr
    assert "missing or mixed blocks [(1, 3)]" in merge.stderr
    bad = run_bionav(*overrides, "experiment.block=[3,3]", f"hydra.run.dir={tmp_path / 'bad'}", cwd=tmp_path)
    assert bad.returncode != 0 and "Traceback" not in bad.stderr and "0 <= i < n" in bad.stderr


def test_cross_db_units_cover_every_pair_and_snapshot_once():
    """Known answer: up to as many tasks as snapshots, task i holds every n-th snapshot for all pairs
    (the old split); beyond, every n-th (snapshot, pair) unit, balanced, each exactly once."""
    from bionav.experiments.cross_db.run import task_units

    snaps = [3, 7, 11]
    whole = task_units(None, snaps, 2)
    assert list(whole) == [(0, 0), (0, 1), (1, 0), (1, 1)] and all(list(v) == snaps for v in whole.values())
    assert {p: list(v) for p, v in task_units([1, 2], snaps, 2).items()} == {p: [7] for p in whole}
    # 3 snapshots x 4 pairs = 12 units in 5 tasks: units k = 1, 6, 11 for task 1
    assert {p: list(v) for p, v in task_units([1, 5], snaps, 2).items()} == {(0, 1): [3], (1, 0): [7], (1, 1): [11]}
    seen = {}
    sizes = []
    for i in range(12):
        part = task_units([i, 12], snaps, 2)
        sizes.append(sum(len(v) for v in part.values()))
        for p, v in part.items():
            for s in v:
                seen[(p, int(s))] = seen.get((p, int(s)), 0) + 1
    assert sizes == [1] * 12 and len(seen) == 12 and set(seen.values()) == {1}


@pytest.mark.parametrize("blocks", [3, 8])
def test_split_cross_db_run_merges_to_the_unsplit_results(tmp_path, blocks):
    """3 tasks: snapshot blocks for every pair; 8 tasks, more than the 6 snapshots: (snapshot, pair) units."""
    overrides = ("experiment=cross_db", "homing=mfdid", "experiment.family=[sim_original,sim_doorlit]",
                 "db.image_size=[120,18]", "experiment.snapshot_stride=8")
    cache = {"BIONAV_CACHE": str(tmp_path / "cache")}
    whole = run_bionav(*overrides, f"hydra.run.dir={tmp_path / 'whole'}", "workers=1", cwd=tmp_path, env=cache)
    assert whole.returncode == 0, whole.stderr[-2000:]
    expected = json.loads((tmp_path / "whole" / "metrics.json").read_text())

    spec = RunSpec(overrides, group="cross", blocks=blocks)
    result = Runner(out=tmp_path / "report", jobs=2, echo=lambda s: None,
                    env={**tool_env(), **cache}).run_all([spec])[spec.key]
    assert result.ok, result.error
    merged = json.loads((result.dir / "metrics.json").read_text())
    for key in ("aae", "mae", "rr", "n_databases", "n_snapshots", "homing"):
        assert merged[key] == expected[key], key
    assert merged["tasks"] == blocks and expected["n_snapshots"] == 6
    assert (result.dir / "cross_db.csv").read_text() == (tmp_path / "whole" / "cross_db.csv").read_text()
    assert (result.dir / "plots" / "cross_db.png").is_file()


def test_merge_of_no_run_is_one_clear_message(tmp_path):
    (tmp_path / "empty").mkdir()
    for args in ([str(tmp_path / "m"), str(tmp_path / "nowhere")], [str(tmp_path / "m"), str(tmp_path / "empty")]):
        proc = run_bionav(*args, cwd=tmp_path, module="bionav.experiments.merge")
        assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr
        assert "is not a run directory" in proc.stderr and args[1] in proc.stderr
    assert not (tmp_path / "m").exists()  # nothing written for a refused merge
