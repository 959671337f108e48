"""The benchmark CLI: its JSON lines, its table and its argument errors (no timing targets here)."""

import json

import pytest

from bionav.bench.__main__ import main

TINY = ["--repeat", "1", "--batch", "2", "--steps", "24", "--size", "72", "12", "--render-size", "144", "24"]


@pytest.mark.parametrize("threads", [1, 2])
def test_bench_json_has_one_line_per_min_warping_variant(capsys, threads):
    assert main(["--json", "--method", "minwarping", "--threads", str(threads), *TINY]) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert [r["variant"] for r in rows] == ["single", "double_fine", "compass", "compass_double_fine"]
    for r in rows:
        assert r["method"] == "minwarping" and r["threads"] == threads and r["image"] == "72x12"
        assert r["steps"] == "24x24" and r["home_vectors_per_round"] == 2
        assert r["cpu_ms_per_home_vector"] > 0 and r["wall_ms_per_home_vector"] > 0
        assert r["cpu_ms_min"] <= r["cpu_ms_per_home_vector"] and r["wall_ms_min"] <= r["wall_ms_per_home_vector"]
        assert (r["compass_fraction"] == 0.3) == ("compass" in r["variant"])


def test_bench_table_and_background_load(capsys):
    assert main(["--method", "warping2d", "--background-load", "1", *TINY]) == 0
    out = capsys.readouterr().out
    lines = [line for line in out.splitlines() if line.startswith("| warping2d")]
    assert [line.split("|")[2].strip() for line in lines] == ["single", "compass"]
    assert "background load 1" in out


@pytest.mark.parametrize("argv, message", [
    (["--threads", "0"], "--threads must lie in 1.."),
    (["--compass-fraction", "0"], "--compass-fraction must lie in (0, 1]"),
    (["--method", "nope"], "invalid choice"),
])
def test_bench_rejects_bad_arguments(capsys, argv, message):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    assert message in capsys.readouterr().err


def test_bench_grid_mode_times_the_grid_runner_with_1_and_2_workers(capsys, tmp_path, monkeypatch):
    monkeypatch.setenv("BIONAV_CACHE", str(tmp_path))
    argv = ["--json", "--grid", "sim_original", "--grid-snapshots", "2", "--grid-rounds", "1", "--threads", "2",
            "--steps", "12", "--size", "36", "8"]
    assert main(argv) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert [(r["variant"], r["threads"]) for r in rows] == [
        (v, w) for v in ("single", "double_fine", "compass", "compass_double_fine") for w in (1, 2)]
    for r in rows:
        assert r["experiment"] == "grid_homing" and r["db"] == "sim_original" and r["snapshots"] == 2
        assert r["home_vectors_per_round"] == 2 * (170 - 1)  # every cell but the snapshot's own
        assert r["cpu_ms_per_home_vector"] > 0 and r["wall_ms_per_home_vector"] > 0
        assert r["workers_speedup"] > 0 and (r["threads"] == 2 or r["workers_speedup"] == 1.0)


def test_bench_grid_mode_names_an_unknown_database(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--grid", "no_such_db"])
    assert exc.value.code == 2
    assert "--grid no_such_db" in capsys.readouterr().err
