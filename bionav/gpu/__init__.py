"""All-pairs homing on an NVIDIA GPU (``device=cuda``): optional, never needed.

``python -m bionav ... device=cuda`` computes the all-pairs home vectors of grid homing and the
cross-database test on the GPU for ``homing=minwarping`` (and its presets), ``homing=warping2d``
and ``homing=sift``; everything else (the per-image work, the return agents, the plots) stays on
the CPU. The kernels are written with numba-cuda (``pip install "bionav[gpu]"``) and give the
CPU kernels' results: bit for bit where the arithmetic is integer (min-warping's distance sums,
window minima and search, SIFT's descriptor distances and matches), within the stated tolerances
where it is floating point (see :mod:`bionav.gpu.minwarp`, :mod:`bionav.gpu.warp2d`). Their
correctness tests run in numba-cuda's CUDA simulator (``NUMBA_ENABLE_CUDASIM=1``) on tiny images,
so CI checks them without a GPU.

:func:`check_device` is called where the value enters (the run settings), before any work: a
selected ``device=cuda`` without the extra or without a usable GPU is one message with the fix.
"""

from __future__ import annotations

#: values of the top-level ``device`` key
DEVICES = ("cpu", "cuda")
#: homing methods the GPU backend computes (plugin names; their presets share the code)
GPU_METHODS = ("minwarping", "warping2d", "sift")
INSTALL = 'pip install "bionav[gpu]"'


def cuda_module():
    """``numba.cuda`` (the simulator when ``NUMBA_ENABLE_CUDASIM=1``), or UserError with the install line."""
    import os

    from bionav.errors import UserError

    try:
        from numba.core import config

        if os.environ.get("NUMBA_ENABLE_CUDASIM") == "1" and not config.ENABLE_CUDASIM:
            config.reload_config()  # numba read the environment before it was set (tests)
        from numba import cuda
    except ImportError:  # pragma: no cover - depends on the installation
        raise UserError(f"device=cuda needs numba-cuda, which is not installed: {INSTALL} (and an NVIDIA driver); "
                        "or run on the CPU with device=cpu.") from None
    if not hasattr(cuda, "jit"):  # pragma: no cover - numba without numba-cuda's target
        raise UserError(f"device=cuda needs numba-cuda: {INSTALL}; or run on the CPU with device=cpu.")
    return cuda


def check_device(device: str) -> None:
    """Refuse ``device=cuda`` without numba-cuda or without a GPU, with one message naming the fix."""
    from bionav.errors import UserError

    if device not in DEVICES:
        raise UserError(f"device={device!r} is not a device; choose one of {', '.join(DEVICES)} "
                        "(cuda: an NVIDIA GPU, see docs/performance.md).")
    if device == "cpu":
        return
    cuda = cuda_module()
    try:
        ok = bool(cuda.is_available())
    except Exception:  # noqa: BLE001 - a broken driver stack raises its own errors
        ok = False
    if not ok:
        raise UserError("device=cuda: no usable NVIDIA GPU here (numba-cuda found no CUDA driver or device). "
                        "Run on a machine with an NVIDIA GPU and its driver (nvidia-smi lists it), with "
                        f"{INSTALL}; or use device=cpu.")


def check_method(name: str) -> None:
    """Refuse ``device=cuda`` for a homing method the GPU backend does not compute."""
    from bionav.errors import UserError

    if name not in GPU_METHODS:
        raise UserError(f"device=cuda computes homing={', '.join(GPU_METHODS)} (and their presets), not "
                        f"homing={name}; run it with device=cpu.")
