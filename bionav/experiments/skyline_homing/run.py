"""``experiment=skyline_homing``: outdoor homing from five-channel images under changing light (beyond thesis 6.5).

The thesis' own outdoor homing test failed for lack of good data (6.5.3). Here
a synthetic five-channel outdoor world (a garden: shrubs, trees, buildings,
a distant tree line; spectral daylight of :mod:`bionav.light.daylight`) is
rendered on a full grid under several conditions (sun position and cloud
state). Every *representation* — single channels, dual-channel contrasts,
binary skylines from the ``J_sigma`` lines learned on natural samples — is fed
to the configured homing method (``homing=<any plugin>``, default ``mfdid``)
with snapshots under one condition and current views under another (all pairs,
the diagonal being "no light change"). AAE*, MAE* and RR* per representation
and condition pair go to ``skyline_homing.csv``; metrics.json holds ``rr``,
``aae`` (mean over changed-light pairs) and ``rr_same``, ``aae_same`` (same
light), each keyed by representation, and ``best_representation`` (highest
``rr`` under changed light). The thesis' 2 m square test (6.5.2: four corners
of a 2 m square, home vectors between all of them) gives ``square_aae`` per
representation.
"""

from __future__ import annotations

import numpy as np

from bionav.errors import UserError
from bionav.experiments.common import load_samples
from bionav.experiments.skyline_homing.config import SkylineHomingConfig
from bionav.experiments.skyline_homing.plots import plot_skyline_homing
from bionav.files import write_csv_atomic
from bionav.light.sun import parse_time

CELL_TOPIC = "/skyline_homing/cell"


def _conditions(exp: SkylineHomingConfig):
    """``(name, time, cloud cover, cloud optical depth)`` of every light condition."""
    out = []
    for k, c in enumerate(exp.conditions):
        t = parse_time(str(c.time), what=f"experiment.conditions[{k}].time", naive_utc=False)
        out.append((str(c.name), t, float(c.cloud_cover), float(c.cloud_optical_depth)))
    if not out:
        raise UserError("experiment.conditions is empty; give at least one {name, time, cloud_cover, "
                        "cloud_optical_depth}.")
    return out


def run(exp: SkylineHomingConfig, ctx) -> dict:
    """Run ``experiment=skyline_homing`` with the checked ``exp`` (the rest of the config in ``ctx.cfg``)."""
    from bionav.experiments.common import make_homing
    from bionav.spectral.lda_analysis import learn_discriminants
    from bionav.spectral.sensor_model import LogSensorModel

    cfg = ctx.cfg
    conditions = _conditions(exp)
    reps = _representations(exp)
    world_name, (nx, ny), spacing, geometry = _world_grid(exp)
    sensor_model = LogSensorModel(noise_counts=exp.noise_counts)
    disc = learn_discriminants(load_samples(exp.learn), sigma=exp.sigma)
    border = exp.separation

    gx, gy = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
    positions = np.c_[gx.ravel(), gy.ravel()]
    side = exp.square_side_m
    square_cells = np.array([[0, 0], [1, 0], [0, 1], [1, 1]])
    centre = np.array([nx - 1, ny - 1]) * spacing / 2
    square_pos = centre - side / 2 + square_cells * side
    do_square = exp.square_test

    counts, squares, truths = _render_conditions(exp, ctx, conditions, world_name, geometry, positions, (nx, ny),
                                                 spacing, square_pos if do_square else None, sensor_model)
    np.savez_compressed(ctx.dir / "panoramas.npz", counts=np.stack(counts), sky=np.stack(truths),
                        positions=positions, conditions=np.array([c[0] for c in conditions]))

    method = make_homing(cfg, ctx, geometry)
    stride = max(1, exp.snapshot_stride)
    snap_idx = np.flatnonzero((positions[:, 0] % stride == 0) & (positions[:, 1] % stride == 0))
    names = [c[0] for c in conditions]
    n = len(conditions)
    rows, square_rows, ms = [], [], []
    results = {r: {k: np.full((n, n), np.nan) for k in ("aae", "mae", "rr")} for r in reps}
    square = {r: np.full((n, n), np.nan) for r in reps}
    for rep in ctx.progress(reps, desc="representations"):
        images = [_representation_images(c, rep, disc, border) for c in counts]
        _grid_cells(cfg, ctx, exp, method, rep, images, names, positions, (nx, ny), spacing, geometry, snap_idx,
                    results[rep], rows, ms)
        if do_square:
            _square_cells(method, rep, [_representation_images(s, rep, disc, border) for s in squares], names,
                          square_cells, side, geometry, square[rep], square_rows)

    _write_csv(ctx.dir / "skyline_homing.csv", rows, ["representation", "snapshot_condition", "current_condition",
                                                       "aae", "mae", "rr"])
    if do_square:
        _write_csv(ctx.dir / "square_test.csv", square_rows, ["representation", "snapshot_condition",
                                                               "current_condition", "aae"])
    metrics = _summary_metrics(cfg, reps, n, len(positions), len(snap_idx), results, ms,
                               square if do_square else None)
    if exp.plots:
        plot_skyline_homing(ctx.plots, counts, disc, reps, names, metrics, results, border)
    return metrics


def _representation_images(counts, rep: str, disc, border: str):
    """The images of representation ``rep`` of sensor counts (:func:`bionav.spectral.representations.representation_image`)."""
    from bionav.spectral.representations import representation_image

    return representation_image(counts, rep, discriminants=disc, threshold=border)


def _representations(exp) -> list[str]:
    """``experiment.representations``, each checked (one message naming the bad one)."""
    from bionav.spectral.representations import check_representation

    reps = [str(r) for r in exp.representations]
    for r in reps:
        try:
            check_representation(r)
        except ValueError as exc:
            raise UserError(f"experiment.representations: {exc}.") from None
    return reps


def _world_grid(exp):
    """The world's name, grid shape ``(nx, ny)``, spacing (m) and the panoramas' geometry.

    The campus world brings its own grid; the garden takes ``experiment.grid`` and ``experiment.spacing_m``.
    """
    from bionav.geometry import PanoramaGeometry

    world_name = exp.world
    nx, ny = exp.grid
    spacing = exp.spacing_m
    if world_name == "campus":
        from bionav.world.worlds.outdoor import GRID_SHAPE, SPACING

        (nx, ny), spacing = GRID_SHAPE, SPACING
    width, height = exp.image_width, exp.image_height
    top = np.deg2rad(exp.elevation_top_deg)
    rad_per_row = 2 * np.pi / width
    geometry = PanoramaGeometry(width, height, top / rad_per_row, rad_per_row)
    return world_name, (nx, ny), spacing, geometry


def _render_conditions(exp, ctx, conditions, world_name, geometry, positions, grid_shape, spacing, square_pos,
                       sensor_model):
    """Sensor counts and sky masks of every grid cell under every sky condition (and of the square test's
    four positions, metres, when ``square_pos`` is given)."""
    from bionav.light.clouds import CloudLayer
    from bionav.light.daylight import SkyState
    from bionav.world.worlds.garden import garden_scene, render_garden_counts
    from bionav.world.worlds.outdoor import campus_world, render_campus_counts

    nx, ny = grid_shape
    seed = exp.world_seed
    extent = max(nx - 1, ny - 1) * spacing
    world_pos = positions * spacing
    counts, squares, truths = [], [], []
    for k, (name, t, cover, tau) in enumerate(conditions):
        sky = SkyState.from_time(t, clouds=CloudLayer(cover=cover, optical_depth=tau, seed=seed + 1),
                                 turbidity=exp.turbidity)
        if world_name == "campus":
            world = campus_world(sky, seed=seed)
            c, truth = render_campus_counts(world, geometry, positions, sensor_model=sensor_model, rng=ctx.rng,
                                            progress=ctx.progress)
            if square_pos is not None:
                squares.append(render_campus_counts(world, geometry, square_pos / spacing,
                                                    sensor_model=sensor_model, rng=ctx.rng)[0])
        else:
            scene = garden_scene(sky, seed=seed, grid_extent=extent)
            c, truth = render_garden_counts(scene, geometry, world_pos, sensor_model=sensor_model, rng=ctx.rng,
                                               progress=ctx.progress)
            if square_pos is not None:
                squares.append(render_garden_counts(scene, geometry, square_pos, sensor_model=sensor_model,
                                                       rng=ctx.rng)[0])
        counts.append(c)
        truths.append(truth)
    return counts, squares, truths


def _grid_cells(cfg, ctx, exp, method, rep, images, names, positions, grid_shape, spacing, geometry, snap_idx,
                results, rows, ms) -> None:
    """Home vectors of every pair of conditions (snapshots under ``i``, current views under ``j``) on the grid:
    AAE, MAE and RR into ``results[k][i, j]``, one row per pair into ``rows``, ms per home vector into ``ms``."""
    from bionav.db.database import ImageDatabase
    from bionav.evaluation.agent import evaluate_agents
    from bionav.evaluation.measures import angular_errors, ideal_home_angles, quality_measures
    from bionav.evaluation.pairs import home_vector_matrix, prepare_images

    step, radius = exp.step_length, exp.success_radius
    workers = int(cfg.get("workers") or 1)
    dbs, prepared = [], []
    for imgs in images:
        db = ImageDatabase(name=rep, images=imgs, positions=positions, grid_shape=grid_shape, geometry=geometry,
                           spacing_m=spacing)
        dbs.append(db)
        prepared.append(prepare_images(method, list(imgs), workers=workers))
    n = len(names)
    for i in range(n):
        for j in range(n):
            hv = home_vector_matrix(method, dbs[i], dbs[j], snapshot_index=snap_idx,
                                    workers=workers, prepared=(prepared[i], prepared[j]))
            ae = angular_errors(hv.angles, ideal_home_angles(positions[snap_idx], positions))
            success, _ = evaluate_agents(dbs[j], hv, step_length=step, success_radius=radius)
            q = quality_measures(ae, success)
            results["aae"][i, j], results["mae"][i, j], results["rr"][i, j] = q.aae, q.mae, q.rr
            ms.append(hv.ms_per_home_vector)
            rows.append({"representation": rep, "snapshot_condition": names[i], "current_condition": names[j],
                         "aae": q.aae, "mae": q.mae, "rr": q.rr})
            ctx.log.write(CELL_TOPIC, rows[-1], schema_name="bionav.SkylineHomingCell")


def _square_cells(method, rep, images, names, square_cells, side, geometry, square, square_rows) -> None:
    """The square test: AAE (radians) of every pair of conditions among four positions ``side`` metres apart."""
    from bionav.db.database import ImageDatabase
    from bionav.evaluation.measures import angular_errors, ideal_home_angles
    from bionav.evaluation.pairs import home_vector_matrix

    sq_dbs = [ImageDatabase(name=rep, images=imgs, positions=square_cells, grid_shape=(2, 2), geometry=geometry,
                            spacing_m=side) for imgs in images]
    n = len(names)
    for i in range(n):
        for j in range(n):
            hv = home_vector_matrix(method, sq_dbs[i], sq_dbs[j])
            ae = angular_errors(hv.angles, ideal_home_angles(square_cells, square_cells))
            square[i, j] = float(np.nanmean(ae))
            square_rows.append({"representation": rep, "snapshot_condition": names[i],
                                "current_condition": names[j], "aae": square[i, j]})


def _summary_metrics(cfg, reps, n, n_positions, n_snapshots, results, ms, square) -> dict:
    """Means over changed (off-diagonal) and same (diagonal) condition pairs, the best representation,
    and the square test's AAE when ``square`` is given."""
    off = ~np.eye(n, dtype=bool)
    diag = np.eye(n, dtype=bool)

    def mean(m, mask):
        return float(np.mean(m[mask])) if mask.any() else float("nan")

    metrics = {
        "homing": str(cfg.homing.name) if cfg.get("homing") else "",
        "n_conditions": n,
        "n_positions": int(n_positions),
        "n_snapshots": int(n_snapshots),
        "rr": {r: mean(results[r]["rr"], off) for r in reps},
        "aae": {r: mean(results[r]["aae"], off) for r in reps},
        "rr_same": {r: mean(results[r]["rr"], diag) for r in reps},
        "aae_same": {r: mean(results[r]["aae"], diag) for r in reps},
        "ms_per_home_vector": float(np.mean(ms)) if ms else float("nan"),
    }
    ranked = [r for r in reps if np.isfinite(metrics["rr" if n > 1 else "rr_same"][r])]
    key = "rr" if n > 1 else "rr_same"
    if ranked:
        metrics["best_representation"] = max(ranked, key=lambda r: (metrics[key][r], -metrics["aae" if n > 1 else "aae_same"][r]))
    if square is not None:
        metrics["square_aae"] = {r: mean(square[r], diag) for r in reps}
        if n > 1:
            metrics["square_aae_changed"] = {r: mean(square[r], off) for r in reps}
    return metrics


def _write_csv(path, rows, fields):
    """One row per dict of ``rows`` (floats with 6 decimals) under the header ``fields``."""
    write_csv_atomic(path, fields, ([(f"{v:.6f}" if isinstance(v, float) else v) for v in
                                     (r.get(c, "") for c in fields)] for r in rows))


