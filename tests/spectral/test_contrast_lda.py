"""experiment=contrast_lda end to end on small data."""

import csv
import json

import numpy as np
import pytest
from omegaconf import OmegaConf
from spectral_ctx import FakeContext, run_with

from bionav.errors import UserError
from bionav.light.bands import feature_subsets


@pytest.mark.slow
def test_contrast_lda_small_simulated_run(tmp_path):
    cfg = OmegaConf.create({"experiment": {"name": "contrast_lda", "sigma": 30.0, "n_resamples": 200},
                            "data": {"name": "sim_natural", "seed": 3, "n_objects": 60, "n_sky": 50}})
    ctx = FakeContext(tmp_path)
    m = run_with(cfg, ctx)
    names = list(feature_subsets())
    assert set(m["J"]) == set(names) == set(m["J_sigma"]) == set(m["n_f"])
    for n in names:
        assert 0 < m["J_sigma"][n] <= m["J"][n]
        assert 0 <= m["n_f"][n] < 0.5
    json.dumps(m)  # JSON-serialisable
    assert m["n_sky"] == 50 and m["n_objects"] == 60
    rows = list(csv.DictReader(open(tmp_path / "lda_table.csv")))
    assert [r["feature"] for r in rows] == names
    assert float(rows[0]["J"]) == pytest.approx(m["J"]["UV"], rel=1e-5)
    for f in ("lda_table.md", "significance.md", "significance_J.csv", "significance_n_f.csv", "samples.csv",
              "plots/pairs.png", "plots/uv_g_uv_ir.png", "plots/projection_histograms.png"):
        assert (tmp_path / f).stat().st_size > 0, f
    md = (tmp_path / "lda_table.md").read_text()
    assert "| J |" in md and "UV-IR" in md or "**UV**" in md
    samples = [m for m in ctx.log.messages if m[0] == "/spectral5/samples"]
    features = [m for m in ctx.log.messages if m[0] == "/contrast_lda/features"]
    assert len(samples) == 110 and ctx.log.messages[0][0] == "/spectral5/samples"
    assert [m[1]["feature"] for m in features] == names and len(ctx.log.messages) == 110 + len(names)


def test_contrast_lda_csv_round_trip_and_errors(tmp_path):
    rng = np.random.default_rng(0)
    lines = ["class,UV,B,G,R,IR,kind"]
    for i in range(30):
        lines.append("sky," + ",".join(f"{v:.1f}" for v in rng.normal([3000, 2900, 2850, 2700, 2600], 80)) + ",blue")
    for i in range(30):
        lines.append("object," + ",".join(f"{v:.1f}" for v in rng.normal([1800, 2000, 2100, 2000, 2600], 80)) + ",tree")
    p = tmp_path / "mine.csv"
    p.write_text("\n".join(lines) + "\n")
    cfg = OmegaConf.create({"experiment": {"name": "contrast_lda", "n_resamples": 0, "plots": False},
                            "data": {"name": "csv", "path": str(p)}})
    m = run_with(cfg, FakeContext(tmp_path))
    assert m["n_f"]["UV"] == 0.0 and m["J"]["UV"] > 50
    bad = OmegaConf.create({"experiment": {"name": "contrast_lda"}, "data": {"name": "csv", "path": "???"}})
    with pytest.raises(UserError, match="data.path"):
        run_with(bad, FakeContext(tmp_path))
    bad = OmegaConf.create({"experiment": {"name": "contrast_lda"}, "data": {"name": "nope"}})
    with pytest.raises(UserError, match="sim_natural"):
        run_with(bad, FakeContext(tmp_path))


@pytest.mark.slow
def test_documented_command_runs_with_the_committed_data_configs(tmp_path):
    """`python -m bionav experiment=contrast_lda data=...` (conf/data/*.yaml, once hidden by .gitignore) runs;
    the per-feature criteria are logged before the bootstrap and equal metrics.json's."""
    import json

    from helpers import run_bionav

    from bionav.logs.reader import read_messages

    for data in ("sim_natural", "sim_artificial"):
        run_dir = tmp_path / data
        proc = run_bionav("experiment=contrast_lda", f"data={data}", "data.n_objects=30", "data.n_sky=30",
                          "experiment.n_resamples=20", "experiment.plots=false", f"hydra.run.dir={run_dir}",
                          cwd=tmp_path)
        assert proc.returncode == 0, proc.stderr
        metrics = json.loads((run_dir / "metrics.json").read_text())
        assert metrics["status"] == "completed" and metrics["n_objects"] == 30 and metrics["n_sky"] == 30
        logged = {m["feature"]: m for topic, _, m in read_messages(run_dir / "run.mcap", ["/contrast_lda/features"])}
        assert set(logged) == set(metrics["J"]) and len(logged) == 16
        assert all(abs(logged[f]["J"] - metrics["J"][f]) < 1e-12 for f in logged)
