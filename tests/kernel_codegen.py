"""Compile bionav's hot numba kernels for one CPU target and dump their assembly (never executes them).

Run as a script in a fresh process (the target is fixed when numba starts)::

    python tests/kernel_codegen.py avx2 OUT.json
    python tests/kernel_codegen.py avx512 OUT.json

It sets ``NUMBA_CPU_NAME`` and ``NUMBA_CPU_FEATURES`` of the target (see
``docs/performance.md``), compiles every kernel of :data:`KERNELS` for the
numba types of small example arguments with ``dispatcher.compile(signature)``
and writes ``{"target": ..., "asm": {kernel: assembly}}`` as JSON. Code for
the AVX-512 target can be compiled and inspected on any x86-64 host, but is
never run here. :func:`kernel_asm` runs this script in a subprocess with its
own empty ``NUMBA_CACHE_DIR`` (cached code cannot be inspected, and code
cached for one target must not be loaded for another).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from bionav.bench.cpu import KNOWN_TARGETS

#: numba target per ISA: (NUMBA_CPU_NAME, NUMBA_CPU_FEATURES); the name alone does not change the features
#: (the feature strings have one home: bionav.bench.cpu.KNOWN_TARGETS)
TARGETS = {"avx2": ("haswell", KNOWN_TARGETS["haswell"]),
           "avx512": ("skylake-avx512", KNOWN_TARGETS["skylake-avx512"])}


def target_env(isa: str, cache_dir: str) -> dict:
    """Environment variables that make numba compile for ``isa`` (``avx2`` or ``avx512``) with its own cache."""
    name, features = TARGETS[isa]
    return {"NUMBA_CPU_NAME": name, "NUMBA_CPU_FEATURES": features, "NUMBA_CACHE_DIR": cache_dir}


def kernel_asm(isa: str, *, timeout: float = 600) -> dict:
    """Assembly of every kernel of :data:`KERNELS` compiled for ``isa``, from a subprocess."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "asm.json"
        env = dict(os.environ)
        env.update(target_env(isa, str(Path(tmp) / "numba-cache")))
        proc = subprocess.run([sys.executable, __file__, isa, str(out)], env=env, capture_output=True, text=True,
                              timeout=timeout)
        if proc.returncode != 0:
            raise RuntimeError(f"compiling the kernels for {isa} failed:\n{proc.stderr[-4000:]}")
        return json.loads(out.read_text())["asm"]


def _examples():
    """``{name: (dispatcher, example arguments)}`` for every hot kernel (arguments are only typed, never run)."""
    import importlib

    import numpy as np

    from bionav.evaluation import agent
    from bionav.homing import sift_kernels
    from bionav.homing.warping import distance, kernels, pair, vkernels
    from bionav.robot import coverage
    from bionav.world import intersect, mesh_kernels
    from bionav.world import kernels as world

    warping1d = importlib.import_module("bionav.homing.warping.warping1d")  # the package exports a function of that name

    f32, f64, i64, u8, u16 = np.float32, np.float64, np.int64, np.uint8, np.uint16
    w, step, n_planes = 48, 3, 3
    n = w // step

    def z(*shape, dtype=f64):
        return np.zeros(shape, dtype)

    def windows():
        return z(w + 1, dtype=i64), z(4, dtype=i64), z(4, dtype=i64), z(4, dtype=i64)

    ex = {}
    for tag, dt, big, acc in (("u8", u8, u8(255), u16), ("f32", f32, f32(np.inf), f32)):
        levels = z(2, n_planes, w, step, n, dtype=dt)
        dist = z(n_planes, w, step, n, dtype=dt)
        ex[f"fill_window_minima[{tag}]"] = (kernels.fill_window_minima, (levels,))
        ex[f"minwarp_scores[{tag}]"] = (kernels.minwarp_scores,
                                        (levels, n, z(4, dtype=i64), *windows(), big, z(4, n, dtype=acc)))
        ex[f"minwarp_scores_at[{tag}]"] = (kernels.minwarp_scores_at,
                                           (levels, z(4, dtype=i64), z(4, dtype=i64), *windows()))
        ex[f"minwarp_scores_runs[{tag}]"] = (kernels.minwarp_scores_runs,
                                             (levels, z(4, dtype=i64), 5, z(4, dtype=i64), *windows()))
        ex[f"compass_measure[{tag}]"] = (kernels.compass_measure, (dist, z(4, dtype=i64)))
        ex[f"swap_roles[{tag}]"] = (kernels.swap_roles, (dist, dist.copy()))
    dist = z(n_planes, w, step, n, dtype=f32)
    tab = z(5, w, dtype=np.int32)
    ex["warp2d_scores"] = (kernels.warp2d_scores, (dist, n, z(4, dtype=i64), tab, tab))
    ex["diagonal_distances[u8]"] = (distance._diagonal_distances_q,
                                    (z(n_planes, 9, w, dtype=np.int16), z(n_planes, 9, 2 * w + 1, dtype=np.int16),
                                     z(n_planes, w, dtype=np.int32), z(n_planes, 2 * w + 1, dtype=np.int32), step,
                                     227, z(n_planes, w, step, n, dtype=u8)))
    ex["diagonal_distances[f32]"] = (distance._diagonal_distances,
                                     (z(n_planes, 9, w, dtype=f32), z(n_planes, 9, 2 * w, dtype=f32),
                                      z(n_planes, w, dtype=f32), z(n_planes, 2 * w, dtype=f32), step,
                                      z(n_planes, w, step, n, dtype=f32)))
    # the explicit-vector kernels (issue 42): search and distance sums, padded buffers as the search gives them
    ex["minwarp_search_u8"] = (vkernels.minwarp_search_u8,
                               (z(2 * n_planes * w * step * n + vkernels.TABLE_PAD, dtype=u8), n_planes, w, step, n,
                                z(4, dtype=i64), *windows(), z(4, vkernels.padded_lanes(n), dtype=u16),
                                z(vkernels.search_scratch_size(n), dtype=u8)))
    ex["diagonal_distances_u8"] = (vkernels.diagonal_distances_u8,
                                   (z(n_planes, 9, w, dtype=np.int16), z(n_planes, 9, 2 * w + 4, dtype=np.int16),
                                    z(n_planes, w, dtype=np.int32), z(n_planes, 2 * w + 4, dtype=np.int32), step, 227,
                                    z(n_planes, w, step, n, dtype=u8), z(w + 4, w, dtype=u16)))
    # the whole quantised pair in one compiled call (issue 42): the kernels above and the selection, argmin, fine search
    stack, table = z(n_planes, 9, w, dtype=f32), z(2, n_planes, w, step, n, dtype=u8)
    flat = z(table.size + vkernels.TABLE_PAD, dtype=u8)
    ex["minwarp_pair_u8"] = (pair.minwarp_pair_u8,
                             ((stack, stack, stack, stack), (f32(1), f32(1)), step, 227, z(4, dtype=i64), z(4, dtype=i64),
                              2, windows(), True, False, True, 1, 1,
                              (z(n_planes, 9, w, dtype=np.int16), z(n_planes, w, dtype=np.int32),
                               z(n_planes, 9, 2 * w + 4, dtype=np.int16), z(n_planes, 2 * w + 4, dtype=np.int32),
                               z(w + 4, w, dtype=u16), table, flat, table, flat,
                               z(vkernels.search_scratch_size(n), dtype=u8))))
    ex["warping1d_scores"] = (warping1d._warp1d_scores, (z(w), z(4 * w + 1), z(3), z(3), z(3)))
    # SIFT matching: descriptors float32, keys int64
    xa, da, na = z(16), z(16, 128, dtype=f32), z(16, dtype=i64)
    ex["sift_scan_core"] = (sift_kernels._scan_core,
                            (z(16, dtype=np.int32), na, i64(0), na.copy(), na.copy(), True, 0, 16, i64(0)))
    ex["sift_scan_edge"] = (sift_kernels._scan_edge,
                            (z(16, dtype=np.int32), na, i64(0), na.copy(), na.copy(), True, 0, 16, i64(0), 0.0, 0.0, xa, xa,
                             1.0, 1.0))
    ex["sift_match_sorted"] = (sift_kernels.match_sorted,
                               (xa, xa, da, na, na, xa, xa, da, na, na, 1.0, 1.0, na.copy(), na.copy(), True))
    # renderers: ray casting (scalar per ray)
    ex["mesh_cast_kernel"] = (mesh_kernels.cast_kernel,
                              (0.0, 0.0, 0.0, z(4), z(4), z(2, 9), 0.0, 0.0, 1.0, 1, 1, z(2, dtype=i64),
                               z(1, dtype=i64), z(1), z(1), 1.0, 0.0, True, z(4, 4), z(4, 4, dtype=i64)))
    ex["mesh_fill_grid"] = (mesh_kernels._fill_grid,
                            (z(2, 3, 3), 0.0, 0.0, 1.0, 1, 1, False, z(2, dtype=i64), z(1, dtype=i64), z(1), z(1)))
    ex["world_candidates"] = (intersect._candidates,
                              (0.0, 0.0, 0.0, z(4), 0.0, z(1, dtype=i64), z(1, dtype=i64), z(1, 9), z(1, 6),
                               z(1, 6)))
    ex["world_depth_kernel"] = (world.depth_kernel,
                                (0.0, 0.0, 0.0, z(4), z(4), 0.0, z(1, dtype=i64), z(1, dtype=i64), z(1, 4), z(1, 9),
                                 z(1, 6), z(1, 6), z(4, 4), z(4, 4, dtype=i64), z(4, 4, dtype=i64)))
    i2 = z(1, 6, dtype=i64)
    ex["world_render_kernel"] = (world.render_kernel,
                                 (0.0, 0.0, 0.0, z(4), z(4), 0.0, z(1, 10), i2, z(1, 7), z(1, 3, dtype=i64), z(1, 7),
                                  z(1, dtype=i64), z(1, dtype=i64), z(1, dtype=i64), z(1, 4), z(1, 6), i2, i2,
                                  z(1, dtype=i64), z(1), z(1, 2), z(1, 3), z(1, 3), z(16, dtype=f32), 4, z(1, 6),
                                  z(1, 3), z(3), z(3), True, z(4, 4, 3), z(4, 4), z(4, 4, dtype=np.bool_)))
    ex["world_surface_kernel"] = (world.surface_kernel,
                                  (0.0, 0.0, 0.0, z(4), z(4, 3), 360, z(1, 10), i2, z(1, 7), z(1, 3, dtype=i64),
                                   z(1, 7), z(1, dtype=i64), z(1, dtype=i64), z(1, dtype=i64), z(1, 4), z(1, 6), i2,
                                   i2, z(1, 6), 0, z(4), z(4, 3), z(4, 3), z(4, dtype=i64), z(4)))
    # cleaning-robot coverage and the return agent (the parameter sweep's batch)
    ex["coverage_sweep"] = (coverage._sweep_kernel, (z(4, 4), 0.0, 0.0, 1.0, 4, 4))
    ex["agent_success"] = (agent._agent_success_kernel,
                           (z(1, 2, 3), z(1, 2, 3), z(2, 2), z(3, 2), z(4, 4, dtype=i64), 0, z(17, dtype=i64),
                            z(3, dtype=i64), z(3), z(3), 10, 0.5, 1.0, z(1, 2, 3, dtype=np.bool_)))
    return ex


def main(isa: str, out: str) -> None:
    name, features = TARGETS[isa]
    if os.environ.get("NUMBA_CPU_NAME") != name or os.environ.get("NUMBA_CPU_FEATURES") != features:
        raise SystemExit(f"run with the environment of target_env({isa!r}, cache_dir)")
    from numba import typeof

    asm = {}
    for kname, (dispatcher, args) in _examples().items():
        sig = tuple(typeof(a) for a in args)
        dispatcher.compile(sig)  # compile only: AVX-512 code must not run on a host without it
        asm[kname] = dispatcher.inspect_asm(sig)
    Path(out).write_text(json.dumps({"target": isa, "asm": asm}))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
