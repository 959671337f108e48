"""Hostile conditions for ``python -m bionav`` runs: SIGKILL at several points, two runs in one directory,
Ctrl-C in a sweep, failed sweep jobs, bad output directories, a full disk, file modes, corrupt images.

For every case: non-zero exit, one paragraph naming the problem and the fix, no traceback, and nothing
already recorded lost.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from helpers import assert_fails_cleanly, run_bionav, write_tiny_folder
from mcap.reader import make_reader
from mcap.records import Message
from mcap.stream_reader import StreamReader

from bionav.logs.reader import read_attachment, read_messages

#: a grid-homing run that logs one row every ~0.2 s for ~30 s on an idle machine (SIFT, 170 x 169 pairs, one
#: worker; every keypoint (contrast threshold 0, ~740 per image) matched within half the width: the fast matcher
#: needs that much work to stay busy)
SLOW_RUN = ("homing=sift", "workers=1", "bionav.cache_prepared=false", "homing.contrast_threshold=0",
            "homing.search_radius=0.5")
ROW_TOPIC = "/grid_homing/snapshot_rows"


@pytest.fixture(scope="module")
def render_cache():
    """The shared, content-hashed render cache (sim_original is rendered once, ever); per-image work is
    not cached in these runs (bionav.cache_prepared=false)."""
    from bionav.files import default_cache_dir

    return default_cache_dir()


@pytest.fixture
def tiny_folder(tmp_path):
    return write_tiny_folder(tmp_path / "tiny", shape=(16, 64), sigma=2.0)


def _start(args, cwd, cache) -> subprocess.Popen:
    env = dict(os.environ, BIONAV_CACHE=str(cache))
    # Ctrl-C as in a terminal, also when pytest itself runs in the background (which ignores SIGINT)
    return subprocess.Popen([sys.executable, "-m", "bionav", *args], cwd=cwd, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))


def _wait_for(predicate, timeout, proc=None, what=""):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if predicate():
            return
        if proc is not None and proc.poll() is not None:
            raise AssertionError(f"the run ended before {what}: {proc.communicate()}")
        time.sleep(0.05)
    raise AssertionError(f"timed out waiting for {what}")


def _status(run_dir: Path):
    try:
        return json.loads((run_dir / "metrics.json").read_text()).get("status")
    except (OSError, ValueError):
        return None


def _stream_messages(path: Path, topic: str | None = None) -> list[Message]:
    """Messages of a (possibly cut) MCAP file read sequentially with mcap's own stream reader (only ``topic``'s
    when given)."""
    from mcap.records import Channel, Chunk
    from mcap.stream_reader import breakup_chunk

    out, topics = [], {}
    with open(path, "rb") as f:
        try:
            for record in StreamReader(f, skip_magic=False).records:
                for r in breakup_chunk(record) if isinstance(record, Chunk) else [record]:
                    if isinstance(r, Channel):
                        topics[r.id] = r.topic
                    elif isinstance(r, Message) and topic in (None, topics.get(r.channel_id)):
                        out.append(r)
        except Exception:  # the cut-off tail
            pass
    return out


def _rows_since(path: Path) -> int:
    """Whole snapshot rows in the (possibly cut) log: the run also logs poses and partial rows."""
    return len(_stream_messages(path, ROW_TOPIC))


@pytest.mark.slow
@pytest.mark.parametrize("extra_wait_s", [None, 0.3, 1.2, 2.9])
def test_sigkill_loses_at_most_the_last_two_seconds(tmp_path, render_cache, extra_wait_s):
    """SIGKILL early (per-image work) and at three points of the home-vector phase (odd offsets to the
    2 s flush period): metrics.json says running, the raw log is readable by mcap's stream reader,
    `python -m bionav.logs recover` repairs it, and the last logged row is at most ~2 s (plus one row
    interval) older than the kill."""
    run_dir = tmp_path / "run"
    proc = _start([*SLOW_RUN, f"hydra.run.dir={run_dir}"], tmp_path, render_cache)
    try:
        _wait_for(lambda: _status(run_dir) == "running", 120, proc, "metrics.json says running")
        if extra_wait_s is not None:  # wait until rows have reached the file, then a bit more
            _wait_for(lambda: (run_dir / "run.mcap").exists() and _rows_since(run_dir / "run.mcap") >= 2, 120, proc,
                      "the first rows are flushed")
            time.sleep(extra_wait_s)
        else:
            time.sleep(0.5)
    finally:
        proc.send_signal(signal.SIGKILL)
        killed_ns = time.time_ns()
        proc.communicate()
    assert _status(run_dir) == "running"  # something left to say the run did not finish
    raw = _stream_messages(run_dir / "run.mcap")
    fixed = tmp_path / "fixed.mcap"
    rec = run_bionav("recover", str(run_dir / "run.mcap"), str(fixed), cwd=tmp_path, module="bionav.logs")
    assert rec.returncode == 0, rec.stderr
    assert b"seed:" in read_attachment(fixed, "config.yaml")  # the config is there from the start
    with open(fixed, "rb") as f:  # the repaired file has a summary that mcap's seeking reader uses
        assert make_reader(f).get_summary().statistics.message_count == len(raw)
    rows = [(t, m) for topic, t, m in read_messages(fixed) if topic == ROW_TOPIC]
    if extra_wait_s is None:
        return
    assert len(rows) >= 2
    times = np.array([t for t, _ in rows], dtype=float)
    gap = float(np.median(np.diff(times))) / 1e9 if len(rows) > 2 else 1.0
    lost = (killed_ns - times[-1]) / 1e9
    assert lost <= 2.0 + gap + 0.75, f"last row {lost:.2f} s before the kill (rows every {gap:.2f} s)"
    assert all(len(m["angles"]) == 170 and m["angles"] for _, m in rows)


@pytest.mark.slow
def test_second_run_into_the_same_directory_is_refused(tmp_path, render_cache, tiny_folder):
    """While a run holds a directory, a second run into it is refused (first run's files untouched);
    after the first is SIGKILLed its stale lock does not block a new run."""
    run_dir = tmp_path / "run"
    first = _start([*SLOW_RUN, f"hydra.run.dir={run_dir}"], tmp_path, render_cache)
    try:
        _wait_for(lambda: _status(run_dir) == "running", 120, first, "metrics.json says running")
        hydra_cfg = (run_dir / ".hydra" / "config.yaml").read_bytes()
        second = run_bionav("homing=mfdid", "db=folder", f"db.path={tiny_folder}", f"hydra.run.dir={run_dir}",
                            cwd=tmp_path)
        assert_fails_cleanly(second, "in use by another bionav command", f"pid {first.pid}", "hydra.run.dir", code=2)
        assert first.poll() is None  # the first run goes on
        assert _status(run_dir) == "running" and (run_dir / ".hydra" / "config.yaml").read_bytes() == hydra_cfg
    finally:
        first.send_signal(signal.SIGKILL)
        first.communicate()
    assert (run_dir / ".bionav.lock").exists()  # left behind by the crash ...
    third = run_bionav("homing=mfdid", "db=folder", f"db.path={tiny_folder}", f"hydra.run.dir={run_dir}",
                       cwd=tmp_path)
    assert third.returncode == 0, third.stderr  # ... but stale: its process is gone
    assert _status(run_dir) == "completed" and not (run_dir / ".bionav.lock").exists()


@pytest.mark.slow
def test_lock_of_a_live_process_blocks_and_a_dead_one_does_not(tmp_path, tiny_folder):
    import socket

    from bionav.runlock import LOCK_FILE, _process_start

    run_dir = tmp_path / "run"
    run_dir.mkdir()
    sleeper = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        lock = {"pid": sleeper.pid, "host": socket.gethostname(), "started": "then",
                "start_ticks": _process_start(sleeper.pid)}
        (run_dir / LOCK_FILE).write_text(json.dumps(lock))
        args = ("homing=mfdid", "db=folder", f"db.path={tiny_folder}", f"hydra.run.dir={run_dir}")
        assert_fails_cleanly(run_bionav(*args, cwd=tmp_path), "in use by another bionav command", code=2)
        # the same pid with another start time is a reused pid: stale
        (run_dir / LOCK_FILE).write_text(json.dumps({**lock, "start_ticks": "1"}))
        proc = run_bionav(*args, cwd=tmp_path)
        assert proc.returncode == 0, proc.stderr
        # another host's lock cannot be checked: refused, with the way out
        (run_dir / LOCK_FILE).write_text(json.dumps({**lock, "host": "elsewhere"}))
        assert_fails_cleanly(run_bionav(*args, cwd=tmp_path), "elsewhere", "delete", code=2)
    finally:
        sleeper.kill()
        sleeper.wait()


@pytest.mark.slow
def test_ctrl_c_during_a_sweep_writes_the_summary(tmp_path, render_cache):
    """SIGINT while the second job runs: summary.csv/md list the finished job (completed) and the
    interrupted one (failed); exit 130 with one clean line."""
    sweep = tmp_path / "sweep"
    proc = _start(["-m", "homing=mfdid,sift", "workers=1", "bionav.cache_prepared=false",
                   f"hydra.sweep.dir={sweep}"], tmp_path, render_cache)
    try:
        _wait_for(lambda: _status(sweep / "1") == "running", 180, proc, "the second job starts")
        time.sleep(1.0)
    finally:
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=60)
    done = subprocess.CompletedProcess(proc.args, proc.returncode, out, err)
    summary = (sweep / "summary.md").read_text() if (sweep / "summary.md").exists() else "(no summary.md)"
    assert proc.returncode == 130, (summary, err[-3000:])
    assert_fails_cleanly(done, "interrupted", "summary", "bionav.resume=true", code=130)
    import csv

    with open(sweep / "summary.csv") as f:
        rows = {r["job"]: r for r in csv.DictReader(f)}
    assert rows["0"]["status"] == "completed" and float(rows["0"]["aae"]) > 0, (rows, err)
    assert rows["1"]["status"] == "failed" and "KeyboardInterrupt" in rows["1"]["error"], (rows, err)
    assert "2 runs, 1 failed" in (sweep / "summary.md").read_text()


@pytest.mark.slow
def test_failed_jobs_fail_the_sweep_and_errors_stay_in_their_cell(tmp_path, tiny_folder):
    sweep = tmp_path / "sweep"
    bad = tmp_path / "mis|sing"
    proc = run_bionav("-m", "homing=mfdid", "db=folder", f"db.path={tiny_folder},'{bad}'",
                      f"hydra.sweep.dir={sweep}", cwd=tmp_path)
    assert_fails_cleanly(proc, "1 of 2 jobs failed", "bionav.fail_on_job_error=false", code=1)
    assert "1 of 2 jobs failed" in proc.stderr.strip().splitlines()[-1]  # the last line states the count
    md = (sweep / "summary.md").read_text()
    table = [line for line in md.splitlines() if line.startswith("| ")]
    n_columns = table[0].count(" | ")
    assert all(line.replace("\\|", "").count(" | ") == n_columns for line in table), md
    assert "mis\\|sing" in md
    # opting out: the same sweep exits 0
    proc = run_bionav("-m", "homing=mfdid", "db=folder", f"db.path={tiny_folder},'{bad}'",
                      f"hydra.sweep.dir={tmp_path / 'sweep2'}", "bionav.fail_on_job_error=false", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr


def test_markdown_cells_escape_pipes_and_newlines():
    from bionav.report.table import markdown_table

    text = markdown_table([{"a": "x|y", "b": "line1\nline2"}], ["a", "b"])
    assert text.splitlines()[2] == "| x\\|y | line1<br>line2 |"


@pytest.mark.parametrize("target", ["/proc/foo", "/proc/self/foo/bar"])
def test_output_dir_in_proc_is_clean(tmp_path, target):
    assert_fails_cleanly(run_bionav(f"hydra.run.dir={target}", cwd=tmp_path), "cannot write the output directory",
                   "hydra.run.dir", code=2)


def test_sweep_with_cfg_is_clean(tmp_path):
    assert_fails_cleanly(run_bionav("-m", "homing=sift,mfdid", "--cfg", "job", cwd=tmp_path), "drop -m", code=2)


def _disk_full_checks(proc, run_dir: Path):
    assert_fails_cleanly(proc, "no space left on", "hydra.run.dir", code=2)
    assert "bug" not in proc.stderr
    assert not (run_dir / "error.log").exists() or (run_dir / "error.log").read_text().strip()


@pytest.fixture
def small_tmpfs(tmp_path):
    if os.geteuid() != 0:
        pytest.skip("mounting a tmpfs needs root")
    mount = tmp_path / "small"
    mount.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=4m", "tmpfs", str(mount)]).returncode != 0:
        pytest.skip("cannot mount a tmpfs here")
    yield mount
    subprocess.run(["umount", str(mount)])


def _fill(mount: Path) -> None:
    """Fill a file system completely."""
    with open(mount / "filler", "ab") as f:
        try:
            while True:
                f.write(b"\0" * 65536)
                f.flush()
        except OSError:
            pass


def test_disk_already_full_is_refused_before_hydra_writes(tmp_path, small_tmpfs, tiny_folder):
    _fill(small_tmpfs)
    proc = run_bionav("homing=mfdid", "db=folder", f"db.path={tiny_folder}", f"hydra.run.dir={small_tmpfs / 'run'}",
                      cwd=tmp_path)
    _disk_full_checks(proc, small_tmpfs / "run")
    assert f"no space left on {small_tmpfs}" in proc.stderr


@pytest.mark.slow
def test_disk_fills_up_during_the_run(tmp_path, small_tmpfs, render_cache):
    """The disk fills while the run computes: one clean message naming the mount point; what was written
    before (metrics.json, the start of run.mcap) is kept and the log is recoverable."""
    run_dir = small_tmpfs / "run"
    proc = _start([*SLOW_RUN, f"hydra.run.dir={run_dir}"], tmp_path, render_cache)
    try:
        _wait_for(lambda: (run_dir / "run.mcap").exists() and _rows_since(run_dir / "run.mcap") >= 1, 120, proc,
                  "the first rows are flushed")
        rows_before = _rows_since(run_dir / "run.mcap")
        _fill(small_tmpfs)
        out, err = proc.communicate(timeout=300)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    done = subprocess.CompletedProcess(proc.args, proc.returncode, out, err)
    _disk_full_checks(done, run_dir)
    assert f"no space left on {small_tmpfs}" in err
    assert _status(run_dir) in ("failed", "running")
    (small_tmpfs / "filler").unlink()  # make room, then repair the log: the rows before are all there
    rec = run_bionav("recover", str(run_dir / "run.mcap"), str(tmp_path / "fixed.mcap"), cwd=tmp_path,
                     module="bionav.logs")
    assert rec.returncode == 0, rec.stderr
    assert sum(1 for topic, _, _ in read_messages(tmp_path / "fixed.mcap") if topic == ROW_TOPIC) >= rows_before


def test_disk_full_simulated_with_dev_full(tmp_path, tiny_folder):
    """run.mcap on /dev/full (every write: ENOSPC): clean message, metrics.json says failed."""
    run_dir = tmp_path / "run"
    run_dir.mkdir()
    (run_dir / "run.mcap").symlink_to("/dev/full")
    proc = run_bionav("homing=mfdid", "db=folder", f"db.path={tiny_folder}", f"hydra.run.dir={run_dir}",
                      cwd=tmp_path)
    _disk_full_checks(proc, run_dir)
    metrics = json.loads((run_dir / "metrics.json").read_text())
    assert metrics["status"] == "failed" and "no space left" in metrics["error"]


@pytest.mark.slow
def test_outputs_follow_the_umask(tmp_path, tiny_folder):
    """metrics.json and cache files are readable by the group/others when the umask allows (not 600)."""
    run_dir = tmp_path / "run"
    cache = tmp_path / "cache"
    proc = subprocess.run(
        [sys.executable, "-c", "import os, sys; os.umask(0o022); sys.argv[0] = 'bionav'; "
         "from bionav.cli import main; main(sys.argv[1:])",
         "homing=sift", "db=folder", f"db.path={tiny_folder}", f"hydra.run.dir={run_dir}",
         "bionav.cache_prepared=true"],
        cwd=tmp_path, env=dict(os.environ, BIONAV_CACHE=str(cache)), capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert (run_dir / "metrics.json").stat().st_mode & 0o777 == 0o644
    cached = [p for p in cache.rglob("*") if p.is_file()]
    assert cached
    assert all(p.stat().st_mode & 0o777 == 0o644 for p in cached), {p.name: oct(p.stat().st_mode) for p in cached}


def test_corrupt_png_gives_one_clean_line_without_libpng_noise(tmp_path, tiny_folder):
    data = bytearray((tiny_folder / "1_1.png").read_bytes())
    i = data.find(b"IDAT")
    data[i + 20] ^= 0xFF
    (tiny_folder / "1_1.png").write_bytes(bytes(data))
    proc = run_bionav("homing=mfdid", "db=folder", f"db.path={tiny_folder}", f"hydra.run.dir={tmp_path / 'r'}",
                      cwd=tmp_path)
    assert_fails_cleanly(proc, "1_1.png", "corrupt", code=2)
    assert "libpng" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1, proc.stderr


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_interrupt_or_terminate_a_run_keeps_its_results(tmp_path, render_cache, sig):
    """Ctrl-C or SIGTERM (kill, a cluster's time limit) during the home vectors: exit 130 with one clean
    line, metrics.json says failed, run.mcap is finished (summary readable) and keeps the rows so far."""
    run_dir = tmp_path / "run"
    proc = _start([*SLOW_RUN, f"hydra.run.dir={run_dir}"], tmp_path, render_cache)
    try:
        _wait_for(lambda: (run_dir / "run.mcap").exists() and _rows_since(run_dir / "run.mcap") >= 1, 120, proc,
                  "the first rows are flushed")
    finally:
        proc.send_signal(sig)
        out, err = proc.communicate(timeout=60)
    assert_fails_cleanly(subprocess.CompletedProcess(proc.args, proc.returncode, out, err), "interrupted", code=130)
    metrics = json.loads((run_dir / "metrics.json").read_text())
    assert metrics["status"] == "failed" and "KeyboardInterrupt" in metrics["error"]
    with open(run_dir / "run.mcap", "rb") as f:
        summary = make_reader(f).get_summary()
    assert summary.statistics.message_count >= 1
    assert not (run_dir / ".bionav.lock").exists()


def test_ctrl_c_inside_compiled_code_counts_as_an_interrupt(tmp_path, monkeypatch):
    """numba turns a KeyboardInterrupt inside a jitted function into SystemError (caused by the interrupt);
    the runner records it as an interrupt and re-raises KeyboardInterrupt (so a sweep stops, not goes on)."""
    from omegaconf import OmegaConf

    from bionav.experiments.base import Experiment
    from bionav.experiments.runner import run_experiment

    class Interrupted(Experiment):
        Config = dict  # not checked: validate_run_config is replaced below

        def run(self, ctx):
            ctx.log.write("/t", {"before": 1}, schema_name="bionav.Test")
            try:
                raise KeyboardInterrupt
            except KeyboardInterrupt as exc:
                raise SystemError("CPUDispatcher(<function f>) returned a result with an exception set") from exc

    cfg = OmegaConf.create({"experiment": {"name": "interrupted_inside_numba"}, "seed": 0})
    monkeypatch.setattr("bionav.experiments.runner.validate_run_config", lambda cfg: None)
    monkeypatch.setattr("bionav.experiments.settings.experiment_class", lambda name: Interrupted)
    with pytest.raises(KeyboardInterrupt):
        run_experiment(cfg, tmp_path / "run")
    metrics = json.loads((tmp_path / "run" / "metrics.json").read_text())
    assert metrics["status"] == "failed" and metrics["error"].startswith("KeyboardInterrupt")
    assert [m for _, _, m in read_messages(tmp_path / "run" / "run.mcap")] == [{"before": 1}]
