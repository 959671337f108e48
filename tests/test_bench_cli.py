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
