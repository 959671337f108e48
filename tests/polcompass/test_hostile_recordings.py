"""Hostile recordings for ``python -m bionav experiment=pol_recordings`` (issue 32): files that would block
(a FIFO, a device), exhaust memory (a unit key ``pol_op_99999999999``), or confuse (400-digit integers,
UTF-16), and ``~`` in ``recordings.path``. Each ends in one clean paragraph within a bounded time."""

from __future__ import annotations

import json
import os

import pytest
from helpers import assert_fails_cleanly, run_bionav

GOOD = {"pol_op_0": [[1, 2, 3, 4]], "azimuths": [0.0], "yaw": [0.0]}
#: refused while reading the first file: no hang, no memory growth (the FIFO case used to block forever)
BOUND_S = 120


def run_recordings(path, tmp_path, env=None):
    return run_bionav("experiment=pol_recordings", f"recordings.path={path}", f"hydra.run.dir={tmp_path / 'run'}",
                      cwd=tmp_path, env=env, timeout=BOUND_S + 60)


def session(tmp_path, content: bytes | None = None):
    folder = tmp_path / "recs" / "s"
    folder.mkdir(parents=True)
    if content is not None:
        (folder / "1.json").write_bytes(content)
    return folder / "1.json"


def test_a_fifo_named_like_a_recording(tmp_path):
    fifo = session(tmp_path)
    os.mkfifo(fifo)
    proc = run_recordings(tmp_path / "recs", tmp_path)
    assert_fails_cleanly(proc, str(fifo), "FIFO", code=2, max_seconds=BOUND_S)


def test_dev_null_as_the_recordings_path(tmp_path):
    proc = run_recordings("/dev/null", tmp_path)
    assert_fails_cleanly(proc, "recordings.path=/dev/null", "is a device", "Point it at a folder", code=2,
                         max_seconds=BOUND_S)


def test_a_huge_unit_number(tmp_path):
    data = {"pol_op_99999999999": [[1, 2, 3, 4]], "azimuths": [0.0], "yaw": [0.0]}
    session(tmp_path, json.dumps(data).encode())
    proc = run_recordings(tmp_path / "recs", tmp_path)
    assert_fails_cleanly(proc, "pol_op_99999999999", "pol_op_<n>", code=2, max_seconds=BOUND_S)


def test_a_400_digit_integer(tmp_path):
    text = '{"pol_op_0": [[1%s, 2, 3, 4]], "azimuths": [0.0], "yaw": [0.0]}' % ("0" * 400)
    session(tmp_path, text.encode())
    proc = run_recordings(tmp_path / "recs", tmp_path)
    assert_fails_cleanly(proc, "401 digits", code=2, max_seconds=BOUND_S)


def test_utf16_json(tmp_path):
    path = session(tmp_path, json.dumps(GOOD).encode("utf-16"))
    proc = run_recordings(tmp_path / "recs", tmp_path)
    assert_fails_cleanly(proc, str(path), "UTF-16", "iconv -f UTF-16 -t UTF-8", code=2, max_seconds=BOUND_S)


@pytest.mark.slow
@pytest.mark.parametrize("bad", [b"", b"{", b"\xff\xfe\x00"])
def test_empty_cut_or_binary_json(tmp_path, bad):
    path = session(tmp_path, bad)
    proc = run_recordings(tmp_path / "recs", tmp_path)
    assert_fails_cleanly(proc, str(path), code=2, max_seconds=BOUND_S)


def test_tilde_in_the_recordings_path_is_expanded(tmp_path):
    proc = run_recordings('"~/no_such_recordings"', tmp_path, env={"HOME": str(tmp_path)})
    assert_fails_cleanly(proc, f"recordings.path={tmp_path / 'no_such_recordings'} does not exist", code=2,
                         max_seconds=BOUND_S)


@pytest.mark.parametrize("kind", ["fifo", "utf16", "list"])
def test_a_compass_calibration_that_is_a_fifo_utf16_or_a_list(tmp_path, kind):
    from bionav.errors import UserError
    from bionav.polcompass.calibration import UnitCalibration

    path = tmp_path / "calibration.json"
    if kind == "fifo":
        os.mkfifo(path)
    else:
        path.write_bytes(json.dumps({"center_v": [1.0]}).encode("utf-16") if kind == "utf16" else b"[1, 2]")
    needle = {"fifo": "FIFO", "utf16": "UTF-16", "list": "JSON list"}[kind]
    with pytest.raises(UserError, match=needle):
        UnitCalibration.load(path)
