"""The parameter-homing sweep: vectorised all-pairs evaluation, sweep grid, ranking tables."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest
from omegaconf import OmegaConf
from parameter_scene import render, ring_of_landmarks

from bionav.db.database import ImageDatabase
from bionav.evaluation.pairs import home_vector_matrix, neighbour_table
from bionav.experiments.param_sweep import levels as param_sweep
from bionav.geometry import PanoramaGeometry
from bionav.plugins.homing.parameter import Config, ParameterHoming
from bionav.plugins.signatures import SIGNATURE_NAMES, builtin_signature_class
from bionav.report import ranking

GEOM = PanoramaGeometry.square_pixels(72, 18)
ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def small_db():
    """A 4 x 5 grid at 0.25 m spacing rendered from an analytic scene, one cell missing."""
    landmarks = ring_of_landmarks(12, distance=3.0, rng=np.random.default_rng(8))
    cells = [(x, y) for x in range(4) for y in range(5) if (x, y) != (2, 3)]
    images = np.stack([render((0.25 * (x - 1.5), 0.25 * (y - 2)), landmarks, GEOM) for x, y in cells])
    return ImageDatabase(
        name="scene", images=images.astype(np.float32), positions=np.array(cells), grid_shape=(4, 5),
        geometry=GEOM, spacing_m=0.25,
    )


@pytest.mark.parametrize(
    "name, gradient",
    [("mffc_phase", "matched_filter"), ("mffc_abs", "matched_filter"), ("hist", "matched_filter"),
     ("mean", "test_steps"), ("fc_abs", "test_steps"), ("image", "test_steps")],
)  # fmt: skip
def test_vectorised_matrix_equals_per_pair_runner(small_db, name, gradient):
    homing = ParameterHoming(Config(signature=name, gradient=gradient, rings=3, bins=8), geometry=GEOM) if name in (
        "hist", "mean") else ParameterHoming(Config(signature=name, gradient=gradient), geometry=GEOM)
    prepared = [homing.prepare(img) for img in small_db.images]
    fast = home_vector_matrix(homing, small_db, prepared=(prepared, prepared))  # the batch path
    slow = home_vector_matrix(homing, small_db, prepared=(prepared, prepared), batch=False)
    assert fast.n_pairs == slow.n_pairs == len(small_db) * (len(small_db) - 1)
    np.testing.assert_array_equal(np.isnan(fast.angles), np.isnan(slow.angles))
    ok = np.isfinite(slow.angles)
    np.testing.assert_allclose(fast.angles[ok], slow.angles[ok], atol=1e-9)


def test_neighbour_table_with_missing_cell(small_db):
    nb = neighbour_table(small_db)
    i = small_db.index_of(2, 2)
    # (+1,0) -> (3,2); (-1,0) -> (1,2); (0,+1) -> (2,3) is missing; (0,-1) -> (2,1)
    assert list(nb[i]) == [small_db.index_of(3, 2), small_db.index_of(1, 2), -1, small_db.index_of(2, 1)]
    corner = small_db.index_of(0, 0)
    assert list(nb[corner]) == [small_db.index_of(1, 0), -1, small_db.index_of(0, 1), -1]


def test_evaluate_configuration_homes_on_rendered_grid(small_db):
    homing = ParameterHoming(Config(), geometry=GEOM)  # [mffc_phase], matched filter
    q, hv = param_sweep.evaluate_configuration(homing, small_db)
    assert q.rr > 0.9 and q.aae < 0.5, (q.rr, q.aae)
    assert q.rr_s.shape == (len(small_db),)
    assert hv.prepare_s > 0 and hv.n_pairs == 19 * 18


def test_sweep_levels_and_thesis_grid_size():
    cfg = OmegaConf.load(ROOT / "bionav" / "conf" / "experiment" / "param_sweep.yaml")
    exp = cfg.experiment
    assert param_sweep.sweep_levels(builtin_signature_class("image"), rings=[1], n_coeffs=[1]) == [{}]
    assert param_sweep.sweep_levels(builtin_signature_class("hist"), rings=[1, 5], n_coeffs=[3]) == [
        {"rings": 1}, {"rings": 5}]
    full = exp.grids.full
    sigs = full.signature.split(",")
    assert sorted(sigs) == sorted(SIGNATURE_NAMES)
    assert list(full.rings) == [1, 5, 10, 15, 20, 25]
    assert list(full.n_coeffs) == list(range(1, 21)) + [25, 30, 35, 40]
    n_sizes = len(full.image_size.split("],["))
    n_pre = len(full.preprocess.split(","))
    per_setting = sum(
        len(param_sweep.sweep_levels(builtin_signature_class(s), rings=full.rings, n_coeffs=full.n_coeffs)) for s in sigs
    )
    # 8 ring signatures x 6 + 10 DFT signatures x 24 + [image] = 289 per size and preprocessing
    assert per_setting == 289 and n_sizes == 3 and n_pre == 6
    assert 3 * per_setting * n_sizes * n_pre == 15606  # three databases: "more than 15000 tests"
    # the sweeper's parameters resolve for both grids
    for grid in ("full", "ci"):
        cfg.experiment.grid = grid
        params = OmegaConf.to_container(cfg.hydra.sweeper.params, resolve=True)
        assert set(params) == {"signature", "++db.image_size", "preprocess"}
        assert list(cfg.experiment.rings) == list(exp.grids[grid].rings)


def _row(db, sig, rr, aae, **kw):
    return {"db": db, "signature": sig, "rr": rr, "aae": aae, "rings": kw.get("rings"), "n_coeffs": kw.get("k"),
            "image_size": kw.get("size", "150x25"), "preprocess": kw.get("pre", "none"),
            "rotation_invariant": kw.get("inv", False)}  # fmt: skip


def test_ranking_table_best_configuration_per_signature():
    rows = [
        _row("a", "fc", 0.80, 0.50, k=3),
        _row("a", "fc", 0.90, 0.60, k=4, pre="he"),
        _row("a", "fc", 0.90, 0.40, k=7, size="300x50"),  # same RR*, lower AAE* wins
        _row("a", "mean", 0.95, 0.90, rings=20, inv=True),
        _row("a", "image", 0.30, 1.20),
        _row("a", "kurt", float("nan"), float("nan"), rings=5, inv=True),
        _row("b", "fc", 0.10, 1.00, k=1),
    ]
    table = ranking.ranking_table(rows, db="a")
    assert [r["parameter"] for r in table] == ["[mean]", "[fc]", "[image]", "[kurt]"]
    assert [r["rank"] for r in table] == [1, 2, 3, 4]
    fc = table[1]
    assert (fc["rr"], fc["aae"], fc["n_coeffs"], fc["rings"], fc["image_size"], fc["rot_invariant"]) == (
        0.90, 0.40, 7, "-", "300x50", "n")
    assert table[0]["rings"] == 20 and table[0]["n_coeffs"] == "-" and table[0]["rot_invariant"] == "y"
    assert table[2]["rings"] == "-" and table[2]["n_coeffs"] == "-"
    with pytest.raises(ValueError, match="several databases"):
        ranking.ranking_table(rows)
    assert ranking.ranking_table(rows, db="b")[0]["rr"] == 0.10


def test_run_writes_rows_and_report_builds_ranking(small_db, tmp_path, monkeypatch):
    import bionav.experiments.common as common
    from bionav.experiments.context import RunContext
    from bionav.experiments.param_sweep.run import run as sweep_job
    from bionav.experiments.settings import experiment_config
    from bionav.logs.writer import McapLog

    monkeypatch.setattr(common, "load_configured_database", lambda cfg, node=None: small_db)
    for sig, levels in (("mffc_phase", {"n_coeffs": [2, 5, 9]}), ("mean", {"rings": [1, 3, 6]})):
        cfg = OmegaConf.create(
            {
                "homing": {"name": "parameter", "signature": sig, "gradient": "auto"},
                "signature": {"name": sig},
                "preprocess": {"name": "none", "steps": []},
                "experiment": {"name": "param_sweep", "rings": levels.get("rings", [1]),
                               "n_coeffs": levels.get("n_coeffs", [1]), "step_length": 0.5, "success_radius": 1.0},
            }
        )  # fmt: skip
        run_dir = tmp_path / "sweep" / sig
        run_dir.mkdir(parents=True)
        log = McapLog(run_dir / "run.mcap")
        ctx = RunContext(dir=run_dir, log=log, rng=np.random.default_rng(0), cfg=cfg, show_progress=False)
        metrics = sweep_job(experiment_config(cfg), ctx)
        log.close()
        (run_dir / "metrics.json").write_text(json.dumps({"experiment": "param_sweep", "status": "completed", **metrics}))
        lines = (run_dir / "param_sweep.jsonl").read_text().splitlines()
        assert len(lines) == 3
        rows = [json.loads(line) for line in lines]
        assert metrics["rr"] == max(r["rr"] for r in rows)
        assert metrics["n_configs"] == 3 and (run_dir / "plots" / "levels.png").is_file()
        assert rows[0]["gradient"] == ("matched_filter" if sig == "mffc_phase" else "test_steps")
    assert metrics["best_rings"] in (1, 3, 6)

    from bionav.report.sections import extra_sections

    sections = extra_sections(tmp_path / "sweep", [{"experiment": "param_sweep"}])
    assert len(sections) == 1 and "[mffc_phase]" in sections[0] and "[mean]" in sections[0]
    assert (tmp_path / "sweep" / "ranking_scene.csv").is_file()
    assert (tmp_path / "sweep" / "plots" / "ranking_scene.png").is_file()
    table = ranking.ranking_table(ranking.load_sweep_rows(tmp_path / "sweep"))
    assert table[0]["parameter"] == "[mffc_phase]" and table[0]["rr"] > 0.9


def test_rotated_current_views_give_grid_frame_angles(small_db):
    """Rotation-invariant signatures on a database of rotated views: the same grid-frame
    home vectors as on the aligned database, for both gradient estimators; and per-pair calls
    with neighbour offsets in the current view's frame agree."""
    rng = np.random.default_rng(4)
    rolls = rng.integers(0, GEOM.width, len(small_db))
    headings = -2 * np.pi * rolls / GEOM.width
    rotated = ImageDatabase(
        name="rotated", images=np.stack([np.roll(im, m, axis=1) for im, m in zip(small_db.images, rolls)]),
        positions=small_db.positions, grid_shape=small_db.grid_shape, geometry=GEOM, headings=headings,
    )  # fmt: skip
    for name, gradient in (("mffc_abs", "matched_filter"), ("fc_abs", "test_steps"), ("hist", "test_steps")):
        homing = ParameterHoming(Config(signature=name, gradient=gradient, rings=3, bins=8), geometry=GEOM)
        p0 = [homing.prepare(i) for i in small_db.images]
        aligned = home_vector_matrix(homing, small_db, prepared=(p0, p0))
        prep = [homing.prepare(i) for i in rotated.images]
        turned = home_vector_matrix(homing, rotated, prepared=(prep, prep))
        ok = np.isfinite(aligned.angles)
        np.testing.assert_array_equal(ok, np.isfinite(turned.angles))
        diff = np.abs(np.angle(np.exp(1j * (aligned.angles[ok] - turned.angles[ok]))))
        assert diff.max() < 1e-6, (name, diff.max())
        if gradient == "test_steps":
            nb = neighbour_table(rotated)
            s, c = 0, rotated.index_of(2, 2)
            offsets = {}
            for (dx, dy), j in zip(((1, 0), (-1, 0), (0, 1), (0, -1)), nb[c]):
                if j >= 0:  # grid offset expressed in the current view's own frame
                    h = headings[c]
                    own = (dx * np.cos(h) + dy * np.sin(h), -dx * np.sin(h) + dy * np.cos(h))
                    offsets[own] = prep[j]
            hv = homing.home_vector(prep[s], prep[c], neighbours=offsets)
            assert abs(np.angle(np.exp(1j * (hv.angle + headings[c] - turned.angles[s, c])))) < 1e-9


def test_thesis_tables_attached_to_thesis_databases():
    for db, table in ranking.THESIS_RANKINGS.items():
        assert sorted(table) == sorted(SIGNATURE_NAMES), db
        by_rank = sorted(table.values())
        assert [r for r, _, _ in by_rank] == list(range(1, 20))
        assert all(a[1] >= b[1] for a, b in zip(by_rank, by_rank[1:])), db  # ranked by RR*
    rows = [_row("sim_original", "fc", 0.5, 0.9, k=4), _row("sim_original", "mean", 0.6, 0.8, rings=5)]
    table = ranking.ranking_table(rows)
    assert (table[1]["thesis_rank"], table[1]["thesis_rr"], table[1]["thesis_aae"]) == (2, 0.9460, 0.4437)
    assert table[0]["thesis_rank"] == 10
    assert "thesis_rr" in ranking.ranking_markdown(table, db="sim_original")
    assert "thesis_rank" not in ranking.ranking_table([_row("scene", "fc", 0.5, 0.9, k=4)])[0]


@pytest.fixture(scope="module")
def rotated_db(small_db):
    """``small_db`` with every current view rolled by a random number of columns (headings set)."""
    rolls = np.random.default_rng(11).integers(0, GEOM.width, len(small_db))
    return ImageDatabase(
        name="rotated", images=np.stack([np.roll(im, m, axis=1) for im, m in zip(small_db.images, rolls)]),
        positions=small_db.positions, grid_shape=small_db.grid_shape, geometry=GEOM,
        headings=-2 * np.pi * rolls / GEOM.width,
    )  # fmt: skip


@pytest.mark.parametrize("name", SIGNATURE_NAMES)
def test_shared_batch_path_equals_per_configuration_path(small_db, rotated_db, name):
    """evaluate_levels (per-image work shared across R / K, partial sums over the coefficients, one
    compiled agent batch) gives the RR*, AAE*, MAE* and per-snapshot values of evaluate_configuration
    (one configuration at a time, agents trial by trial) for every signature."""
    cls = builtin_signature_class(name)
    levels = param_sweep.sweep_levels(cls, rings=[1, 3, 6], n_coeffs=[1, 2, 5, 11])
    cfg = cls.Config(bins=8) if "bins" in {f.name for f in dataclasses.fields(cls.Config)} else cls.Config()
    for db in (small_db, rotated_db):
        homings, fast, _ = param_sweep.evaluate_levels(ParameterHoming, Config(signature=name), cls, cfg, levels, db)
        assert len(fast) == len(levels)
        for level, homing, q in zip(levels, homings, fast):
            assert all(getattr(homing.signature.config, k) == v for k, v in level.items())
            ref, _ = param_sweep.evaluate_configuration(homing, db)
            assert q.rr == ref.rr, (name, level)
            np.testing.assert_allclose([q.aae, q.mae], [ref.aae, ref.mae], rtol=0, atol=1e-12)
            np.testing.assert_array_equal(q.rr_s, ref.rr_s)
            np.testing.assert_allclose(q.aae_s, ref.aae_s, rtol=0, atol=1e-12)


def test_dft_signatures_nest_over_the_number_of_coefficients():
    """The signature with K coefficients is the one with more coefficients restricted to k < K (same
    order), and the partial-sum potentials equal the potentials of the restricted signatures."""
    from bionav.homing.parameter import potential_matrices_by_coefficients, potential_matrix

    images = np.random.default_rng(2).random((6, 10, 32))
    for name in SIGNATURE_NAMES:
        cls = builtin_signature_class(name)
        if not hasattr(cls, "coefficient_index"):
            continue
        big = cls(cls.Config(n_coeffs=12))
        kidx = big.coefficient_index(images[0].shape)
        f = np.stack([big.compute(im) for im in images])
        assert kidx.shape == (f.shape[1],)
        pots = potential_matrices_by_coefficients(f, f, kidx, [1, 4, 12])
        for k, pot in zip((1, 4, 12), pots):
            fk = np.stack([cls(cls.Config(n_coeffs=k)).compute(im) for im in images])
            np.testing.assert_array_equal(fk, f[:, kidx < k])
            np.testing.assert_allclose(pot, potential_matrix(fk, fk), rtol=1e-12, atol=1e-12)


@pytest.mark.slow
def test_grid_run_equals_the_multirun_jobs(tmp_path):
    """``experiment=param_sweep_grid`` (the whole grid in one run on 2 worker processes) writes the
    same configuration records as the multirun of ``experiment=param_sweep`` (one job per
    signature x image size x preprocessing), and the ranking tables."""
    from helpers import run_bionav, write_tiny_folder

    folder = write_tiny_folder(tmp_path / "tiny", shape=(16, 64), sigma=2.0)
    grid = ["experiment.grid=ci", "experiment.grids.ci.signature='mean,fc,mffc_abs'",
            "experiment.grids.ci.image_size='[32,8],[64,16]'", "experiment.grids.ci.preprocess='none,bw1'",
            "experiment.rings=[1,2]", "experiment.n_coeffs=[1,3,6]", "db=folder", f"db.path={folder}"]
    one = run_bionav("experiment=param_sweep_grid", *grid, "workers=2", f"hydra.run.dir={tmp_path / 'grid'}",
                     cwd=tmp_path)
    assert one.returncode == 0, one.stderr[-2000:]
    jobs = run_bionav("-m", "experiment=param_sweep", *grid, f"hydra.sweep.dir={tmp_path / 'jobs'}", cwd=tmp_path)
    assert jobs.returncode == 0, jobs.stderr[-2000:]
    key = ("signature", "image_size", "preprocess", "rings", "n_coeffs")
    grid_rows = {tuple(r[k] for k in key): r for r in ranking.load_sweep_rows(tmp_path / "grid")}
    job_rows = {tuple(r[k] for k in key): r for r in ranking.load_sweep_rows(tmp_path / "jobs")}
    assert len(job_rows) == 2 * 2 * (2 + 3 + 3) and set(grid_rows) == set(job_rows)
    for k, row in job_rows.items():
        assert grid_rows[k]["rr"] == row["rr"] and grid_rows[k]["rr_s"] == row["rr_s"], k
        np.testing.assert_allclose([grid_rows[k]["aae"], grid_rows[k]["mae"]], [row["aae"], row["mae"]], atol=1e-12)
    metrics = json.loads((tmp_path / "grid" / "metrics.json").read_text())
    assert metrics["n_configs"] == len(job_rows) and metrics["workers"] == 2
    assert list((tmp_path / "grid").glob("ranking_*.md"))
