"""Hostile input to ``python -m bionav.logs``: wrong files, unwritable outputs -> one clean message each."""

import os

import pytest
from helpers import assert_fails_cleanly, run_bionav

from bionav.logs.reader import read_messages
from bionav.logs.writer import McapLog


@pytest.fixture
def good_log(tmp_path):
    path = tmp_path / "good.mcap"
    with McapLog(path) as log:
        for i in range(5):
            log.write("/t", {"i": i}, schema_name="bionav.Test")
    return path


def logs(*args, cwd):
    return run_bionav(*args, cwd=cwd, module="bionav.logs")


def test_recover_to_unwritable_output_is_clean(tmp_path, good_log):
    proc = logs("recover", str(good_log), "/proc/x.mcap", cwd=tmp_path)
    assert_fails_cleanly(proc, "cannot write the output /proc/x.mcap")


def test_recover_refuses_text_file(tmp_path):
    text = tmp_path / "notes.txt"
    text.write_text("this is not a log\n" * 20)
    out = tmp_path / "out.mcap"
    proc = logs("recover", str(text), str(out), cwd=tmp_path)
    assert_fails_cleanly(proc, "is not an MCAP file")
    assert not out.exists()


def test_recover_refuses_random_bytes(tmp_path):
    junk = tmp_path / "junk.mcap"
    junk.write_bytes(os.urandom(4096))
    proc = logs("recover", str(junk), str(tmp_path / "out.mcap"), cwd=tmp_path)
    assert_fails_cleanly(proc, "is not an MCAP file")


def test_recover_refuses_empty_file(tmp_path):
    empty = tmp_path / "empty.mcap"
    empty.write_bytes(b"")
    proc = logs("recover", str(empty), str(tmp_path / "out.mcap"), cwd=tmp_path)
    assert_fails_cleanly(proc, "is not an MCAP file", "empty")


def test_recover_does_not_overwrite_an_existing_log(tmp_path, good_log):
    other = tmp_path / "other.mcap"
    with McapLog(other) as log:
        log.write("/keep", {"k": 1}, schema_name="bionav.Test")
    before = other.read_bytes()
    proc = logs("recover", str(good_log), str(other), cwd=tmp_path)
    assert_fails_cleanly(proc, "exists", "--force")
    assert other.read_bytes() == before  # nothing already recorded lost
    proc = logs("recover", str(good_log), str(other), "--force", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert [m["i"] for _, _, m in read_messages(other)] == list(range(5))


def test_info_on_a_directory_says_directory(tmp_path):
    proc = logs("info", str(tmp_path), cwd=tmp_path)
    assert_fails_cleanly(proc, "is a directory", "run.mcap")


def test_info_on_missing_and_text_files(tmp_path):
    assert_fails_cleanly(logs("info", str(tmp_path / "nope.mcap"), cwd=tmp_path), "does not exist")
    text = tmp_path / "x.mcap"
    text.write_text("hello")
    assert_fails_cleanly(logs("info", str(text), cwd=tmp_path), "is not an MCAP file")


def test_recover_input_directory(tmp_path):
    assert_fails_cleanly(logs("recover", str(tmp_path), str(tmp_path / "o.mcap"), cwd=tmp_path), "is a directory")


def test_info_on_a_fifo_does_not_block(tmp_path):
    fifo = tmp_path / "run.mcap"
    os.mkfifo(fifo)
    proc = logs("info", str(fifo), cwd=tmp_path)
    assert_fails_cleanly(proc, str(fifo), "FIFO", "run.mcap", code=2, max_seconds=60)


@pytest.mark.parametrize("command", ["info", "recover"])
def test_dev_null_is_not_a_log(tmp_path, command):
    args = ["/dev/null"] + ([str(tmp_path / "o.mcap")] if command == "recover" else [])
    assert_fails_cleanly(logs(command, *args, cwd=tmp_path), "/dev/null", "is a device", code=2, max_seconds=60)


@pytest.mark.parametrize("force", [[], ["--force"]])
def test_recover_into_dev_full(tmp_path, good_log, force):
    before = good_log.read_bytes()
    proc = logs("recover", str(good_log), "/dev/full", *force, cwd=tmp_path)
    assert_fails_cleanly(proc, "/dev/full", "is a device", "fixed.mcap", code=2, max_seconds=60)
    assert good_log.read_bytes() == before


def test_recover_on_a_full_disk_keeps_the_input_and_removes_the_partial_output(tmp_path, good_log, monkeypatch):
    """ENOSPC while writing the output: one message naming it, the input intact, no half-written output."""
    import errno
    import importlib

    from bionav.errors import UserError

    rec = importlib.import_module("bionav.logs.recover")

    def full(*_a, **_k):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(rec, "_copy_records", full)
    out = tmp_path / "fixed.mcap"
    with pytest.raises(UserError, match="No space left on device.*unchanged"):
        rec.recover(good_log, out)
    assert not out.exists()


def _flipped_metadata_log(tmp_path, offset):
    path = tmp_path / "meta.mcap"
    with McapLog(path) as log:
        log.metadata("plugins", {"bionav": "0.1", "homing": "sift"})
        for i in range(5):
            log.write("/t", {"i": i}, schema_name="bionav.Test")
    data = bytearray(path.read_bytes())
    data[data.find(b"plugins") + offset] ^= 0xFF
    path.write_bytes(bytes(data))
    return path


@pytest.mark.slow
@pytest.mark.parametrize("offset", [-6, -2, 0, 9, 20])
def test_a_flipped_byte_in_the_metadata(tmp_path, offset):
    """A flipped byte in the metadata record (its length, its name, its values): info says the file is
    damaged and how to repair it; recover keeps every intact record."""
    path = _flipped_metadata_log(tmp_path, offset)
    assert_fails_cleanly(logs("info", str(path), cwd=tmp_path), str(path), "recover", code=2, max_seconds=60)
    proc = logs("recover", str(path), str(tmp_path / "fixed.mcap"), cwd=tmp_path)
    assert proc.returncode == 0 and "Traceback" not in proc.stderr, proc.stderr
    n = sum(1 for _ in read_messages(tmp_path / "fixed.mcap"))
    assert n in (0, 5)  # a length flipped to garbage stops the sequential read there; otherwise all are kept


def test_info_into_a_closed_pipe_ends_quietly(tmp_path, good_log):
    from helpers import run_into_closed_pipe

    proc = run_into_closed_pipe("info", str(good_log), module="bionav.logs", cwd=tmp_path)
    assert proc.returncode == 141, proc.stderr
    assert "Traceback" not in proc.stderr and "BrokenPipeError" not in proc.stderr, proc.stderr


def test_recover_rebuilds_grid_homing_metrics_from_rows_and_partial_rows(tmp_path):
    """Whole rows and partial rows of another snapshot: each pair counted once, AAE their mean (hand-computed)."""
    from bionav.logs.recover import logged_results

    path = tmp_path / "cut.mcap"
    with McapLog(path) as log:
        log.write("/grid_homing/snapshot_rows", {"snapshot": [0, 0], "angles": [None, 0.0, 0.0],
                                                 "ae": [None, 0.1, 0.3], "compass_error": [None] * 3},
                  schema_name="bionav.HomeVectorRow")
        log.write("/grid_homing/partial_rows", {"snapshot": [1, 0], "currents": [[0, 0]], "angles": [0.0],
                                                "ae": [0.5], "compass_error": [None]}, schema_name="bionav.P")
        log.write("/grid_homing/partial_rows", {"snapshot": [1, 0], "currents": [[2, 0]], "angles": [0.0],
                                                "ae": [0.7], "compass_error": [None]}, schema_name="bionav.P")
    got = logged_results(path)
    assert got["n_home_vectors"] == 4 and got["n_snapshots"] == 2 and got["n_complete_rows"] == 1
    assert got["aae_logged"] == pytest.approx((0.1 + 0.3 + 0.5 + 0.7) / 4)
    proc = logs("recover", str(path), str(tmp_path / "fixed.mcap"), cwd=tmp_path)
    assert "home vectors logged: 4 of 2 snapshots (1 whole rows); AAE over them: 0.4000 rad" in proc.stdout
