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
    (["--threads", "0"], "--threads 0 is out of range: it must lie in 1..64"),
    (["--compass-fraction", "0"], "--compass-fraction 0.0 must lie in (0, 1]"),
    (["--method", "nope"], "invalid choice"),
])
def test_bench_rejects_bad_arguments(capsys, argv, message):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    assert message in capsys.readouterr().err


@pytest.mark.slow
def test_bench_whole_runs_print_cpu_and_wall(capsys, tmp_path):
    """--method sweep / cleaning run the documented commands (tiny inputs here) and report their times."""
    from helpers import write_tiny_folder

    folder = write_tiny_folder(tmp_path / "tiny", shape=(16, 64), sigma=2.0)
    assert main(["--json", "--method", "sweep", "--sweep-grid", "ci", "--dbs", "folder", "--override", f"db.path={folder}",
                 "--override", "experiment.grids.ci.signature='mean,fc'"]) == 0
    (row,) = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert row["method"] == "sweep" and row["variant"] == "ci_warm" and row["dbs"] == ["folder"]
    assert row["configurations"] == 2 + 2  # [mean] at 2 ring counts, [fc] at 2 numbers of coefficients
    assert row["cpu_s"] > 0 and row["wall_s"] > 0 and len(row["loadavg_1min"]) == 2
    assert row["command"].startswith("python -m bionav -m experiment=param_sweep_grid experiment.grid=ci db=folder")
    assert main(["--json", "--method", "cleaning", "--runs", "2", "--override", "experiment.vision=oracle",
                 "--override", "layout.n_lanes=2", "--override", "layout.lane_length=1.0"]) == 0
    (row,) = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert row["method"] == "cleaning" and row["runs"] == 2 and row["workers"] == 2
    assert row["cpu_s"] > 0 and row["wall_s"] > 0 and 0 < row["coverage"] <= 1


def test_bench_sift_times_a_small_grid_per_variant(capsys):
    argv = ["--method", "sift", "--json", "--images", "4", "--sift-size", "281", "41", "--threads", "2"]
    assert main(argv) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert [(r["variant"], r["threads"]) for r in rows] == [("plain", 1), ("plain", 2), ("histeq", 1), ("histeq", 2)]
    rows = rows[1::2]  # --threads 2 (each variant also timed with 1 worker, alternately)
    for r in rows:
        assert r["method"] == "sift" and r["threads"] == 2 and r["image"] == "281x41" and r["db"] == "sim_original"
        assert r["workers_speedup"] > 0
        assert r["n_images"] == 4 and r["n_pairs"] == 12 and r["rounds"] == 1
        assert 0 < r["keypoints_per_image"]["min"] <= r["keypoints_per_image"]["mean"] <= r["keypoints_per_image"]["max"]
        assert r["pairs_cpu_s"] > 0 and r["grid_wall_s"] >= r["pairs_wall_s"] > 0
        assert r["cpu_ms_per_home_vector"] == pytest.approx(1e3 * r["pairs_cpu_s"] / 12, rel=0.01, abs=1e-3)
    # histogram equalisation spreads the grey levels: more keypoints
    assert rows[1]["keypoints_per_image"]["mean"] > rows[0]["keypoints_per_image"]["mean"]


@pytest.mark.parametrize("argv, message", [
    (["--method", "sift", "--variants", "plain,nope"], "--variants must be a comma-separated list of plain, histeq"),
    (["--method", "sift", "--images", "1"], "--images must be >= 2"),
    (["--method", "sift", "--sift-size", "4", "41"], "--sift-size 4 41 is out of range: W must lie in 8..4096"),
])
def test_bench_sift_rejects_bad_arguments(capsys, argv, message):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    assert message in capsys.readouterr().err


@pytest.mark.slow
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


@pytest.mark.slow
def test_bench_sweep_with_more_workers_than_cpus(tmp_path):
    """Issue 29: `--method sweep --workers N` with N > CPUs completes; the pool has min(tasks, CPUs) processes."""
    import os
    import subprocess
    import sys

    from helpers import write_tiny_folder

    from bionav.machine import usable_cpus

    folder = write_tiny_folder(tmp_path / "tiny", shape=(16, 64), sigma=2.0)
    cpus = usable_cpus()
    argv = ["--json", "--method", "sweep", "--sweep-grid", "full", "--dbs", "folder", "--workers", str(cpus + 2),
            "--override", f"db.path={folder}", "--override", "experiment.grids.full.signature='mean'",
            "--override", "experiment.grids.full.image_size='[32,8],[64,16]'",
            "--override", "experiment.grids.full.preprocess='none,he'",
            "--override", "experiment.rings=[5]"]
    env = dict(os.environ, BIONAV_CACHE=str(tmp_path / "cache"))
    proc = subprocess.run([sys.executable, "-m", "bionav.bench", *argv], capture_output=True, text=True, env=env,
                          timeout=900)
    assert proc.returncode == 0, proc.stderr[-3000:]
    (row,) = [json.loads(line) for line in proc.stdout.splitlines() if line.startswith("{")]
    assert row["workers"] == cpus + 2
    assert row["workers_used"] == [min(4, cpus)]  # 2 sizes x 2 preprocessings = 4 tasks
    assert row["configurations"] == 2 * 2 * 1  # [mean] at one ring count, per size and preprocessing


def test_bench_scaling_prints_growth_and_fixed_cost_per_run(capsys, tmp_path):
    """--method scaling (issue 42): CPU per home vector against the image size for every method (with the
    growth exponent), and whole runs with 1 and N snapshots (slope and fixed part)."""
    from helpers import write_tiny_folder

    folder = write_tiny_folder(tmp_path / "tiny", shape=(16, 64), sigma=2.0)
    assert main(["--json", "--method", "scaling", "--scaling-sizes", "32x8,64x16", "--steps", "8", "--repeat", "1",
                 "--batch", "1", "--db", "folder", "--override", f"db.path={folder}", "--scaling-snapshots", "2"]) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    pairs = [r for r in rows if r["table"] == "pairs"]
    assert {r["method"] for r in pairs} == {"minwarping", "warping2d", "warping1d", "hiss", "sift"}
    for r in pairs:
        assert r["cpu_ms_min"] > 0 and r["pixels"] in (32 * 8, 64 * 16)
        assert ("growth_exponent" in r) == (r["image"] == "64x16")
    runs = {r["method"]: r for r in rows if r["table"] == "runs"}
    assert set(runs) == {"minwarping", "sift"}
    for r in runs.values():
        assert r["home_vectors"] == [8, 16] and r["cpu_s"][1] > 0  # 9 cells: 8 other cells per snapshot
        slope = (r["cpu_s"][1] - r["cpu_s"][0]) / 8
        assert r["cpu_ms_per_home_vector"] == pytest.approx(1e3 * slope, abs=2.0)  # cpu_s rounded to 10 ms
        assert r["fixed_cpu_s"] == pytest.approx(r["cpu_s"][0] - 8 * slope, abs=0.05)


def test_bench_scaling_rejects_bad_sizes(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--method", "scaling", "--scaling-sizes", "288x50,abc"])
    assert exc.value.code == 2 and "--scaling-sizes" in capsys.readouterr().err


def test_bench_stages_sets_every_stage_against_its_floor(capsys):
    """--method stages (issue 42): byte-lane operations counted from the sizes, floor at the given clock."""
    assert main(["--json", "--method", "stages", "--size", "48", "16", "--steps", "16", "--repeat", "1", "--batch", "1",
                 "--clock-ghz", "2.0"]) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    by = {r["stage"]: r for r in rows}
    assert {"home vector, single", "home vector, compass", "home vector, double_fine"} <= set(by)
    per_ms = 64 * 2 * 2.0e6  # byte lanes per ms at 2 GHz, two 512-bit instructions per cycle
    d = by["distances (sums + normalisation)"]
    # K = 9 planes, R = 15 rows (16 - 1 for the edge filter), W = 48: 3 ops x 2 bytes per term, 6 x 4 per entry
    k, w = 9, 48
    r = (d["byte_lane_ops"] - k * w * w * 24) // (k * w * w * 6)
    assert d["byte_lane_ops"] == k * r * w * w * 6 + k * w * w * 24 and 8 <= r <= 16
    for row in rows:
        assert row["cpu_ms"] > 0 and row["clock_ghz"] == 2.0
        if row["byte_lane_ops"] is not None:
            assert row["floor_ms"] == pytest.approx(row["byte_lane_ops"] / per_ms, abs=1e-4)
        assert row["fraction_of_floor"] == pytest.approx(row["floor_ms"] / row["cpu_ms"], rel=0.01, abs=1e-3)
