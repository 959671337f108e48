"""Issue 29 item 3: ``python -m bionav.thesis --plan``: tasks, their CPU, critical path, wall time."""

import json

import pytest
from helpers import run_bionav

from bionav.thesis import plan as plan_mod
from bionav.thesis.runs import RunSpec


def _fixed(images: int, homing: str, size=plan_mod.DEFAULT_SIZE) -> float:
    """Hand-computed fixed part of a task: start-up, loading the database(s), per-image work."""
    return (plan_mod.RUN_START_S + images * size[0] * size[1] / 1e6 * plan_mod.DB_LOAD_S_PER_MPX
            + images * plan_mod.PREPARE_MS.get(homing, 0.0) / 1e3)


def test_grid_task_cpu_is_start_up_plus_home_vectors_times_the_unit_cost():
    ms = plan_mod.HOME_VECTOR_MS["minwarping"][0]
    start = _fixed(170, "minwarping")
    spec = RunSpec(("experiment=grid_homing", "db=sim_original", "homing=minwarping", "experiment.snapshots=[0,5,9]"))
    est = plan_mod.task_cpu_s(spec)
    assert est.cpu_s == pytest.approx(start + 3 * 170 * ms / 1e3)  # sim_original: a 10 x 17 grid
    split = RunSpec(spec.overrides, blocks=3).tasks()
    assert [plan_mod.task_cpu_s(t).cpu_s for t in split] == pytest.approx([start + 170 * ms / 1e3] * 3)
    # two tasks of three snapshots: every 2nd from the 0th (2 snapshots) and from the 1st (1), not 2 and 2
    split = RunSpec(spec.overrides, blocks=2).tasks()
    assert [plan_mod.task_cpu_s(t).cpu_s for t in split] == pytest.approx([start + 2 * 170 * ms / 1e3,
                                                                          start + 1 * 170 * ms / 1e3])


def test_blocks_hold_every_nth_item_as_the_experiments_split_them():
    """Hand-computed: 170 snapshots in 64 tasks are 42 tasks of 3 and 22 of 2 (ceil(170/64) = 3 for all
    charged 192); the shares always add up to the whole."""
    from bionav.experiments.tasks import block_of

    shares = [plan_mod.block_share(170, [i, 64]) for i in range(64)]
    assert shares == [3] * 42 + [2] * 22 and sum(shares) == 170
    for total, n in ((7, 3), (144, 16), (144, 5), (10, 10)):
        got = [plan_mod.block_share(total, [i, n]) for i in range(n)]
        assert got == [len(block_of([i, n], range(total), what="x")) for i in range(n)] and sum(got) == total
    assert plan_mod.block_share(5, None) == 5


def test_cross_db_tasks_by_unit_hold_every_nth_unit():
    """6 databases (36 pairs) x 4 snapshots = 144 (snapshot, pair) units; 5 tasks hold 29, 29, 29, 29, 28."""
    fam = "experiment.family=[sim_original,sim_arboreal,sim_chairs,sim_doorlit,sim_screen,sim_winlit]"
    spec = RunSpec(("experiment=cross_db", "homing=warping2d", fam, "experiment.snapshot_stride=9"), blocks=5)
    ms = plan_mod.HOME_VECTOR_MS["warping2d"][0]
    cpu = [plan_mod.task_cpu_s(t).cpu_s - _fixed(6 * 170, "warping2d") for t in spec.tasks()]
    assert cpu == pytest.approx([u * 170 * ms / 1e3 for u in (29, 29, 29, 29, 28)])


def test_costs_scale_with_the_machine_factors():
    spec = RunSpec(("experiment=grid_homing", "db=sim_original", "homing=warping2d", "experiment.snapshots=[0]"))
    base = plan_mod.task_cpu_s(spec)
    f = {"minwarping": 3.0, "warping2d": 2.0, "sift": 5.0, "python": 0.5, "source": "test"}
    scaled = plan_mod.task_cpu_s(spec, f)
    start = _fixed(170, "python")  # start-up and database: the python family; home vectors and per-image work: warping2d
    assert scaled.cpu_s == pytest.approx(start * 0.5 + (base.cpu_s - start) * 2.0)
    assert scaled.render_cpu_s == pytest.approx(base.render_cpu_s * 0.5)


def test_sift_is_costed_by_keypoints_not_pixels():
    """Half the width and height: a quarter of the pixels, but the keypoints (and their square) fall less."""
    big = plan_mod.sift_costs((1122, 162))
    small = plan_mod.sift_costs((561, 81))
    kp_ratio = plan_mod.keypoints_per_image((561, 81)) / plan_mod.keypoints_per_image((1122, 162))
    assert kp_ratio == pytest.approx(0.25 ** plan_mod.SIFT_KEYPOINTS_EXPONENT)
    assert small[0] / big[0] == pytest.approx(kp_ratio ** 2)  # matching: keypoints of both images
    assert small[1] / big[1] == pytest.approx(0.25 ** plan_mod.SIFT_IMAGE_EXPONENT)  # detection: pixels
    assert plan_mod.keypoints_per_image((561, 81), histeq=True) > plan_mod.keypoints_per_image((561, 81))


def test_schedule_longest_first_after_the_renders(monkeypatch):
    """Hand-computed: a 4 s render, then tasks of 10, 6, 6 and 4 s (one needs no render) on 2 slots."""
    costs = {"a": (10.0, ("db1",)), "b": (6.0, ("db1",)), "c": (6.0, ()), "d": (4.0, ())}

    def fake(spec, factors=None):
        name = spec.overrides[0]
        cpu, render = costs[name]
        return plan_mod.TaskEstimate(name, "x", cpu, "test", render, 4.0 if render else 0.0)

    monkeypatch.setattr(plan_mod, "task_cpu_s", fake)
    specs = [RunSpec((n,)) for n in costs]
    p = plan_mod.make_plan(specs, nodes=1, cores=2)
    assert p["n_tasks"] == 4 and p["largest_task_cpu_s"] == 10.0
    assert p["total_cpu_s"] == pytest.approx(26.0 + 4.0)
    assert p["critical_path_s"] == pytest.approx(14.0)  # render 4 s, then a (10 s)
    # slot 1: render 0-4, a 4-14; slot 2: c 0-6 (b waits for the render: starts at 6), b 6-12, d 12-16
    assert p["expected_wall_s"] == pytest.approx(16.0)
    assert plan_mod.make_plan(specs, nodes=4, cores=1)["expected_wall_s"] == pytest.approx(14.0)


@pytest.mark.slow
def test_plan_command_prints_json_and_refuses_bad_sizes(tmp_path):
    proc = run_bionav("--preset", "tiny", "--plan", "--nodes", "2", "--cores", "4", "--json", cwd=tmp_path,
                      module="bionav.thesis")
    assert proc.returncode == 0, proc.stderr
    p = json.loads(proc.stdout)
    assert {"tasks", "largest_task_cpu_s", "total_cpu_s", "critical_path_s", "expected_wall_s"} <= set(p)
    assert p["slots"] == 8 and p["n_tasks"] == len(p["tasks"]) > 0
    assert p["largest_task_cpu_s"] == max(t["cpu_s"] for t in p["tasks"])
    assert p["expected_wall_s"] >= p["critical_path_s"] > 0
    assert not list(tmp_path.glob("*report*"))  # a plan runs and writes nothing
    text = run_bionav("--preset", "full", "--only", "table5_4", "--plan", cwd=tmp_path, module="bionav.thesis")
    assert text.returncode == 0 and "expected wall time" in text.stdout and "experiment.block=[0,64]" in text.stdout
    bad = run_bionav("--preset", "tiny", "--plan", "--nodes", "0", cwd=tmp_path, module="bionav.thesis")
    assert bad.returncode == 2 and "Traceback" not in bad.stderr and "--nodes 0" in bad.stderr
    no_out = run_bionav("--preset", "tiny", "--only", "table3_1", cwd=tmp_path, module="bionav.thesis")
    assert no_out.returncode == 2 and "--out DIR is needed" in no_out.stderr


def test_run_costs_scale_with_the_size_the_overrides_give():
    """Start-up plus the measured unit cost times the run's size (hand-computed from RUN_CPU_S)."""
    c = {k: v[0] for k, v in plan_mod.RUN_CPU_S.items()}
    scan = RunSpec(("experiment=contrast_scan", "experiment.times=[2009-06-17T10:00:00+02:00,2009-06-17T11:00:00+02:00]",
                    "experiment.n_pan=10", "experiment.n_tilt=3"))
    assert plan_mod.task_cpu_s(scan).cpu_s == pytest.approx(c["contrast_scan_start"] + 2 * 30 * c["contrast_scan_direction"])
    lda = RunSpec(("experiment=contrast_lda", "data=sim_natural", "experiment.n_resamples=2000"))
    assert plan_mod.task_cpu_s(lda).cpu_s == pytest.approx(c["contrast_lda_start"] + 2000 * c["contrast_lda_resample"])
    sky = [plan_mod.task_cpu_s(RunSpec(("experiment=skyline_homing", "homing=sift", f"experiment.snapshot_stride={s}")))
           for s in (2, 4)]
    assert sky[0].cpu_s - c["skyline_homing_start"] == pytest.approx(4 * (sky[1].cpu_s - c["skyline_homing_start"]))
    cleaning = RunSpec(("experiment=cleaning", "layout=long_lanes", "runs=4"))
    assert plan_mod.task_cpu_s(cleaning).cpu_s == pytest.approx(c["cleaning_start"] + 4 * c["cleaning_run"])


def test_a_database_without_a_preset_grid_gets_an_assumed_one_not_an_error():
    """A folder database knows its grid only once read: the estimate assumes one and says so (the pool
    sorts every task by its estimate, so an estimate must never stop a run)."""
    ms = plan_mod.HOME_VECTOR_MS["mfdid"][0] * 64 * 16 / (288 * 50)  # mfdid scales with the pixels
    nx, ny = plan_mod.ASSUMED_GRID
    for db in ("folder", "no_such_database"):
        est = plan_mod.task_cpu_s(RunSpec(("experiment=grid_homing", f"db={db}", "homing=mfdid",
                                           "db.image_size=[64,16]", "experiment.snapshots=[0,1]")))
        assert est.cpu_s == pytest.approx(_fixed(nx * ny, "mfdid", (64, 16)) + 2 * nx * ny * ms / 1e3)
        assert f"grid of {db} assumed {nx} x {ny}" in est.basis


def test_plan_for_another_machine_through_the_command(tmp_path):
    """--cpu-factor scales every figure; --calibrate --json writes the file --calibration reads (issue 42)."""
    def plan(*extra):
        proc = run_bionav("--preset", "tiny", "--only", "table5_3", "--plan", "--json", *extra, cwd=tmp_path,
                          module="bionav.thesis")
        assert proc.returncode == 0, proc.stderr
        return json.loads(proc.stdout)

    one, two = plan("--cpu-factor", "1"), plan("--cpu-factor", "2")
    assert two["total_cpu_s"] == pytest.approx(2 * one["total_cpu_s"])
    assert two["cpu_factors"]["source"] == "--cpu-factor 2"
    cal = run_bionav("--calibrate", "--json", cwd=tmp_path, module="bionav.thesis")
    assert cal.returncode == 0, cal.stderr
    (tmp_path / "here.json").write_text(cal.stdout)
    here = plan("--calibration", str(tmp_path / "here.json"))
    assert "calibration of" in here["cpu_factors"]["source"] and here["total_cpu_s"] > 0
    bad = run_bionav("--preset", "tiny", "--plan", "--calibration", str(tmp_path / "nope.json"), cwd=tmp_path,
                     module="bionav.thesis")
    assert bad.returncode == 2 and "Traceback" not in bad.stderr and "--calibrate --json" in bad.stderr
