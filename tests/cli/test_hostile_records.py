"""A run's record is never rewritten (issue 45): resume only the same configuration, stale locks settled as
interrupted, the user's files in --out kept, an export continued; the command lines that printed tracebacks.

Each refusal goes through :func:`helpers.assert_fails_cleanly`; where something was recorded before, every
file of it (bytes and modification time) is checked to be as it was.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers import REFUSAL_S, REPO, assert_fails_cleanly, run_bionav, run_tiny, source_copy



def snapshot(folder: Path) -> dict[str, tuple[bytes, int]]:
    """Every file below ``folder`` (hidden ones included): its bytes and modification time."""
    return {str(p.relative_to(folder)): (p.read_bytes(), p.stat().st_mtime_ns)
            for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.fixture(scope="module")
def finished(tiny, tmp_path_factory):
    root = tmp_path_factory.mktemp("finished")
    proc = run_tiny(tiny, f"hydra.run.dir={root / 'run'}", cwd=root)
    assert proc.returncode == 0, proc.stderr
    return root / "run"


@pytest.mark.parametrize(("args", "named"), [
    (["homing=hiss"], "homing.name (hiss asked for, mfdid recorded)"),
    (["seed=3"], "seed (3 asked for, 0 recorded)"),
    (["experiment=cross_db"], "experiment.name (cross_db asked for, grid_homing recorded)"),
])
def test_resume_with_another_configuration_is_refused_and_rewrites_nothing(finished, tiny, tmp_path, args, named):
    before = snapshot(finished)
    assert ".hydra/config.yaml" in before and ".hydra/overrides.yaml" in before
    proc = run_bionav("db=folder", f"db.path={tiny}", "homing=mfdid", *args, f"hydra.run.dir={finished}",
                      "bionav.resume=true", cwd=tmp_path)
    assert_fails_cleanly(proc, "continues only a run of the same configuration", str(finished), named,
                         "hydra.run.dir=", code=2, max_seconds=REFUSAL_S)
    assert snapshot(finished) == before


def test_resume_of_the_same_finished_run_shows_it_and_rewrites_nothing(finished, tiny, tmp_path):
    before = snapshot(finished)
    proc = run_tiny(tiny, f"hydra.run.dir={finished}", "bionav.resume=true", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.strip().splitlines()
    assert lines[-1] == f"run directory: {finished}" and "| resumed | true | resumed |" in proc.stdout
    assert "nothing was run or rewritten" in proc.stdout
    assert snapshot(finished) == before


def test_a_run_without_its_recorded_configuration_is_not_resumed(tiny, tmp_path):
    run_dir = tmp_path / "run"
    run_dir.mkdir()
    (run_dir / "metrics.json").write_text(json.dumps({"status": "failed", "error": "x"}))
    proc = run_tiny(tiny, f"hydra.run.dir={run_dir}", "bionav.resume=true", cwd=tmp_path)
    assert_fails_cleanly(proc, "without its recorded configuration", "hydra.run.dir=", code=2,
                         max_seconds=REFUSAL_S)
    assert sorted(p.name for p in run_dir.iterdir()) == ["metrics.json"]


@pytest.mark.slow
def test_a_resumed_sweep_keeps_finished_jobs_and_refuses_another_sweep(tiny, tmp_path):
    sweep = tmp_path / "sweep"
    args = ("-m", "homing=mfdid,hiss", "db=folder", f"db.path={tiny}", f"hydra.sweep.dir={sweep}")
    proc = run_bionav(*args, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    # the sweep's figure: AAE* and RR* over the swept values, linked from summary.md
    assert (sweep / "summary.png").stat().st_size > 0 and "](summary.png)" in (sweep / "summary.md").read_text()
    jobs = {job: snapshot(sweep / job) for job in ("0", "1")}
    proc = run_bionav(*args, "bionav.resume=true", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert {job: snapshot(sweep / job) for job in ("0", "1")} == jobs  # .hydra/, cli.log and results untouched
    other = ("-m", "homing=mfdid,minwarping", "db=folder", f"db.path={tiny}", f"hydra.sweep.dir={sweep}")
    proc = run_bionav(*other, "bionav.resume=true", cwd=tmp_path)
    assert_fails_cleanly(proc, "continues only the same sweep", "job 1", "homing (minwarping asked for, hiss recorded)",
                         code=2, max_seconds=REFUSAL_S)
    assert {job: snapshot(sweep / job) for job in ("0", "1")} == jobs
    # a job whose record another configuration wrote (here: edited by hand) fails alone; its files stay
    record = sweep / "1" / ".hydra" / "config.yaml"
    record.write_text(record.read_text().replace("seed: 0", "seed: 5"))
    jobs["1"] = snapshot(sweep / "1")
    proc = run_bionav(*args, "bionav.resume=true", "bionav.fail_on_job_error=false", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "seed (0 asked for, 5 recorded)" in proc.stdout + proc.stderr
    assert snapshot(sweep / "1") == jobs["1"]


def test_thesis_reuse_compares_the_recorded_configuration(finished, tiny, tmp_path):
    """``python -m bionav.thesis`` reuses a completed run only when its record is what its overrides compose to."""
    import shutil

    from bionav.thesis.runs import canonical_key, index_runs

    out = tmp_path / "out"
    run_dir = out / "runs" / "misc" / "run"
    shutil.copytree(finished, run_dir)
    import yaml

    key = canonical_key(yaml.safe_load((run_dir / ".hydra" / "overrides.yaml").read_text()))
    assert index_runs(out).get(key) == run_dir
    record = run_dir / ".hydra" / "config.yaml"
    record.write_text(record.read_text().replace("seed: 0", "seed: 9"))  # a record that describes another run
    assert key not in index_runs(out)


@pytest.mark.slow
def test_a_killed_runs_stale_lock_is_taken_over_and_the_run_marked_interrupted(tiny, tmp_path):
    """SIGKILL leaves "running" and a dead lock; the next bionav command on the directory settles both."""
    run_dir = tmp_path / "run"
    env = dict(os.environ, BIONAV_CACHE=str(tmp_path / "cache"))
    cmd = [sys.executable, "-m", "bionav", "homing=sift", "workers=1", "bionav.cache_prepared=false",
           "homing.contrast_threshold=0", "db=folder", f"db.path={tiny}", f"hydra.run.dir={run_dir}"]
    proc = subprocess.Popen(cmd, cwd=tmp_path, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 300
    while time.monotonic() < deadline and not (run_dir / ".bionav.lock").exists():
        time.sleep(0.05)
    while time.monotonic() < deadline and not (run_dir / "metrics.json").exists():
        time.sleep(0.05)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert json.loads((run_dir / "metrics.json").read_text())["status"] == "running"
    assert (run_dir / ".bionav.lock").exists()
    report = run_bionav(str(tmp_path), cwd=tmp_path, module="bionav.report")
    assert report.returncode == 0, report.stderr
    metrics = json.loads((run_dir / "metrics.json").read_text())
    assert metrics["status"] == "interrupted" and f"pid {proc.pid}" in metrics["error"], metrics
    assert not (run_dir / ".bionav.lock").exists()
    assert "interrupted" in (tmp_path / "summary.csv").read_text()


def test_thesis_never_overwrites_a_file_it_did_not_write(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "report.md").write_text("my own notes\n")
    args = ("--preset", "tiny", "--only", "5.3", "--out", str(out), "--report-only")
    proc = run_bionav(*args, cwd=tmp_path, module="bionav.thesis")
    assert_fails_cleanly(proc, "report.md", "which bionav did not write", "another --out", code=2,
                         max_seconds=REFUSAL_S)
    assert (out / "report.md").read_text() == "my own notes\n"
    (out / "report.md").unlink()
    proc = run_bionav(*args, cwd=tmp_path, module="bionav.thesis")
    assert proc.returncode == 0, proc.stderr
    assert "report.md" in json.loads((out / ".bionav-files.json").read_text())
    proc = run_bionav(*args, cwd=tmp_path, module="bionav.thesis")  # its own files it rewrites
    assert proc.returncode == 0, proc.stderr
    (out / "report.md").write_text((out / "report.md").read_text() + "\nmy remark\n")  # edited: the user's now
    proc = run_bionav(*args, cwd=tmp_path, module="bionav.thesis")
    assert_fails_cleanly(proc, "report.md", "changed since", code=2)
    assert (out / "report.md").read_text().endswith("my remark\n")


@pytest.mark.slow
def test_db_export_ends_on_sigterm_like_ctrl_c_and_resume_continues_it(tmp_path):
    out = tmp_path / "export"
    env = dict(os.environ, BIONAV_CACHE=str(tmp_path / "cache"))
    cmd = [sys.executable, "-m", "bionav.db", "export", "sim_original", str(out), "db.realism=ideal",
           "db.image_size=[64,16]"]
    proc = subprocess.Popen(cmd, cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(2.0)
    proc.send_signal(signal.SIGTERM)
    _out, err = proc.communicate(timeout=300)
    if proc.returncode == 0:
        pytest.skip("the export finished before SIGTERM arrived")
    assert proc.returncode == 130, err
    assert "Traceback" not in err and "interrupted" in err and "--resume" in err, err
    # an export cut off half-way: some images written, the sidecar says incomplete
    proc = run_bionav("export", "sim_original", str(out), "db.realism=ideal", "db.image_size=[64,16]", cwd=tmp_path,
                      module="bionav.db", env={"BIONAV_CACHE": str(tmp_path / "cache")})
    assert proc.returncode == 0, proc.stderr
    names = sorted(p.name for p in out.glob("*.png"))
    kept = {n: (out / n).stat().st_mtime_ns for n in names[:50]}
    for name in names[50:]:
        (out / name).unlink()
    sidecar = out / "bionav-export.yaml"
    sidecar.write_text(sidecar.read_text().replace("complete: true", "complete: false"))
    proc = run_bionav("export", "sim_original", str(out), "db.realism=ideal", "db.image_size=[64,16]", cwd=tmp_path,
                      module="bionav.db", env={"BIONAV_CACHE": str(tmp_path / "cache")})
    assert_fails_cleanly(proc, "--resume", "--force", code=2)
    proc = run_bionav("export", "sim_original", str(out), "db.realism=ideal", "db.image_size=[64,16]", "--resume",
                      cwd=tmp_path, module="bionav.db", env={"BIONAV_CACHE": str(tmp_path / "cache")})
    assert proc.returncode == 0, proc.stderr
    assert sorted(p.name for p in out.glob("*.png")) == names
    assert {n: (out / n).stat().st_mtime_ns for n in kept} == kept  # what was written is kept, not rewritten
    assert "complete: true" in sidecar.read_text()
    proc = run_bionav("export", "sim_original", str(out), "db.realism=ideal", "db.image_size=[64,16]", "db.seed=3",
                      "--resume", cwd=tmp_path, module="bionav.db", env={"BIONAV_CACHE": str(tmp_path / "cache")})
    assert_fails_cleanly(proc, "--resume", "another database", code=2)


def test_non_utf8_run_directory_runs_without_a_logging_traceback(tiny, tmp_path):
    name = os.fsdecode(b"run\xffdir")
    proc = run_tiny(tiny, f"hydra.run.dir='{tmp_path / name}'", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr and "Logging error" not in proc.stderr, proc.stderr
    assert proc.stdout.strip().splitlines()[-1] == "run directory: " + str(tmp_path / "run") + "\\udcffdir"
    assert json.loads((tmp_path / name / "metrics.json").read_text())["status"] == "completed"


def test_merge_with_a_read_only_install_and_home_gets_a_numba_cache(tiny, tmp_path):
    """No kernel cache beside the sources (a read-only install) and no home folder: numba would stop at the first
    import with "no locator available"; bionav gives it a cache folder of its own."""
    tasks = []
    for i in range(2):
        task = tmp_path / f"task{i}"
        proc = run_tiny(tiny, f"experiment.block=[{i},2]", f"hydra.run.dir={task}", cwd=tmp_path)
        assert proc.returncode == 0, proc.stderr
        tasks.append(str(task))
    copy = source_copy(REPO, tmp_path / "src")
    for kernels in ("evaluation", "homing", "homing/warping", "robot", "world"):  # no __pycache__ can be made
        (copy / "bionav" / kernels / "__pycache__").write_text("")
    env = {"PYTHONPATH": str(copy), "HOME": "/dev/null", "MPLCONFIGDIR": str(tmp_path / "mpl"),
           "PYTHONDONTWRITEBYTECODE": "1", "BIONAV_CACHE": str(tmp_path / "cache")}
    env.pop("NUMBA_CACHE_DIR", None)
    full = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    proc = subprocess.run([sys.executable, "-m", "bionav.experiments.merge", str(tmp_path / "merged"), *tasks],
                          cwd=tmp_path, env={**full, **env}, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0 and "Traceback" not in proc.stderr, proc.stderr
    assert json.loads((tmp_path / "merged" / "metrics.json").read_text())["status"] == "completed"
    assert (tmp_path / "cache" / "numba").is_dir()  # numba's cache where bionav put it: $BIONAV_CACHE/numba


def bench_refused(proc, *needles: str, absent: tuple[str, ...] = ()) -> str:
    """``python -m bionav.bench``'s refusal: status 2, no traceback, one ``python -m bionav.bench: error:`` line."""
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr + proc.stdout, proc.stderr
    lines = [line for line in proc.stderr.splitlines() if line.startswith("python -m bionav.bench: error: ")]
    assert len(lines) == 1, proc.stderr
    for needle in needles:
        assert needle in lines[0], lines[0]
    for needle in absent:
        assert needle not in proc.stderr, proc.stderr
    return lines[0]


@pytest.mark.slow
def test_bench_reference_printing_bytes_that_are_not_utf8(tmp_path):
    ref = tmp_path / "ref.sh"
    ref.write_bytes(b"#!/bin/sh\nprintf '\\377\\376 not json\\n'\n")
    ref.chmod(0o755)
    proc = run_bionav("--reference", str(ref), "--repeat", "1", "--batch", "1", "--size", "64", "16",
                      "--steps", "8", "--render-size", "64", "16", cwd=tmp_path, module="bionav.bench")
    bench_refused(proc, "--reference", "printed", "one JSON object per variant")


@pytest.mark.parametrize(("args", "needle"), [
    (["--cpu-name", "no_such_cpu", "--cpu-features", "+sse2"], "LLVM does not know no_such_cpu"),
    (["--cpu-name", "haswell", "--cpu-features", "+sse2,+no_such_feature"], "LLVM does not know +no_such_feature"),
    (["--cpu-name", "no_such_cpu"], "unknown CPU name 'no_such_cpu'"),
])
def test_bench_unknown_cpu_is_refused_before_llvm_sees_it(tmp_path, args, needle):
    proc = run_bionav(*args, "--repeat", "1", "--batch", "1", cwd=tmp_path, module="bionav.bench")
    bench_refused(proc, "--cpu-name", needle, absent=("LLVM ERROR", "is not a recognized"))


@pytest.mark.parametrize(("group", "value", "install"), [
    ("hydra/sweeper", "optuna", 'pip install "bionav[tune]"'),
    ("hydra/sweeper", "nevergrad", "pip install hydra-nevergrad-sweeper"),
    ("hydra/launcher", "ray", "pip install hydra-ray-launcher"),
])
def test_a_hydra_plugin_that_is_not_installed_names_its_install_line(tmp_path, group, value, install):
    env = None
    if value == "optuna":  # installed here with the test extras: shadow it as if optuna were missing
        fake = tmp_path / "site" / "hydra_plugins" / "hydra_optuna_sweeper"
        fake.mkdir(parents=True)
        (fake / "__init__.py").write_text('raise ImportError("No module named \'optuna\'")\n')
        env = {"PYTHONPATH": os.pathsep.join([str(tmp_path / "site"), os.environ.get("PYTHONPATH", "")])}
    proc = run_bionav("-m", f"{group}={value}", "homing=sift", cwd=tmp_path, env=env)
    assert_fails_cleanly(proc, f"{group}={value} is not installed", install, code=2, max_seconds=REFUSAL_S,
                         absent=("Could not find", "Config search path"))
    assert not (tmp_path / "multirun").exists()


def test_an_interrupted_single_run_continues_from_its_last_logged_row(finished, tiny, tmp_path):
    """``bionav.resume=true`` into a run that stopped after some snapshot rows: those rows are read from its log
    (kept as ``run.attempt-1.mcap``), only the others are computed, and the measures are the uninterrupted run's."""
    import shutil

    from bionav.logs.reader import read_recorded_messages
    from bionav.logs.writer import McapLog

    run_dir = tmp_path / "run"
    shutil.copytree(finished, run_dir)
    rows = read_recorded_messages(run_dir / "run.mcap", ["/grid_homing/snapshot_rows"])
    assert len(rows) == 9
    with McapLog(run_dir / "run.mcap") as log:  # what a SIGKILL after five rows leaves (rows are logged as computed)
        for topic, msg in rows[:5]:
            log.write(topic, msg, schema_name="bionav.HomeVectorRow")
    (run_dir / "metrics.json").write_text(json.dumps({"experiment": "grid_homing", "status": "running", "pid": 2**22}))
    proc = run_tiny(tiny, f"hydra.run.dir={run_dir}", "bionav.resume=true", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "5 of 9 snapshot rows come from the earlier attempt" in proc.stdout + proc.stderr
    resumed = json.loads((run_dir / "metrics.json").read_text())
    full = json.loads((finished / "metrics.json").read_text())
    assert resumed["resumed_rows"] == 5 and resumed["status"] == "completed"
    assert {k: resumed[k] for k in ("aae", "mae", "rr", "n_pairs")} == {k: full[k] for k in ("aae", "mae", "rr", "n_pairs")}
    assert (run_dir / "run.attempt-1.mcap").is_file() and (run_dir / "metrics.attempt-1.json").is_file()
    assert len(read_recorded_messages(run_dir / "run.mcap", ["/grid_homing/snapshot_rows"])) == 9


def test_the_table_names_the_thesis_measures_with_units_and_outputs_latest_points_at_the_run(tiny, tmp_path):
    proc = run_tiny(tiny, cwd=tmp_path)  # the default run directory outputs/<date>/<time>
    assert proc.returncode == 0, proc.stderr
    for row in ("| AAE* (rad) |", "| MAE* (rad) |", "| RR* (fraction of agents home) |", "| metric | value | metrics.json |"):
        assert row in proc.stdout, proc.stdout
    run_dir = Path(proc.stdout.strip().splitlines()[-1].removeprefix("run directory: "))
    latest = tmp_path / "outputs" / "latest"
    assert latest.is_symlink() and latest.resolve() == run_dir.resolve()
    assert (latest / "metrics.json").is_file() and (latest / "plots" / "per_snapshot.png").is_file()
