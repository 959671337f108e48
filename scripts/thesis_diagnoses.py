"""Evidence for the diagnoses of the thesis items that do not hold (issue 44; docs/thesis.md, "Why").

The report's verdicts come from ``python -m bionav.thesis``; the experiments
behind most diagnoses are ``python -m bionav`` runs listed in docs/thesis.md.
This script computes the few pieces of evidence no bionav command prints::

    python scripts/thesis_diagnoses.py table6_3              # bootstrap of table 6.3 (seconds)
    python scripts/thesis_diagnoses.py table6_3 --resamples 1000
    python scripts/thesis_diagnoses.py fig5_6                # how much each lab variant changes the views
    python scripts/thesis_diagnoses.py fig6_26               # square test with the thesis' capture (minutes)
    python scripts/thesis_diagnoses.py checks fig6_10 RUN    # an item's checks on any run directory
    python scripts/thesis_diagnoses.py leaf_plateau 0.55 RUN # the quick scan with another leaf NIR plateau
    python scripts/thesis_diagnoses.py lab_ambient 3 DIR sift # fig. 5.6's lab with 3 times the bounce light

Each prints Markdown tables to stdout. Nothing here is imported by bionav.
"""

from __future__ import annotations

import argparse

import numpy as np

#: thesis 6.2.4: the groups of natural-object contrasts that "do not differ significantly" in J
GROUPS_6_2_4 = (("UV-IR", "B-IR"), ("UV-G", "B-R", "G-IR"), ("UV-B", "B-G", "G-R", "R-IR"),
                ("UV", "B", "G", "R", "IR"))


def percentile_mark(diff: np.ndarray) -> str:
    """``***``/``**``/``*``: the smallest level (0.1, 1, 5 %) whose two-sided percentile interval of ``diff``
    excludes 0; ``o`` when none does (bionav.stats.pairwise_significance's rule, for one pair)."""
    mark = "o"
    for alpha, stars in ((0.05, "*"), (0.01, "**"), (0.001, "***")):
        lo, hi = np.quantile(diff, [alpha / 2, 1 - alpha / 2])
        if lo > 0 or hi < 0:
            mark = stars
    return mark


def _thesis_j() -> dict[str, float]:
    from bionav.thesis.reference import load_reference

    return {k: float(v) for k, v in load_reference()["table6_2"]["J"].items()}


def table6_3(*, resamples: int, seed: int) -> str:
    """Which pairs of table 6.3's claims bionav finds different, and what its test says of the thesis' differences.

    Bootstraps of J on ``sim_natural`` (239 objects, 233 sky readings: the
    thesis' sample sizes; ``resamples`` data sets, the thesis 10,000): bionav's
    paired test (every feature on the same resamples, the percentile interval
    of the difference; thesis 3.3.2, eqs. 3.9/3.10), an unpaired one (the two
    features on independent resamples) and the overlap of the features' own
    95 % intervals. ``z`` is the thesis' difference in units of bionav's paired
    spread: what bionav's test would say of the thesis' numbers under the
    stand-in's sampling noise (|z| > 1.96: significant at 5 %, > 3.29 at 0.1 %).
    """
    from bionav.spectral import lda_analysis as la
    from bionav.spectral.samples import sim_natural
    from bionav.stats.lda_bootstrap import bootstrap_lda

    samples = sim_natural(seed=seed)
    results = la.analyse_features(samples, sigma=30.0)
    names = list(results)
    subsets = [results[n].channels for n in names]
    boot = [bootstrap_lda(samples.counts, samples.is_sky, subsets, sigma=30.0, n_resamples=resamples,
                          rng=np.random.default_rng([seed, k])).J for k in range(2)]
    ix = {n: i for i, n in enumerate(names)}
    thesis = _thesis_j()
    lines = [f"sim_natural (seed {seed}): {samples.n_objects} objects, {samples.n_sky} sky readings; "
             f"{resamples} bootstrap resamples", "",
             "| pair | thesis J | thesis diff | bionav J | bionav diff | paired spread | z of the thesis' diff | "
             "bionav paired | unpaired | 95 % intervals overlap |", "|---|---|---|---|---|---|---|---|---|---|"]
    for group in GROUPS_6_2_4:
        for i, a in enumerate(group):
            for b in group[i + 1:]:
                paired = boot[0][:, ix[a]] - boot[0][:, ix[b]]
                unpaired = boot[0][:, ix[a]] - boot[1][:, ix[b]]
                (la_, ha), (lb, hb) = (np.quantile(boot[0][:, ix[f]], [0.025, 0.975]) for f in (a, b))
                sd = float(paired.std(ddof=1))
                td = thesis[a] - thesis[b]
                lines.append(f"| {a} / {b} | {thesis[a]:.2f} / {thesis[b]:.2f} | {td:+.2f} | {results[a].J:.2f} / "
                             f"{results[b].J:.2f} | {results[a].J - results[b].J:+.2f} | {sd:.2f} | {td / sd:+.1f} | "
                             f"{percentile_mark(paired)} | {percentile_mark(unpaired)} | "
                             f"{'yes' if la_ <= hb and lb <= ha else 'no'} |")
    return "\n".join(lines) + "\n\n" + thesis_singles(resamples=resamples, seed=seed)


def thesis_singles(*, resamples: int, seed: int) -> str:
    """Whether any bootstrap could leave the thesis' single channels unmarked: J 4.36 (UV) ... 0.11 (IR).

    One Gaussian two-class data set per channel at the thesis' sample sizes,
    standardised so that its J is exactly the thesis' (class means ``d`` apart,
    unit variance each: J = d^2 / 2); each channel bootstrapped on its own
    resamples (unpaired, the most conservative of the tests above). Intervals
    that do not overlap at 99.9 % differ at 0.1 % under any of them.
    """
    from bionav.stats.lda_bootstrap import bootstrap_lda

    rng = np.random.default_rng(seed)
    thesis = _thesis_j()
    rows = ["| channel | thesis J | 99.9 % percentile interval of J (unpaired bootstrap) |", "|---|---|---|"]
    intervals = {}
    for c in ("UV", "B", "G", "R", "IR"):
        x1, x0 = rng.standard_normal(233), rng.standard_normal(239)
        x1, x0 = (x1 - x1.mean()) / x1.std(), (x0 - x0.mean()) / x0.std()
        x1 += np.sqrt(2 * thesis[c])
        x = np.r_[x1, x0][:, None]
        lab = np.r_[np.ones(233, bool), np.zeros(239, bool)]
        j = bootstrap_lda(x, lab, [(0,)], sigma=1e-9, n_resamples=resamples, rng=rng).J[:, 0]
        intervals[c] = np.quantile(j, [0.0005, 0.9995])
        rows.append(f"| {c} | {thesis[c]:.2f} | {intervals[c][0]:.2f} ... {intervals[c][1]:.2f} |")
    apart = [f"{a}/{b}" for i, a in enumerate(intervals) for b in list(intervals)[i + 1:]
             if intervals[a][0] > intervals[b][1] or intervals[b][0] > intervals[a][1]]
    rows += ["", f"Pairs of single channels whose 99.9 % intervals do not overlap: {', '.join(apart) or 'none'} "
                 f"({len(apart)} of 10)."]
    return "\n".join(rows)


DUALS = ("UV-B", "UV-G", "UV-R", "UV-IR", "B-G", "B-R", "B-IR", "G-R", "G-IR", "R-IR")


def _square_setup(seed: int):
    """What every square test shares: geometry, sensor, J_sigma lines, the SIFT method, the corners (m)."""
    from bionav.geometry import PanoramaGeometry
    from bionav.plugins.homing.sift import SiftConfig, SiftHoming
    from bionav.spectral.lda_analysis import learn_discriminants
    from bionav.spectral.samples import sim_natural
    from bionav.spectral.sensor_model import LogSensorModel

    width, height, top = 120, 20, np.deg2rad(45.0)  # experiment=skyline_homing's panoramas
    geometry = PanoramaGeometry(width, height, top / (2 * np.pi / width), 2 * np.pi / width)
    disc = learn_discriminants(sim_natural(seed=seed), sigma=30.0)
    corners = np.array([[0, 0], [1, 0], [0, 1], [1, 1]])
    positions = 2.0 + (corners - 0.5) * 2.0  # a 2 m square at the centre of the 4 m garden grid
    return geometry, LogSensorModel(noise_counts=4.0), disc, SiftHoming(SiftConfig(), geometry=geometry), corners, positions


def square_aae(setup, *, seed: int, half_sigma_deg: float, heading_sigma_deg: float, minutes_apart: float,
               draw: int) -> float:
    """AAE (rad) over the dual contrasts of SIFT homing in the square test (thesis 6.5.2), one capture draw.

    ``experiment=skyline_homing``'s square (garden world, the corners of a 2 m
    square at the centre of its 4 m grid, 120 x 20 panoramas, the overcast noon
    of 17 June 2009, noise 4 counts, the J_sigma lines of ``sim_natural``),
    captured the thesis' way: each panorama is two 180-degree halves, the second
    taken after the unit was turned by hand (its heading off by N(0,
    ``half_sigma_deg``)); the whole corner's heading off by N(0,
    ``heading_sigma_deg``) (the tripod set down by hand); corner k captured
    ``k * minutes_apart`` minutes after the first (sun and clouds move on). All
    zero: the experiment's own square test (``square_aae``).
    """
    import datetime as dt

    from bionav.db.database import ImageDatabase
    from bionav.evaluation.measures import angular_errors, ideal_home_angles
    from bionav.evaluation.pairs import home_vector_matrix
    from bionav.light.clouds import CloudLayer
    from bionav.light.daylight import SkyState
    from bionav.spectral.representations import representation_image
    from bionav.world.worlds.garden import garden_scene, render_spectral_panorama

    geometry, sensor, disc, method, corners, positions = setup
    rng = np.random.default_rng([seed, draw])
    noon = dt.datetime(2009, 6, 17, 12, 0, tzinfo=dt.timezone(dt.timedelta(hours=2)))
    half = geometry.width // 2
    counts = []
    for k, pos in enumerate(positions):
        sky = SkyState.from_time(noon + dt.timedelta(minutes=k * minutes_apart),
                                 clouds=CloudLayer(cover=0.95, optical_depth=40.0, seed=seed + 1), turbidity=0.1)
        scene = garden_scene(sky, seed=seed, grid_extent=4.0)
        heading = np.deg2rad(rng.normal(0.0, heading_sigma_deg)) if heading_sigma_deg else 0.0
        second = heading + (np.deg2rad(rng.normal(0.0, half_sigma_deg)) if half_sigma_deg else 0.0)
        first, _ = render_spectral_panorama(scene, geometry, position=(*pos, 0.0), heading=heading)
        turned = first if second == heading else render_spectral_panorama(scene, geometry, position=(*pos, 0.0),
                                                                          heading=second)[0]
        rad = np.concatenate([first[:, :half], turned[:, half:]], axis=1)
        counts.append(sensor.read(rad, rng=rng)[0, ..., :5].astype(np.float32))
    ideal = ideal_home_angles(corners, corners)
    aae = []
    for rep in DUALS:
        imgs = np.stack([representation_image(c, rep, discriminants=disc) for c in counts])
        db = ImageDatabase(name=rep, images=imgs, positions=corners, grid_shape=(2, 2), geometry=geometry,
                           spacing_m=2.0)
        aae.append(float(np.nanmean(angular_errors(home_vector_matrix(method, db, db).angles, ideal))))
    return float(np.mean(aae))


def fig6_26(*, seed: int, draws: int) -> str:
    """The square test's AAE as the capture comes closer to the thesis' (6.5.2/6.5.3), against its 1.3427 rad."""
    setup = _square_setup(seed)
    cases = [("bionav's square test (one panorama per corner, same light, exact headings)", 0, 0, 0),
             ("corners captured 40 min apart (two 180-degree halves of 20 min each)", 0, 0, 40),
             ("second half turned by hand, sigma 5 deg", 5, 0, 0),
             ("second half turned by hand, sigma 10 deg", 10, 0, 0),
             ("second half turned by hand, sigma 20 deg", 20, 0, 0),
             ("corner headings by hand, sigma 10 deg", 0, 10, 0),
             ("40 min apart, halves sigma 10 deg, headings sigma 10 deg", 10, 10, 40)]
    rows = ["| capture | AAE over the dual contrasts (rad), mean of draws | draws |", "|---|---|---|"]
    for name, half, head, minutes in cases:
        n = 1 if not (half or head) else draws
        vals = [square_aae(setup, seed=seed, half_sigma_deg=half, heading_sigma_deg=head, minutes_apart=minutes,
                           draw=d) for d in range(n)]
        spread = f" (draws {min(vals):.2f} ... {max(vals):.2f})" if n > 1 else ""
        rows.append(f"| {name} | {np.mean(vals):.2f}{spread} | {n} |")
    rows += ["", "Thesis (6.5.2): 1.3427 rad over all contrasts; random home vectors give pi/2 = 1.571 rad."]
    return "\n".join(rows)


def fig5_6(*, size: tuple[int, int] = (346, 50)) -> str:
    """How much each variant of the lab changes the panoramas against ``sim_original``, cell by cell.

    The stand-ins are rendered with the same pose errors and camera draws per
    cell, so a difference is the variant's change to the room: the fraction of
    pixels that differ by more than 10 % of full scale, and the mean absolute
    difference, averaged over the cells (databases at ``size``, from the render
    cache as the runs use them).
    """
    from bionav.config import compose
    from bionav.experiments.common import load_configured_database

    def images(name):
        cfg = compose([f"db={name}", f"db.image_size=[{size[0]},{size[1]}]"])
        db = load_configured_database(cfg)
        return {tuple(int(v) for v in p): np.asarray(db.images[i], float) for i, p in enumerate(db.positions)}

    base = images("sim_original")
    scale = max(float(np.max(im)) for im in base.values())
    rows = ["| variant (current views) | pixels changed > 10 % of full scale | mean absolute change (% of full scale) |",
            "|---|---|---|"]
    for name in ("sim_arboreal", "sim_chairs", "sim_screen", "sim_doorlit", "sim_winlit"):
        other = images(name)
        cells = [c for c in base if c in other]
        diff = [np.abs(other[c] - base[c]) / scale for c in cells]
        rows.append(f"| {name.removeprefix('sim_')} | {100 * np.mean([np.mean(d > 0.1) for d in diff]):.1f} % | "
                    f"{100 * np.mean([d.mean() for d in diff]):.2f} |")
    return "\n".join(rows)


def item_checks(item_id: str, run_dir: str, preset: str = "quick") -> str:
    """The checks of a one-run item (figs. 6.10-6.15, 6.26, tables 6.2-6.5) evaluated on any run directory.

    For runs the thesis command does not make: the same experiment under other
    settings (a stand-in closer to the thesis' scene, another seed).
    """
    import json
    import tempfile
    from pathlib import Path

    from bionav.thesis.items import REGISTRY, Context
    from bionav.thesis.presets import PRESETS
    from bionav.thesis.reference import load_reference
    from bionav.thesis.runs import RunResult

    item = REGISTRY[item_id]
    specs = item.runs(PRESETS[preset])
    if len(specs) != 1:
        raise SystemExit(f"{item_id} needs {len(specs)} runs; give an item of one run")
    run = Path(run_dir)
    res = RunResult(specs[0], run, json.loads((run / "metrics.json").read_text()))
    with tempfile.TemporaryDirectory() as tmp:
        out = item.evaluate(Context(PRESETS[preset], Path(tmp), load_reference().get(item_id, {}),
                                    {specs[0].key: res}, ref_id=item_id), specs)
    lines = [f"{item.label} on {run}: {out.verdict} ({out.score[0]} of {out.score[1]} checks pass)", "",
             "| check | result | detail |", "|---|---|---|"]
    lines += [f"| {c.rule} | {'n/a' if c.passed is None else 'pass' if c.passed else 'fail'} | {c.detail} |"
              for c in out.checks]
    lines += [f"| {r.quantity} | {r.verdict or '(shown)'} | thesis {r.thesis}, bionav {r.bionav} |"
              for r in out.rows if r.tolerance is not None]
    return "\n".join(lines)


#: the quick preset's scan (bionav.thesis.presets.QUICK.scan) as overrides
QUICK_SCAN = ("experiment=contrast_scan", "experiment.n_pan=38", "experiment.pan_step_deg=6.0", "experiment.n_tilt=9",
              "experiment.tilt_step_deg=9.0")


def leaf_plateau_scan(plateau: float, run_dir: str) -> int:
    """The quick preset's one-day scan with the leaves' near-infrared plateau at ``plateau`` (bionav: 0.48).

    The plateau beyond 700 nm is an extrapolation (docs/spectral.md); fresh leaves
    reflect 0.45-0.55 at 800 nm. Runs ``python -m bionav`` in a child process with
    ``bionav.light.measured_spectra.LEAF_NIR_PLATEAU`` set before anything reads it.
    """
    import subprocess
    import sys

    code = ("import sys, bionav.light.measured_spectra as m; m.LEAF_NIR_PLATEAU = float(sys.argv[1]); "
            "sys.argv = ['bionav'] + sys.argv[2:]; from bionav.cli_main import run_main; from bionav.cli import main; "
            "run_main(main, 'bionav')")
    return subprocess.call([sys.executable, "-c", code, str(plateau), *QUICK_SCAN, f"hydra.run.dir={run_dir}"])


def lab_ambient_cross_db(factor: float, out_dir: str, homing: str = "sift") -> int:
    """Fig. 5.6's cross-database run on original, doorlit and winlit with the lab's bounce light times ``factor``.

    The stand-in lab's inter-reflected light is a uniform ambient term kept small
    against a light band's direct light (``bionav.world.worlds.lab.AMBIENT_PER_BAND``,
    0.07 up and 0.045 down per band that is on), so that switching a band off
    reverses the shading of faces. The quick preset's settings (4 snapshots per
    database, 346 x 50), into ``out_dir``/``homing``; the stand-ins render into
    ``out_dir``/cache, never into the shared render cache (the cache key does not
    see the patched constant).
    """
    import os
    import subprocess
    import sys

    code = ("import sys, bionav.world.worlds.lab as lab; f = float(sys.argv[1]); "
            "lab.AMBIENT_PER_BAND = tuple(f * a for a in lab.AMBIENT_PER_BAND); "
            "sys.argv = ['bionav'] + sys.argv[2:]; from bionav.cli_main import run_main; from bionav.cli import main; "
            "run_main(main, 'bionav')")
    env = dict(os.environ, BIONAV_CACHE=os.path.join(out_dir, "cache"))
    return subprocess.call([sys.executable, "-c", code, str(factor), "experiment=cross_db", f"homing={homing}",
                            "experiment.family=[sim_original,sim_doorlit,sim_winlit]", "experiment.snapshot_stride=9",
                            "db.image_size=[346,50]", f"hydra.run.dir={out_dir}/{homing}"], env=env)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python scripts/thesis_diagnoses.py", description=__doc__.split("\n\n")[0])
    p.add_argument("item", help="table6_3, fig5_6, fig6_26, or 'checks ITEM RUN_DIR' (an item's checks on any run)")
    p.add_argument("args", nargs="*", help="checks: ITEM RUN_DIR; leaf_plateau: VALUE RUN_DIR; "
                                           "lab_ambient: FACTOR DIR [HOMING]")
    p.add_argument("--resamples", type=int, default=10_000, help="bootstrap resamples (thesis: 10000)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--draws", type=int, default=10, help="fig6_26: capture draws per case with random headings")
    args = p.parse_args(argv)
    if args.item == "table6_3":
        print(table6_3(resamples=args.resamples, seed=args.seed))
    elif args.item == "fig5_6":
        print(fig5_6())
    elif args.item == "fig6_26":
        print(fig6_26(seed=args.seed, draws=args.draws))
    elif args.item == "checks" and len(args.args) == 2:
        print(item_checks(*args.args))
    elif args.item == "leaf_plateau" and len(args.args) == 2:
        return leaf_plateau_scan(float(args.args[0]), args.args[1])
    elif args.item == "lab_ambient" and len(args.args) in (2, 3):
        return lab_ambient_cross_db(float(args.args[0]), *args.args[1:])
    else:
        p.error("give table6_3, fig5_6, fig6_26, checks ITEM RUN_DIR, leaf_plateau VALUE RUN_DIR or "
                "lab_ambient FACTOR DIR [HOMING]")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
