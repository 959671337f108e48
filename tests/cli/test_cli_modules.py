"""Command-line modules outside the Hydra entry: the fake-device server and the replay checker."""

import signal
import subprocess
import sys

import pytest


@pytest.mark.parametrize("scene, overrides", [
    ("spectral", ["sensor=spectral5_serial sensor.port=/dev/pts/", "pantilt=ptu46 pantilt.port=/dev/pts/"]),
    ("polcompass", ["sensor=polcompass_serial sensor.port=/dev/pts/", "pantilt=ptu46 pantilt.port=/dev/pts/",
                    "sensor=tcm2 sensor.port=/dev/pts/"]),
])
def test_fake_server_prints_one_override_per_device_and_stops_on_ctrl_c(scene, overrides):
    proc = subprocess.Popen([sys.executable, "-m", "bionav.plugins.sensors.fakes", "--scene", scene],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        lines = [proc.stdout.readline() for _ in overrides]
        assert "serving" in proc.stderr.readline()
    finally:
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=20)
    for line, want in zip(lines, overrides):
        assert want in line
    assert proc.returncode == 0 and "Traceback" not in err


def test_fake_server_stops_on_ctrl_c_even_when_started_with_sigint_ignored():
    """A shell running a script's background job hands it SIGINT ignored (and Python keeps that):
    the server takes Ctrl-C back, so that it still stops."""
    proc = subprocess.Popen([sys.executable, "-m", "bionav.plugins.sensors.fakes", "--scene", "polcompass"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN))
    try:
        assert "serving" in proc.stderr.readline()
    finally:
        proc.send_signal(signal.SIGINT)
        try:
            _, err = proc.communicate(timeout=20)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.communicate()
            raise AssertionError("the fake server ignored Ctrl-C") from None
    assert proc.returncode == 0 and "Traceback" not in err


def test_replay_of_a_missing_log_is_one_clear_error(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "bionav.experiments.cleaning_replay", str(tmp_path / "nowhere")],
                          capture_output=True, text=True)
    assert proc.returncode == 2
    assert proc.stderr.startswith("bionav.experiments.cleaning_replay: error:") and "Traceback" not in proc.stderr
