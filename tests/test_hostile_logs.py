"""Hostile input to ``python -m bionav.logs``: wrong files, unwritable outputs -> one clean message each."""

import os

import pytest
from helpers import run_bionav

from bionav.logs.reader import read_messages
from bionav.logs.writer import McapLog


def _clean_failure(proc, *needles):
    """Non-zero exit, no traceback, one paragraph that contains every needle."""
    assert proc.returncode != 0, proc.stdout + proc.stderr
    assert "Traceback" not in proc.stderr, proc.stderr
    lines = [line for line in proc.stderr.strip().splitlines() if line.strip()]
    assert len(lines) == 1, proc.stderr
    for needle in needles:
        assert needle in proc.stderr, proc.stderr


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
    _clean_failure(proc, "cannot write the output /proc/x.mcap")


def test_recover_refuses_text_file(tmp_path):
    text = tmp_path / "notes.txt"
    text.write_text("this is not a log\n" * 20)
    out = tmp_path / "out.mcap"
    proc = logs("recover", str(text), str(out), cwd=tmp_path)
    _clean_failure(proc, "is not an MCAP file")
    assert not out.exists()


def test_recover_refuses_random_bytes(tmp_path):
    junk = tmp_path / "junk.mcap"
    junk.write_bytes(os.urandom(4096))
    proc = logs("recover", str(junk), str(tmp_path / "out.mcap"), cwd=tmp_path)
    _clean_failure(proc, "is not an MCAP file")


def test_recover_refuses_empty_file(tmp_path):
    empty = tmp_path / "empty.mcap"
    empty.write_bytes(b"")
    proc = logs("recover", str(empty), str(tmp_path / "out.mcap"), cwd=tmp_path)
    _clean_failure(proc, "is not an MCAP file", "empty")


def test_recover_does_not_overwrite_an_existing_log(tmp_path, good_log):
    other = tmp_path / "other.mcap"
    with McapLog(other) as log:
        log.write("/keep", {"k": 1}, schema_name="bionav.Test")
    before = other.read_bytes()
    proc = logs("recover", str(good_log), str(other), cwd=tmp_path)
    _clean_failure(proc, "exists", "--force")
    assert other.read_bytes() == before  # nothing already recorded lost
    proc = logs("recover", str(good_log), str(other), "--force", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert [m["i"] for _, _, m in read_messages(other)] == list(range(5))


def test_info_on_a_directory_says_directory(tmp_path):
    proc = logs("info", str(tmp_path), cwd=tmp_path)
    _clean_failure(proc, "is a directory", "run.mcap")


def test_info_on_missing_and_text_files(tmp_path):
    _clean_failure(logs("info", str(tmp_path / "nope.mcap"), cwd=tmp_path), "does not exist")
    text = tmp_path / "x.mcap"
    text.write_text("hello")
    _clean_failure(logs("info", str(text), cwd=tmp_path), "is not an MCAP file")


def test_recover_input_directory(tmp_path):
    _clean_failure(logs("recover", str(tmp_path), str(tmp_path / "o.mcap"), cwd=tmp_path), "is a directory")
