"""``python -m bionav.bench --method stages``: min-warping's stages against the machine's arithmetic floor.

For one pair of the bench's pillar-room views at ``--size`` (default 288 x 50, ``--steps`` 96 x 96)
each stage of :func:`bionav.homing.warping.minwarping` is timed alone (CPU time, minimum over
``--repeat`` rounds of ``--batch`` calls; the stages and the whole home vectors interleaved round by round) and set against its floor: the byte-lane operations the
stage's arithmetic needs, counted from the kernels (a 16-bit operation counts 2 byte lanes, a
32-bit one 4), over ``2 vector instructions per cycle x 64 byte lanes x clock`` (two 512-bit
instructions per cycle; the clock is measured, :func:`clock_ghz`). Counted per pair (``K`` planes,
``R`` rows, ``W`` columns, ``P`` rotations, ``n`` alpha steps, ``E`` windows, ``J`` window levels):

* quantise: both stacks, multiply, round, convert: ``2 K R W x 3 x 4``;
* distances: ``K R W^2`` terms of ``|a - b|`` summed (subtract, absolute value, add on 16 bits: ``x 3 x 2``)
  and ``K W^2`` normalisations (add, convert, multiply, divide, add, convert on 32 bits: ``x 6 x 4``);
* window minima: ``J K W^2`` byte minima;
* compass measure: ``P K W`` byte minima and ``P W`` 16-bit additions;
* search: ``E P n`` byte minima and ``W P n`` 16-bit additions (widened bytes);
* double search: the transposed table (``K W^2`` byte moves), its window minima and a second search;
* fine search: the runs of directions around the best hypothesis (``E`` minima per value).

The rows give ``floor_ms``, ``cpu_ms`` (minimum), ``fraction_of_floor``; the ``home vector`` rows
time whole calls of the plugin (the Python around the kernels included) against the sum of the
floors of their stages.
"""

from __future__ import annotations

import os
import time

import numpy as np

#: byte lanes of one vector instruction and vector instructions per cycle of the floor
LANES, PER_CYCLE = 64, 2


def clock_ghz() -> float:
    """The core clock in GHz, from a dependent chain of integer multiplications (3 cycles each on x86-64)."""
    from numba import njit

    @njit(cache=False)
    def chain(x, n):
        for _ in range(n):
            x = x * x  # one dependent imul per iteration (3 cycles)
        return x

    @njit(cache=False)
    def chain2(x, n):
        for _ in range(n):
            x = x * x
            x = x * x
        return x

    n = 20_000_000
    chain(3, 10), chain2(3, 10)
    best1 = best2 = float("inf")
    for _ in range(3):
        c0 = time.process_time()
        chain(3, n)
        best1 = min(best1, time.process_time() - c0)
        c0 = time.process_time()
        chain2(3, n)
        best2 = min(best2, time.process_time() - c0)
    # the second chain has one more dependent multiplication per iteration: its extra time is n x 3 cycles
    return n * 3.0 / max(best2 - best1, 1e-9) / 1e9


def _pair(args):
    from bionav.bench.pairs import POSES
    from bionav.plugins.homing.warping import MinWarping
    from bionav.testing.pillar_scene import render_pillar_panorama

    w, h = args.size
    snap, geo = render_pillar_panorama((0.0, 0.0), width=2 * w, height=2 * h, supersample=2)
    cur = render_pillar_panorama(POSES[0][0], heading=POSES[0][1], width=2 * w, height=2 * h, supersample=2)[0]
    methods = {name: MinWarping(MinWarping.Config(image_size=[w, h], n_alpha=args.steps, n_psi=args.steps,
                                                  compass_fraction=args.compass_fraction, **opts), geometry=geo)
               for name, opts in (("single", {}), ("compass", {"compass_acceleration": True}),
                                  ("double_fine", {"double_search": True, "fine_search": True}))}
    m = methods["single"]
    return methods, m.prepare(snap), m.prepare(cur)


def stage_rows(args) -> list[dict]:
    """One row per stage and per whole home vector (see the module docstring)."""
    from bionav.bench.calibration import _interleaved_min_ms
    from bionav.homing.warping import search as S
    from bionav.homing.warping.distance import _quantise, diagonal_distances
    from bionav.homing.warping.kernels import compass_measure, fill_window_minima, minwarp_scores_runs, swap_roles

    methods, s, c = _pair(args)
    single = methods["single"]
    single.home_vector(s, c)
    _, windows = single._template
    k, r, w = np.shape(s["snap"])
    p_all = S._column_grid(args.steps, w)
    step = S._layout_step(w, args.steps, p_all, True)
    n = w // step
    levels = S._window_minima(s, c, step, windows, True)
    n_levels = levels.shape[0] - 1
    levels2 = S._table("levels2_stages", levels.shape, levels.dtype)
    n_comp = max(1, int(np.ceil(args.compass_fraction * p_all.size)))
    e_count, p_count = int(windows[0][-1]), int(p_all.size)
    snapf = np.ascontiguousarray(s["snap"], np.float32)
    sq, sn = np.empty((k, r, w), np.int16), np.empty((k, w), np.int32)
    ra = max(1, int(np.ceil(w / args.steps)) - 1)
    pc = np.arange(-ra, ra + 1, dtype=np.int64) % w
    a_first = np.full(pc.size, (w - ra) % w, dtype=np.int64)
    stages = [
        ("quantise (both stacks)", 2 * k * r * w * 3 * 4, lambda: (_quantise(snapf, np.float32(1.0), sq, sn),
                                                                     _quantise(snapf, np.float32(1.0), sq, sn))),
        ("distances (sums + normalisation)", k * r * w * w * 6 + k * w * w * 24,
         lambda: diagonal_distances(s, c, step=step, out=levels[0], quantised=True)),
        ("window minima", n_levels * k * w * w, lambda: fill_window_minima(levels)),
        (f"compass measure ({p_count} psi)", p_count * (k * w + 2 * w), lambda: compass_measure(levels[0], p_all)),
        (f"search ({p_count} psi)", e_count * p_count * n + w * p_count * n * 2,
         lambda: S._search(levels, n, p_all, windows, True)),
        (f"search ({n_comp} psi, compass)", e_count * n_comp * n + w * n_comp * n * 2,
         lambda: S._search(levels, n, p_all[:n_comp], windows, True)),
        ("double search: transposed table + its minima", k * w * w + n_levels * k * w * w,
         lambda: (swap_roles(levels[0], levels2[0]), fill_window_minima(levels2))),
        ("fine search (both directions)", 2 * e_count * pc.size * (2 * ra + 1) * 2,
         lambda: (minwarp_scores_runs(levels, a_first, 2 * ra + 1, pc, *windows),
                  minwarp_scores_runs(levels2, a_first, 2 * ra + 1, pc, *windows))),
    ]
    ghz = args.clock_ghz or clock_ghz()
    per_ms = LANES * PER_CYCLE * ghz * 1e6  # byte-lane operations per millisecond at the floor
    names = [x[0] for x in stages]
    wholes = {"single": names[:2] + names[2:3] + names[4:5],
              "compass": names[:4] + names[5:6],
              "double_fine": names[:3] + names[4:5] * 2 + names[6:8]}
    # stages and whole home vectors interleaved round by round (calibration's rule: a burst of other work
    # spoils a round of every stage, not all rounds of one)
    work = {name: (fn, args.batch or 6) for name, _, fn in stages}
    work.update({f"home vector, {v}": (lambda m=methods[v]: m.home_vector(s, c), args.batch or 6) for v in wholes})
    times = list(_interleaved_min_ms(work, args.repeat).values())
    rows, floors = [], {}
    for (name, ops, _), ms in zip(stages, times):
        floors[name] = ops / per_ms
        rows.append({"stage": name, "byte_lane_ops": int(ops), "floor_ms": round(ops / per_ms, 6),
                     "cpu_ms": round(ms, 6), "fraction_of_floor": round(ops / per_ms / ms, 4)})
    for (variant, parts), ms in zip(wholes.items(), times[len(stages):]):
        floor = sum(floors[p] for p in parts)
        rows.append({"stage": f"home vector, {variant}", "byte_lane_ops": None, "floor_ms": round(floor, 6),
                     "cpu_ms": round(ms, 6), "fraction_of_floor": round(floor / ms, 4)})
    common = {"image": f"{args.size[0]}x{args.size[1]}", "steps": args.steps, "clock_ghz": round(ghz, 3),
              "loadavg_1min": round(os.getloadavg()[0], 2)}
    return [{**row, **common} for row in rows]
