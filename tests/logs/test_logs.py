"""MCAP logs: round trip, crash-safe flushing, recovery of a truncated file, the CLI."""

import subprocess
import sys

import numpy as np

from bionav.logs import McapLog, read_attachment, read_messages, read_metadata, recover


def _write(path, n=500, flush_interval_s=2.0):
    log = McapLog(path, flush_interval_s=flush_interval_s)
    log.attach("config.yaml", b"seed: 1\n", media_type="application/yaml")
    log.metadata("plugins", {"homing": "sift (bionav 0.1.0)"})
    for i in range(n):
        log.write("/test/values", {"i": i, "v": np.arange(3) * i}, schema_name="bionav.Test", log_time_ns=1000 + i)
    return log


def test_round_trip(tmp_path):
    path = tmp_path / "run.mcap"
    _write(path).close()
    msgs = list(read_messages(path))
    assert [m[2]["i"] for m in msgs] == list(range(500))
    assert msgs[7] == ("/test/values", 1007, {"i": 7, "v": [0, 7, 14]})
    assert read_attachment(path, "config.yaml") == b"seed: 1\n"
    assert read_metadata(path)["plugins"]["homing"] == "sift (bionav 0.1.0)"


def test_crash_mid_run_is_recoverable(tmp_path):
    """A process killed while writing leaves a file whose flushed messages recover."""
    path = tmp_path / "run.mcap"
    code = (
        "import os, sys\n"
        "from bionav.logs import McapLog\n"
        f"log = McapLog({str(path)!r}, flush_interval_s=0.0)\n"
        "for i in range(300):\n"
        "    log.write('/crash/i', {'i': i}, schema_name='bionav.Test')\n"
        "os._exit(1)\n"  # no close(): the summary and footer are never written
    )
    subprocess.run([sys.executable, "-c", code], check=False)
    out = tmp_path / "repaired.mcap"
    report = recover(path, out)
    assert report.truncated
    assert report.messages == 300
    assert [m[2]["i"] for m in read_messages(out)] == list(range(300))


def test_truncated_file_keeps_every_complete_message(tmp_path):
    path = tmp_path / "run.mcap"
    log = _write(path, n=0)
    for i in range(400):
        log.write("/test/values", {"i": i}, schema_name="bionav.Test")
        if i % 50 == 49:
            log.flush()
    log.close()
    data = path.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: int(len(data) * 0.8)])
    report = recover(cut, tmp_path / "fixed.mcap")
    got = [m[2]["i"] for m in read_messages(tmp_path / "fixed.mcap")]
    assert report.truncated
    assert got == list(range(len(got))) and len(got) >= 200  # complete chunks, in order, none invented


def test_logs_cli_info_and_recover(tmp_path):
    path = tmp_path / "run.mcap"
    _write(path).close()
    info = subprocess.run([sys.executable, "-m", "bionav.logs", "info", str(path)], capture_output=True, text=True)
    assert info.returncode == 0 and "/test/values" in info.stdout and "500" in info.stdout
    bad = subprocess.run(
        [sys.executable, "-m", "bionav.logs", "info", str(tmp_path / "nope.mcap")], capture_output=True, text=True
    )
    assert bad.returncode == 2 and "does not exist" in bad.stderr and "Traceback" not in bad.stderr
    (tmp_path / "half.mcap").write_bytes(path.read_bytes()[:3000])
    rec = subprocess.run(
        [sys.executable, "-m", "bionav.logs", "recover", str(tmp_path / "half.mcap"), str(tmp_path / "ok.mcap")],
        capture_output=True,
        text=True,
    )
    assert rec.returncode == 0 and "truncated input" in rec.stdout
    assert subprocess.run([sys.executable, "-m", "bionav.logs", "info", str(tmp_path / "ok.mcap")]).returncode == 0
