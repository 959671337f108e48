"""``python -m bionav.thesis``: reference data, run bookkeeping, verdicts, and the whole path on the tiny preset."""

from __future__ import annotations

import csv
import itertools
import json
from pathlib import Path

import pytest
import yaml
from helpers import run_bionav
from hydra.core.override_parser.overrides_parser import OverridesParser

from bionav.errors import UserError
from bionav.thesis.items import REGISTRY, select_items, spearman
from bionav.thesis.outcome import Check, Outcome, Row, verdict_of
from bionav.thesis.reference import load_reference
from bionav.thesis.runs import RunSpec, canonical_key, index_runs, product_blocks


# --------------------------------------------------------------------------- reference data
def test_reference_tables_are_complete_and_consistent():
    ref = load_reference()
    for t in ("table5_3", "table5_4"):
        assert ref[t]["databases"] == ["original", "hall1", "moeller1", "roeben1", "uni"]
        assert all(len(ref[t][k]) == 5 for k in ("aae", "mae", "rr"))
    # the values the thesis' text quotes agree with its tables
    assert ref["table5_3"]["rr"][0] == 1.0 and ref["table5_4"]["rr"][1] == 0.9912
    signatures = set(ref["table5_5"]["ranking"][i][1] for i in range(19))
    for t in ("table5_5", "table5_6", "table5_7"):
        rows = ref[t]["ranking"]
        assert [r[0] for r in rows] == list(range(1, 20))
        assert {r[1] for r in rows} == signatures and len(signatures) == 19
        rr = [r[2] for r in rows]
        assert rr == sorted(rr, reverse=True)  # ranked by RR*
    # quoted in the text: [image] on original 0.9483/0.4626, [mffc_phase] on hall1 0.9988/0.2420
    assert ref["table5_5"]["ranking"][0][1:4] == ["image", 0.9483, 0.4626]
    assert ref["table5_6"]["ranking"][0][1:4] == ["mffc_phase", 0.9988, 0.242]
    for t in ("table6_2", "table6_4"):
        assert len(ref[t]["J"]) == len(ref[t]["J_sigma"]) == len(ref[t]["n_f_permille"]) == 16
    assert ref["table6_2"]["J"]["UV-IR"] == 7.30 and ref["table6_4"]["n_f_permille"]["all"] == 47
    assert (ref["fig7_3"]["coverage_pct"], ref["fig7_4"]["uncovered_pct"]) == (86.4, 15.9)
    assert len(ref["fig5_4"]["cutoffs"]) == 17
    for t in ("tableB_1", "tableB_2", "tableB_3", "tableB_4"):
        for vals in ref[t]["dbs"].values():
            assert all(len(vals[k]) == 4 for k in ("keys", "aae", "rr"))


# --------------------------------------------------------------------------- runs bookkeeping
def test_canonical_key_ignores_spelling_order_and_neutral_overrides():
    a = canonical_key(["db=sim_hall1", "db.image_size=[346,50]", "preprocess.steps=[{op:equalize,levels:256}]"])
    b = canonical_key(["++db.image_size=[346, 50]", "db=sim_hall1", "preprocess.steps=[{levels: 256, op: equalize}]",
                       "bionav.resume=true", "hydra.run.dir=/x", "workers=1"])
    assert a == b
    assert a != canonical_key(["db=sim_hall1", "db.image_size=[346,51]", "preprocess.steps=[{op:equalize,levels:256}]"])
    assert canonical_key(["db=sim_uni"]) != canonical_key(["db=sim_uni"], multirun=True)


def test_product_blocks_cover_every_run_exactly_once():
    specs = [RunSpec((f"db={d}", f"db.image_size={s}", "homing=sift")) for d in ("a", "b") for s in ("[1,2]", "[3,4]")]
    specs.append(RunSpec(("db=c", "db.image_size=[1,2]", "homing=sift")))
    specs.append(RunSpec(("db=a", "homing=mfdid")))
    blocks = product_blocks(specs)
    covered = [s for _, cov in blocks for s in cov]
    assert sorted(s.key for s in covered) == sorted(s.key for s in specs)
    parser = OverridesParser.create()
    for sweep, cov in blocks:  # each block's Cartesian product is exactly the runs it covers
        choices = []
        for ov in parser.parse_overrides(sweep):
            values = list(ov.sweep_string_iterator()) if ov.is_sweep_override() else [ov.get_value_element_as_str()]
            choices.append([f"{ov.key_or_group}={v}" for v in values])
        assert {canonical_key(combo) for combo in itertools.product(*choices)} == {s.key for s in cov}
    assert len(blocks) == 3  # {a,b} x sizes; c alone; the mfdid run


def test_index_finds_completed_runs_only(tmp_path):
    """Completed runs whose recorded configuration is what their overrides compose to (issue 45: a record that
    describes another run, or none, is not reused)."""
    from omegaconf import OmegaConf

    from bionav.config import compose, register_configs

    register_configs()
    for name, status, overrides, edit in (("r1", "completed", ["db=sim_uni", "homing=sift"], None),
                                          ("r2", "failed", ["db=sim_hall1"], None),
                                          ("r3", "completed", ["db=sim_hall2"], "seed: 0"),
                                          ("r4", "completed", ["db=sim_day"], "no record")):
        d = tmp_path / "runs" / name
        (d / ".hydra").mkdir(parents=True)
        (d / ".hydra" / "overrides.yaml").write_text(yaml.safe_dump(overrides))
        (d / "metrics.json").write_text(json.dumps({"status": status}))
        if edit != "no record":
            text = OmegaConf.to_yaml(compose(overrides))
            (d / ".hydra" / "config.yaml").write_text(text.replace(edit, "seed: 7") if edit else text)
    index = index_runs(tmp_path)
    assert index == {canonical_key(["homing=sift", "db=sim_uni"]): tmp_path / "runs" / "r1"}


# --------------------------------------------------------------------------- verdicts
def test_verdict_rule():
    assert verdict_of([True, True]) == "holds"
    assert verdict_of([True, False]) == "partly"
    assert verdict_of([True, False, False]) == "does not hold"
    assert verdict_of([]) == "not produced"
    out = Outcome(rows=[Row("x", 1.0, 1.05, 0.1), Row("y", 1.0, 1.5, 0.1), Row("shown only", 1.0, 9.0)],
                  checks=[Check("c", True), Check("not evaluable", None)])
    assert out.score == (2, 3) and out.verdict == "partly"
    assert Row("x", 0.2663, 0.3, 0.1).difference == pytest.approx(0.0337)
    assert spearman([1, 2, 3], [10, 30, 20]) == pytest.approx(0.5)
    assert spearman([1, 1], [1, 2]) is None


def test_an_item_without_completed_runs_is_not_produced():
    out = Outcome(rows=[Row("SIFT AAE* original", 0.27, None, 0.1)], checks=[Check("ordering", False)],
                  figures=["table5_3.png"], missing=["run x: not run"], notes=["a note"])
    assert out.verdict == "does not hold"  # what the report said before issue 32
    gone = out.without_runs(5)
    assert gone.verdict == "not produced" and gone.score == (0, 0)
    assert (gone.rows, gone.checks, gone.figures, gone.missing, gone.notes) == ([], [], [], ["run x: not run"], ["a note"])
    assert Outcome().without_runs(3).missing == ["none of the item's 3 runs completed"]
    # an ordering claim over five databases with two runs missing is not evaluated (it used to fail on 3 values)
    from bionav.thesis.items import rho_check

    partial = rho_check("RR*", [0.9, 0.8, 0.7, 0.6, 0.5], [0.5, None, 0.9, None, 0.6])
    assert partial.passed is None and "2 of 5 values missing" in partial.detail
    assert rho_check("RR*", [0.9, 0.8, 0.7], [0.5, 0.7, 0.9]).passed is False
    assert rho_check("RR*", [0.9, 0.8, 0.7], [0.95, 0.85, 0.6]).passed is True


def test_report_keeps_the_asterisks_of_aae_mae_rr(tmp_path):
    from bionav.thesis.report import Section, markdown_to_html, md_text, section_markdown

    assert md_text("AAE*, MAE* and RR*") == "AAE\\*, MAE\\* and RR\\*"
    assert md_text("`a*b*` and c*") == "`a*b*` and c\\*"  # code spans stay verbatim
    o = Outcome(rows=[Row("SIFT AAE* original", 0.2663, 0.3, 0.1), Row("SIFT RR* uni", 0.9, 0.95, 0.1)],
                checks=[Check("ordering of RR* across databases equal", True, "rho = 1.00")])
    sec = Section("table5_3", "Table 5.3", "Table 5.3: results of SIFT homing", "table 5.3, p. 60",
                  "|AAE*, MAE*| <= 0.1 rad; RR* within 0.1", o, [], ["AAE* and RR* grow with the image size"])
    md = section_markdown(sec, tmp_path)
    page = markdown_to_html(md, tmp_path)
    for text in ("SIFT AAE* original", "SIFT RR* uni", "ordering of RR* across databases", "|AAE*, MAE*| &lt;= 0.1 rad",
                 "AAE* and RR* grow"):
        assert text in page, text
    assert "<i>" not in page.replace("<i>Source:</i>", "").replace("<i>Verdict:</i>", "").replace("<i>Rule:</i>", "")
    assert "<b>holds</b>" in page  # real emphasis still renders
    from bionav.thesis.items import markdown

    table = markdown(["quantity", "thesis"], [["SIFT AAE* original", 0.2663], ["J: UV-IR vs All", "***"]])
    assert "| SIFT AAE\\* original | 0.2663 |" in table and "| J: UV-IR vs All | \\*\\*\\* |" in table


def test_select_items_by_id_and_thesis_number():
    assert [it.id for it in select_items("5.3,B.1")] == ["table5_3", "tableB_1"]
    assert {it.id for it in select_items("5.4")} == {"table5_4", "fig5_4"}
    assert [it.id for it in select_items("6.26")] == ["fig6_26"]
    assert len(select_items(None)) == len(REGISTRY)
    with pytest.raises(UserError, match="unknown item 'table9_9'"):
        select_items("table9_9")


def test_every_item_of_the_issue_is_registered():
    wanted = ["table3_1", "table5_3", "table5_4", "fig5_4", "fig5_5", "fig5_6", "table5_5", "table5_6", "table5_7",
              "tableB_1", "tableB_2", "tableB_3", "tableB_4", "fig4_2", "fig4_4", "fig4_5", "fig4_6", "table6_2",
              "table6_3", "table6_4", "table6_5", "fig6_3", "fig6_4", "fig6_5", "fig6_10", "fig6_11", "fig6_12",
              "fig6_13", "fig6_14", "fig6_15", "fig6_16", "fig6_26", "fig7_3", "fig7_4"]
    assert [w for w in wanted if w not in REGISTRY] == []
    ref = load_reference()
    assert [w for w in wanted if w not in ref] == []


# --------------------------------------------------------------------------- the command, end to end
def _rows(path: Path) -> list[dict]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


@pytest.mark.slow
def test_cli_tiny_preset_end_to_end(tmp_path):
    out = tmp_path / "report"
    args = ("--preset", "tiny", "--only", "table3_1,fig5_5,table6_2,fig4_4", "--out", str(out))
    proc = run_bionav(*args, cwd=tmp_path, module="bionav.thesis")
    assert proc.returncode == 0, proc.stderr + proc.stdout
    for name in ("report.md", "report.html", "items.csv", "fig5_5.png", "table6_2.md", "table6_2.png",
                 "fig4_4.png", "table3_1.md"):
        assert (out / name).is_file(), name
    rows = _rows(out / "items.csv")
    assert {"item", "quantity", "thesis", "bionav", "verdict"} <= set(rows[0])
    by = {(r["item"], r["quantity"]): r for r in rows}

    # bionav's values in the report are the runs' metrics
    runs = {}
    for m in out.glob("runs/*/*/metrics.json"):
        ov = yaml.safe_load((m.parent / ".hydra" / "overrides.yaml").read_text())
        runs[tuple(ov)] = json.loads(m.read_text())
    grid = [(ov, m) for ov, m in runs.items() if "experiment=grid_homing" in ov]
    assert len(grid) == 2  # fig. 5.5: one size, without and with equalisation
    for ov, m in grid:
        eq = "he" if "preprocess=he" in ov else "none"
        assert float(by[("fig5_5", f"AAE* 120x18 {eq}")]["bionav"]) == pytest.approx(m["aae"], abs=1e-6)
        assert float(by[("fig5_5", f"RR* 120x18 {eq}")]["bionav"]) == pytest.approx(m["rr"], abs=1e-6)
    lda = next(m for ov, m in runs.items() if "experiment=contrast_lda" in ov)
    r = by[("table6_2", "J UV-IR")]
    assert float(r["thesis"]) == 7.30 and float(r["bionav"]) == pytest.approx(lda["J"]["UV-IR"], abs=1e-6)
    assert float(r["difference"]) == pytest.approx(lda["J"]["UV-IR"] - 7.30, abs=1e-6)
    assert r["verdict"] == ("holds" if abs(lda["J"]["UV-IR"] - 7.30) <= 0.5 else "does not hold")
    nf = by[("table6_2", "n_f B-IR (per mille)")]
    assert float(nf["bionav"]) == pytest.approx(1000 * lda["n_f"]["B-IR"], abs=1e-4)
    # table 3.1 takes #images of sim_original from the grid runs and its grid from the config
    assert by[("table3_1", "original: #images")]["bionav"] == str(grid[0][1]["n_images"])
    assert by[("table3_1", "original: grid ny")]["verdict"] == "holds"
    # item verdict rows agree with their checks
    for item in ("table3_1", "fig5_5", "table6_2", "fig4_4"):
        checks = [r for r in rows if r["item"] == item and r["level"] in ("check", "value") and r["verdict"]]
        passed = sum(r["verdict"] == "holds" for r in checks)
        verdict = by[(item, "(item verdict)")]["verdict"]
        assert verdict == verdict_of([True] * passed + [False] * (len(checks) - passed)), item

    report = (out / "report.md").read_text()
    for label in ("Table 3.1", "Fig. 5.5", "Table 6.2", "Fig. 4.4"):
        assert f"## {label}" in report
    assert "Rule:" in report and "![Fig. 5.5: fig5_5.png](fig5_5.png)" in report
    html = (out / "report.html").read_text()
    assert html.count("data:image/png;base64,") == report.count("![") == 3

    # running the same command again reuses every run
    again = run_bionav(*args, cwd=tmp_path, module="bionav.thesis")
    assert again.returncode == 0, again.stderr
    assert "4 found completed" in again.stdout and "0 to run" in again.stdout


@pytest.mark.slow
def test_cli_reports_why_an_item_is_missing(tmp_path):
    out = tmp_path / "r"
    proc = run_bionav("--preset", "tiny", "--only", "5.3", "--out", str(out), "--report-only", cwd=tmp_path,
                      module="bionav.thesis")
    assert proc.returncode == 0, proc.stderr
    report = (out / "report.md").read_text()
    assert "**Not produced / incomplete:**" in report and "not run (--report-only)" in report
    row = next(r for r in _rows(out / "items.csv") if r["item"] == "table5_3" and r["level"] == "item")
    assert row["verdict"] == "not produced"
    # no run of the item: no value rows or checks (nothing reads "does not hold"), no empty figure embedded or left
    assert [r for r in _rows(out / "items.csv") if r["item"] == "table5_3" and r["level"] != "item"] == []
    assert "does not hold" not in report.split("## ")[-1]
    assert not (out / "table5_3.png").exists() and "<img" not in (out / "report.html").read_text()
    # the header names the command that wrote the report
    assert f"Command: `python -m bionav.thesis --preset tiny --only 5.3 --out {out} --report-only`" in report
    assert "bionav" not in {r["bionav"] for r in _rows(out / "items.csv") if r["quantity"] == "SIFT AAE* original"}


def test_cli_bad_input_is_one_clear_message(tmp_path):
    proc = run_bionav("--only", "nope", "--out", str(tmp_path / "x"), cwd=tmp_path, module="bionav.thesis")
    assert proc.returncode == 2 and "unknown item 'nope'" in proc.stderr and "Traceback" not in proc.stderr
    proc = run_bionav("--preset", "huge", "--out", str(tmp_path / "x"), cwd=tmp_path, module="bionav.thesis")
    assert proc.returncode == 2 and "unknown --preset 'huge'" in proc.stderr and "tiny" in proc.stderr
    (tmp_path / "file").write_text("")
    proc = run_bionav("--out", str(tmp_path / "file"), "--only", "3.1", cwd=tmp_path, module="bionav.thesis")
    assert proc.returncode == 2 and "is a file" in proc.stderr


def test_cli_dry_run_prints_launcher_multiruns(tmp_path):
    proc = run_bionav("--preset", "full", "--only", "5.3,table5_5", "--out", str(tmp_path / "x"), "--launcher",
                      "submitit_slurm", "--launcher-arg", "hydra.launcher.partition=cpu", "--dry-run",
                      cwd=tmp_path, module="bionav.thesis")
    assert proc.returncode == 0, proc.stderr
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("python -m bionav")]
    # the five SIFT runs of table 5.3 form one multirun over db; the parameter sweep is its own multirun
    sift = [ln for ln in lines if "homing=sift" in ln]
    assert len(sift) == 1 and "db=sim_hall1,sim_moeller1,sim_original,sim_roeben1,sim_uni" in sift[0]
    assert all("hydra/launcher=submitit_slurm" in ln and "hydra.launcher.partition=cpu" in ln for ln in lines)
    assert any("experiment=param_sweep" in ln and "experiment.grid=full" in ln for ln in lines)
    # longest expected task first: a full-grid parameter sweep (342 jobs) before the SIFT multirun's blocks
    assert "experiment=param_sweep" in lines[0] and lines.index(sift[0]) > 0
    assert not (tmp_path / "x").exists()


@pytest.mark.slow
def test_grid_homing_reports_sift_keypoints_per_image(tmp_path):
    """Tables B.1-B.4 need "Keys": grid homing reports the mean SIFT keypoint count, checked against OpenCV."""
    import cv2
    import numpy as np

    from bionav.db.synthetic import synthetic_database

    proc = run_bionav("db.image_size=[120,18]", "experiment.snapshots=[0]", f"hydra.run.dir={tmp_path / 'run'}",
                      cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    metrics = json.loads((tmp_path / "run" / "metrics.json").read_text())
    db = synthetic_database("sim_original", image_size=(120, 18), cache_dir=tmp_path / "cache", realism="camera")
    counts = [len(cv2.SIFT_create().detect(np.clip(np.rint(im * 255.0), 0, 255).astype(np.uint8), None))
              for im in db.images]
    assert metrics["keypoints_per_image"] == pytest.approx(np.mean(counts))
    assert metrics["keypoints_per_image"] > 0


@pytest.mark.slow
def test_cli_runs_through_a_hydra_launcher(tmp_path):
    """--launcher joblib: the runs become multiruns under DIR/sweeps and the report reads their jobs."""
    out = tmp_path / "rep"
    proc = run_bionav("--preset", "tiny", "--only", "fig4_4,fig4_6", "--out", str(out), "--launcher", "joblib",
                      "--launcher-arg", "hydra.launcher.n_jobs=2", cwd=tmp_path, module="bionav.thesis")
    assert proc.returncode == 0, proc.stderr + proc.stdout
    jobs = {}
    for m in out.glob("sweeps/*/*/metrics.json"):
        ov = yaml.safe_load((m.parent / ".hydra" / "overrides.yaml").read_text())
        key = next(o for o in ov if o.startswith("experiment.sky.cloud_cover") or o.startswith("mode="))
        jobs[key] = json.loads(m.read_text())
    assert {"experiment.sky.cloud_cover=0.0", "experiment.sky.cloud_cover=0.6", "mode=vs_em_compass"} <= set(jobs)
    assert not (out / "runs").exists()
    by = {(r["item"], r["quantity"]): r for r in _rows(out / "items.csv")}
    assert float(by[("fig4_6", "e-vector residual RMSE, cloud cover 0.6 (deg)")]["bionav"]) == pytest.approx(
        jobs["experiment.sky.cloud_cover=0.6"]["heading_rmse_deg"], abs=1e-6)
    assert float(by[("fig4_4", "averaged axial RMSE against the TCM2 (deg)")]["bionav"]) == pytest.approx(
        jobs["mode=vs_em_compass"]["averaged_rmse_deg"], abs=1e-6)


def test_fig4_5_shows_the_raw_first_candidate():
    """Fig. 4.5 plots the first candidate of eq. 4.6 (jumping by 180 degrees), fig. 4.4 the nearest one."""
    import numpy as np

    from bionav.experiments.pol_compass.plots import displayed_heading_deg

    truth = np.deg2rad(np.arange(-170.0, 180.0, 20.0))
    first = np.where(np.abs(truth) > np.pi / 2, truth - np.pi, truth)  # an axial sensor: one 180-degree window
    raw = displayed_heading_deg(first, truth, nearest=False)
    near = displayed_heading_deg(first, truth, nearest=True)
    wrapped_truth = (np.degrees(truth) + 180.0) % 360.0 - 180.0
    jump = np.abs(truth) > np.pi / 2
    assert np.allclose(np.abs((raw - wrapped_truth + 180.0) % 360.0 - 180.0)[jump], 180.0)
    assert np.allclose(raw[~jump], wrapped_truth[~jump])
    assert np.allclose(near, np.degrees(truth))


def test_a_multirun_is_complete_only_when_hydra_finished_it(tmp_path):
    from bionav.thesis.runs import _sweep_metrics

    for k in range(2):
        d = tmp_path / str(k)
        (d / ".hydra").mkdir(parents=True)
        (d / ".hydra" / "overrides.yaml").write_text(yaml.safe_dump([f"signature=s{k}"]))
        (d / "metrics.json").write_text(json.dumps({"status": "completed"}))
    assert _sweep_metrics(tmp_path)["status"] == "failed"  # killed before the sweep's end: no summary.csv
    (tmp_path / "summary.csv").write_text("job,status\n")
    assert _sweep_metrics(tmp_path)["status"] == "completed"
    (tmp_path / "1" / "metrics.json").write_text(json.dumps({"status": "failed"}))
    assert _sweep_metrics(tmp_path) == {"status": "failed", "n_jobs": 2, "n_completed": 1,
                                        "error": "1 of 2 jobs completed"}


def _write_significance(path: Path, crit: str, unmarked: set[frozenset[str]]) -> None:
    """A bootstrap significance table: every pair marked at 0.1 % except the ``unmarked`` ones."""
    from bionav.thesis.items import FEATURES

    with open(path / f"significance_{crit}.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow([crit, *FEATURES])
        for a in FEATURES:
            w.writerow([a, *("" if a == b or frozenset((a, b)) in unmarked else "0.001" for b in FEATURES)])


@pytest.mark.parametrize("tied", [True, False])
def test_table6_5_checks_the_discussion_claims_on_the_pairwise_bootstrap(tmp_path, tied):
    """Thesis 6.3.4: UV-IR and UV-B do not differ in J, UV-IR differs from every other contrast; one check each."""
    from bionav.thesis.items import Context
    from bionav.thesis.presets import PRESETS
    from bionav.thesis.runs import RunResult

    item = REGISTRY["table6_5"]
    preset = PRESETS["quick"]
    (spec,) = item.runs(preset)
    uv = ("UV-B", "UV-G", "UV-R", "UV-IR")
    _write_significance(tmp_path, "J", {frozenset(("UV-IR", "UV-B" if tied else "UV-R"))})
    _write_significance(tmp_path, "J_sigma", {frozenset(("UV-G", "UV-B"))})
    _write_significance(tmp_path, "n_f", {frozenset((a, b)) for a in uv for b in uv}
                        | {frozenset((a, b)) for a in ("B-G", "B-R", "B-IR") for b in ("B-G", "B-R", "B-IR")})
    res = RunResult(spec, tmp_path, {"status": "completed"})
    ctx = Context(preset, tmp_path, load_reference()["table6_5"], {spec.key: res})
    checks = {c.rule: c for c in item.evaluate(ctx, [spec]).checks}
    assert checks["UV-IR, UV-B do not differ significantly in J"].passed is tied
    differs = checks["UV-IR differs significantly (at 5 %) from every contrast but UV-B in J"]
    assert differs.passed is tied and differs.detail == ("not significant: none" if tied else "not significant: UV-R")
    assert checks["UV-G, UV-B do not differ significantly in J_sigma"].passed is True
    assert checks["UV-B, UV-G, UV-R, UV-IR do not differ significantly in n_f"].passed is True
    assert checks["B-G, B-R, B-IR do not differ significantly in n_f"].passed is True


def test_run_pool_renders_each_database_once_before_its_other_runs(tmp_path, monkeypatch):
    """Issue 29: runs go at once on --jobs slots, but a database's first run renders it alone."""
    import threading
    import time as _time

    from bionav.thesis import runs as runs_mod

    events, lock = [], threading.Lock()

    def fake_execute(spec, out, *, env=None, launcher=(), extra=()):
        with lock:
            events.append(("start", spec.key, _time.monotonic()))
        _time.sleep(0.2)
        with lock:
            events.append(("end", spec.key, _time.monotonic()))
        return runs_mod.RunResult(spec, tmp_path, {"status": "completed"}, None, 0.2, cpu_seconds=0.2)

    monkeypatch.setattr(runs_mod, "execute_local", fake_execute)
    specs = [runs_mod.RunSpec((f"db={db}", f"homing={h}")) for db in ("sim_original", "sim_hall1")
             for h in ("mfdid", "hiss", "sift")]
    from bionav.thesis.plan import task_cpu_s

    runner = runs_mod.Runner(out=tmp_path, jobs=3, echo=lambda s: None, cost=lambda s: task_cpu_s(s).cpu_s)
    results = runner.run_all(specs)
    assert set(results) == {s.key for s in specs} and all(r.ok for r in results.values())
    start = {k: t for e, k, t in events if e == "start"}
    end = {k: t for e, k, t in events if e == "end"}
    for db in ("sim_original", "sim_hall1"):
        mine = sorted((s.key for s in specs if f"db={db}" in s.overrides), key=start.get)
        first = mine[0]
        assert all(start[k] >= end[first] for k in mine[1:]), db  # the render comes first
    busy = [sum(1 for k in start if start[k] <= t < end[k]) for t in start.values()]
    assert max(busy) <= 3  # never over --jobs
    assert max(busy) >= 2  # overlapping, not one after the other
    # longest expected task first: the plan's largest estimate starts the pool
    estimate = {s.key: task_cpu_s(s).cpu_s for s in specs}
    assert min(start, key=start.get) == max(estimate, key=estimate.get)
    first = next(s for s in specs if s.key == min(start, key=start.get))
    assert first.overrides == ("db=sim_hall1", "homing=hiss")  # listed 5th, started 1st


def test_jobs_out_of_range_is_one_clear_message(tmp_path):
    proc = run_bionav("--preset", "tiny", "--only", "table3_1", "--jobs", "0", "--out", str(tmp_path / "r"),
                      cwd=tmp_path, module="bionav.thesis")
    assert proc.returncode == 2 and "Traceback" not in proc.stderr and "--jobs 0" in proc.stderr
