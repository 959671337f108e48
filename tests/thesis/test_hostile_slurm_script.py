"""``scripts/slurm-localhost.sh stop`` with stale pid files (issue 32): a pid file naming a pid that now
belongs to an unrelated process must not get that process killed, and the script never acts on the
system's munge or MariaDB pid files (it keeps its own under ``$SLURM_LOCAL_DIR``)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "slurm-localhost.sh"

pytestmark = pytest.mark.skipif(os.geteuid() != 0 or sys.platform != "linux",
                                reason="the script needs root (it runs `sudo` otherwise) and /proc")


def test_stop_does_not_kill_an_unrelated_process_named_in_a_stale_pid_file(tmp_path):
    bystander = subprocess.Popen(["sleep", "300"])
    try:
        for name in ("slurmctld", "slurmd", "slurmdbd", "mariadbd", "munged"):
            (tmp_path / f"{name}.pid").write_text(f"{bystander.pid}\n")
        (tmp_path / "garbage.pid").write_text("1; rm -rf /\n")
        env = dict(os.environ, SLURM_LOCAL_DIR=str(tmp_path), SLURM_LOCAL_ACCOUNTING="0")
        proc = subprocess.run(["bash", str(SCRIPT), "stop"], env=env, capture_output=True, text=True, timeout=120)
        assert proc.returncode == 0, proc.stderr
        assert bystander.poll() is None, "the unrelated process was killed"
        status = subprocess.run(["bash", str(SCRIPT), "status"], env=env, capture_output=True, text=True, timeout=60)
        assert "slurmctld: stopped" in status.stdout and "munged: stopped" in status.stdout
    finally:
        bystander.kill()
        bystander.wait()


def test_the_script_never_names_the_systems_pid_files():
    text = SCRIPT.read_text()
    assert "/run/munge/munged.pid" not in text and "/run/mysqld/mysqld.pid" not in text
    assert "munged --stop" not in text  # that would stop the system's munge
