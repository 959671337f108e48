"""``device=`` (issue 42): validated where it enters; ``device=cuda`` without a GPU is one message with the fix."""

from __future__ import annotations

import pytest
from helpers import assert_fails_cleanly, run_bionav

NO_SIM = {"NUMBA_ENABLE_CUDASIM": "0"}  # the real driver path, whatever other tests set


def test_device_must_be_cpu_or_cuda(tmp_path):
    proc = run_bionav("homing=mfdid", "device=gpu", cwd=tmp_path, env=NO_SIM)
    assert_fails_cleanly(proc, "device", "cuda", code=2)


def test_device_cuda_without_a_gpu_names_the_fix(tmp_path):
    """No NVIDIA driver here: the run stops before any work, naming the install line and device=cpu."""
    import shutil

    pytest.importorskip("numba.cuda", reason="the GPU backend's extra: pip install 'bionav[gpu]'")
    if shutil.which("nvidia-smi"):
        pytest.skip("an NVIDIA driver is installed here")
    proc = run_bionav("homing=minwarping", "device=cuda", cwd=tmp_path, env=NO_SIM)
    err = assert_fails_cleanly(proc, "device=cuda", "bionav[gpu]", "device=cpu", code=2)
    assert "no usable NVIDIA GPU" in err


def test_device_cuda_refuses_a_method_the_gpu_does_not_compute():
    from bionav.errors import UserError
    from bionav.gpu import check_method

    check_method("minwarping")
    with pytest.raises(UserError, match="device=cuda computes homing=minwarping, warping2d, sift"):
        check_method("mfdid")


def test_gpu_bench_script_is_valid_bash_and_stops_without_a_gpu(tmp_path):
    """scripts/gpu-bench.sh (run on a GPU machine by a later session): parses, and says why it stops here."""
    import shutil
    import subprocess
    from pathlib import Path

    script = Path(__file__).resolve().parents[2] / "scripts" / "gpu-bench.sh"
    assert subprocess.run(["bash", "-n", str(script)], capture_output=True).returncode == 0
    if shutil.which("nvidia-smi"):
        pytest.skip("an NVIDIA driver is installed here: the script would run")
    proc = subprocess.run(["bash", str(script), str(tmp_path / "out")], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 3 and "needs an NVIDIA GPU" in proc.stderr
