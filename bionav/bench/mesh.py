"""Time the mesh-world renderer: ``python -m bionav.bench.mesh [--json]``.

Rows (CPU and wall time, warm-up excluded):

* ``panorama`` -- one 561 x 81 canonical panorama of the packaged Seville 2009
  ant world (5,000 triangles) at ant-eye height, median over several poses on
  the open ground (target: <= 20 ms on one core);
* ``grid_20x20`` -- the images of a 20 x 20 grid database at 0.25 m in the
  same world, rendered with ``--threads`` numba threads (target: <= 15 s on
  2 cores; no cache, no quantisation);
* ``panorama_50k`` -- a 561 x 81 panorama of a random 50,000-triangle soup
  of the same extent (scaling of the uniform grid).
"""

from __future__ import annotations

import json
import time

import numpy as np


def _timed(fn):
    c0, w0 = time.process_time(), time.perf_counter()
    fn()
    return 1e3 * (time.process_time() - c0), 1e3 * (time.perf_counter() - w0)


def main(argv=None) -> int:
    from bionav.bench._cli import BenchParser, bounded_int

    parser = BenchParser(prog="python -m bionav.bench.mesh",
                                     description="Time the mesh renderer (CPU and wall ms; warm-up excluded).")
    parser.add_argument("--json", action="store_true", help="one JSON object per line")
    parser.add_argument("--threads", type=int, default=2, help="threads of the grid row (default: 2)")
    parser.add_argument("--repeat", type=int, default=10, help="timed panoramas per pose (default: 10; 1..1000)")
    parser.add_argument("--grid", type=int, default=20, help="grid side of the database row (default: 20; 1..50)")
    args = parser.parse_args(argv)
    bounded_int(parser, "--repeat", args.repeat, 1, 1000)
    bounded_int(parser, "--grid", args.grid, 1, 50)

    import numba

    from bionav.db.mesh import mesh_world, seville_world_path
    from bionav.geometry import PanoramaGeometry
    from bionav.world.mesh import mesh_from_arrays
    from bionav.world.mesh_render import MeshWorld, render_mesh_panorama

    bounded_int(parser, "--threads", args.threads, 1, numba.config.NUMBA_NUM_THREADS,
                " (numba's threads on this machine)")
    world = mesh_world(seville_world_path())
    g = PanoramaGeometry.square_pixels(561, 81)
    poses = [(3.0, 5.0, 0.01), (4.5, 6.5, 0.01), (5.1, 1.5, 0.01), (7.5, 2.0, 0.01)]
    rows = []

    def panorama_row(name, w, note):
        for p in poses:
            render_mesh_panorama(w, position=p, geometry=g)  # warm-up (numba compilation)
        cpu, wall = [], []
        for p in poses:
            for _ in range(args.repeat):
                c, t = _timed(lambda p=p: render_mesh_panorama(w, position=p, geometry=g, threads=1))
                cpu.append(c)
                wall.append(t)
        rows.append({"benchmark": name, "threads": 1, "size": "561x81", "triangles": len(w.mesh),
                     "cpu_ms": float(np.median(cpu)), "wall_ms": float(np.median(wall)), "note": note})

    panorama_row("panorama", world, "median over 4 poses")
    n = args.grid
    xs = 2.5 + 0.25 * np.arange(n)
    cams = [(x, y, 0.01) for x in xs for y in 1.0 + 0.25 * np.arange(n)]
    c, t = _timed(lambda: [render_mesh_panorama(world, position=p, geometry=g, threads=args.threads) for p in cams])
    rows.append({"benchmark": f"grid_{n}x{n}", "threads": args.threads, "size": "561x81", "triangles": len(world.mesh),
                 "cpu_ms": c, "wall_ms": t, "note": f"{len(cams)} images"})
    rng = np.random.default_rng(0)
    centres = rng.uniform([0, 0, 0], [10, 10, 0.8], size=(50_000, 3))
    soup = MeshWorld(mesh_from_arrays(centres[:, None, :] + rng.normal(0, 0.05, size=(50_000, 3, 3))))
    panorama_row("panorama_50k", soup, "random soup, median over 4 poses")
    from bionav.bench.cpu import numba_target

    target = numba_target()
    for r in rows:
        r.update(target)
        if args.json:
            print(json.dumps(r))
        else:
            print(f"{r['benchmark']:<14} threads={r['threads']} {r['size']} {r['triangles']:>6} triangles  "
                  f"cpu {r['cpu_ms']:9.1f} ms  wall {r['wall_ms']:9.1f} ms  ({r['note']})")
    return 0


if __name__ == "__main__":
    from bionav.bench._cli import run

    run(main, "python -m bionav.bench.mesh")
