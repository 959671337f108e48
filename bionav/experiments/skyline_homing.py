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
from bionav.experiments.common import _get, load_samples
from bionav.experiments.configs import experiment_config
from bionav.files import write_csv_atomic
from bionav.light.sun import parse_time
from bionav.report.figures import pyplot, save_figure

CELL_TOPIC = "/skyline_homing/cell"


def _conditions(exp):
    out = []
    for k, c in enumerate(exp.conditions):
        name = str(_get(c, "name", f"c{k}"))
        t = parse_time(str(_get(c, "time", "")), what=f"experiment.conditions[{k}].time", naive_utc=False)
        out.append((name, t, float(_get(c, "cloud_cover", 0.0)), float(_get(c, "cloud_optical_depth", 20.0))))
    if not out:
        raise UserError("experiment.conditions is empty; give at least one {name, time, cloud_cover, "
                        "cloud_optical_depth}.")
    return out


def render_condition_counts(scene, geometry, world_positions, *, sensor_model, rng, progress=None):
    """Five-channel counts ``(N, H, W, 5)`` and true sky masks ``(N, H, W)`` at world positions."""
    from bionav.world.worlds.garden import render_spectral_panorama

    counts, skies = [], []
    it = world_positions if progress is None else progress(world_positions, desc="render", total=len(world_positions))
    for p in it:
        rad, sky = render_spectral_panorama(scene, geometry, position=tuple(p))
        counts.append(sensor_model.read(rad, rng=rng)[0, ..., :5].astype(np.float32))
        skies.append(sky)
    return np.stack(counts), np.stack(skies)


def campus_world(sky, *, seed: int):
    """The outdoor campus of :mod:`bionav.world.worlds.outdoor` in five bands under a spectral sky.

    Per-kind albedos are the campus' default five-band albedos
    (:func:`bionav.light.materials.band_albedos`: the reflectances of the
    kinds' materials), the sun and the hemispherical ambient light from
    :func:`bionav.light.daylight.illumination` (``E/pi``, so that pixel values are
    band radiances in the unit of the sensor model), rays that hit nothing from
    :func:`bionav.light.daylight.band_sky_radiance`.
    """
    try:
        from bionav.world.worlds.outdoor import build_campus
    except ImportError:
        raise UserError("experiment.world=campus needs bionav's outdoor campus world (bionav.world.worlds.outdoor), "
                        "which this installation lacks; use experiment.world=garden.") from None
    from bionav.light.bands import CHANNELS, band_integrate
    from bionav.light.daylight import band_sky_radiance, illumination
    ill = illumination(sky)
    e_dir = band_integrate(ill.direct_normal) / np.pi
    e_dif = band_integrate(ill.diffuse_horizontal) / np.pi
    world = build_campus(seed, channels=CHANNELS, sky=lambda d: band_sky_radiance(sky, d),
                         sun_elevation=float(sky.sun_elevation), sun_azimuth=float(sky.sun_azimuth),
                         sun_irradiance=e_dir, sky_irradiance=e_dif, exposure=1.0)
    return world


def render_campus_counts(world, geometry, cells, *, sensor_model, rng, progress=None):
    """Counts ``(N, H, W, 5)`` and true sky masks of the campus at grid cells ``(N, 2)`` (may be fractional)."""
    from bionav.world.render import render_depth, render_panorama

    counts, skies = [], []
    it = cells if progress is None else progress(cells, desc="render", total=len(cells))
    for i, j in it:
        pos = world.cell_position(float(i), float(j))
        rad = render_panorama(world.scene, position=pos, geometry=geometry, clip=False, exposure=1.0)
        depth, _, _ = render_depth(world.scene, position=pos, geometry=geometry)
        counts.append(sensor_model.read(np.asarray(rad, float), rng=rng)[0, ..., :5].astype(np.float32))
        skies.append(~np.isfinite(depth))
    return np.stack(counts), np.stack(skies)


def run(cfg, ctx) -> dict:
    """Entry point called by bionav's experiment runner."""
    from bionav.experiments.common import make_homing
    from bionav.spectral.lda_analysis import learn_discriminants
    from bionav.spectral.sensor_model import LogSensorModel

    exp = experiment_config(cfg, "skyline_homing")
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
        _plots(ctx.plots, counts, disc, reps, names, metrics, results, geometry, border)
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
    from bionav.world.worlds.garden import garden_scene

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
            c, truth = render_condition_counts(scene, geometry, world_pos, sensor_model=sensor_model, rng=ctx.rng,
                                               progress=ctx.progress)
            if square_pos is not None:
                squares.append(render_condition_counts(scene, geometry, square_pos, sensor_model=sensor_model,
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
    dbs, prepared = [], []
    for imgs in images:
        db = ImageDatabase(name=rep, images=imgs, positions=positions, grid_shape=grid_shape, geometry=geometry,
                           spacing_m=spacing)
        dbs.append(db)
        prepared.append(prepare_images(method, list(imgs), workers=int(_get(cfg, "workers", 1))))
    n = len(names)
    for i in range(n):
        for j in range(n):
            hv = home_vector_matrix(method, dbs[i], dbs[j], snapshot_index=snap_idx,
                                    workers=int(_get(cfg, "workers", 1)), prepared=(prepared[i], prepared[j]))
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
        "homing": str(cfg.homing.name) if _get(cfg, "homing") else "",
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


def _plots(plots, counts, disc, reps, names, metrics, results, geometry, border):
    plt = pyplot()

    from bionav.spectral.representations import representation_image

    # RR* per representation: same light vs changed light
    x = np.arange(len(reps))
    fig, ax = plt.subplots(figsize=(max(6, 0.5 * len(reps) + 2), 3.8))
    ax.bar(x - 0.2, [metrics["rr_same"][r] for r in reps], 0.4, label="same light")
    if len(names) > 1:
        ax.bar(x + 0.2, [metrics["rr"][r] for r in reps], 0.4, label="changed light")
    ax.set_xticks(x, reps, rotation=60, ha="right", fontsize=8)
    ax.set_xlabel("representation (channel, contrast or skyline)")
    ax.set_ylabel("RR* (fraction of agents home)")
    ax.set_ylim(0, 1.05)
    ax.legend()
    ax.set_title(f"return ratio per representation (homing={metrics['homing']})")
    save_figure(fig, plots / "rr_per_representation.png", dpi=100)
    # RR* matrices per representation
    cols = min(5, len(reps))
    rws = int(np.ceil(len(reps) / cols))
    fig, axes = plt.subplots(rws, cols, figsize=(2.6 * cols, 2.4 * rws), squeeze=False)
    for ax, r in zip(axes.ravel(), reps):
        ax.imshow(results[r]["rr"], vmin=0, vmax=1, cmap="viridis")
        ax.set_title(r, fontsize=8)
        ax.set_xticks(range(len(names)), names, rotation=90, fontsize=5)
        ax.set_yticks(range(len(names)), names, fontsize=5)
    for ax in axes.ravel()[len(reps):]:
        ax.axis("off")
    fig.suptitle("RR*: rows snapshot condition, columns current condition", fontsize=9)
    save_figure(fig, plots / "rr_matrices.png", dpi=90)
    # the representations of the first position under every condition
    fig, axes = plt.subplots(len(reps), len(names), figsize=(3.2 * len(names), 0.9 * len(reps) + 0.5), squeeze=False)
    for i, r in enumerate(reps):
        for j, nm in enumerate(names):
            axes[i, j].imshow(representation_image(counts[j][0], r, discriminants=disc, threshold=border), cmap="gray",
                              vmin=0, vmax=1,
                              aspect="auto", interpolation="nearest")
            axes[i, j].set_xticks([])
            axes[i, j].set_yticks([])
            if j == 0:
                axes[i, j].set_ylabel(r, fontsize=7, rotation=0, ha="right")
            if i == 0:
                axes[i, j].set_title(nm, fontsize=8)
    save_figure(fig, plots / "representations.png", dpi=80)
