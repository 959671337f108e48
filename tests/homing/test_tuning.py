"""Sweepers that optimise: the task returns the configured objective (worst on failure); a real Optuna study."""

import json
import math

import pytest
import yaml
from helpers import run_bionav, write_tiny_folder

from bionav.errors import UserError
from bionav.experiments.objective import Objective, objective_from_config


@pytest.fixture
def textured_folder(tmp_path):
    """A 3 x 3 Vardy-named database of textured 128 x 32 panoramas (enough SIFT features)."""
    return write_tiny_folder(tmp_path / "tiny", shape=(32, 128), sigma=1.5)


def test_objective_value_and_worst():
    aae = Objective("aae", "minimize")
    assert aae.value({"status": "completed", "aae": 0.25}) == 0.25
    assert aae.value({"status": "failed", "aae": 0.25}) == math.inf
    assert aae.value({"status": "completed"}) == math.inf  # metric missing
    assert aae.value({"status": "completed", "aae": float("nan")}) == math.inf
    assert aae.value(None) == math.inf
    j = Objective("J.all", "maximize")
    assert j.value({"status": "completed", "J": {"all": 2.5, "UV": 1.0}}) == 2.5
    assert j.value({"status": "failed"}) == -math.inf
    assert Objective("rr.skyline:all", "maximize").value({"rr": {"skyline:all": 0.5}}) == 0.5
    with pytest.raises(UserError, match="one of minimize, maximize"):
        objective_from_config({"metric": "aae", "direction": "down"})
    with pytest.raises(UserError, match="objective.metric"):
        objective_from_config({"metric": None, "direction": "minimize"})


def test_every_experiment_has_a_valid_default_objective():
    from bionav.config import compose, config_dirs

    own = dict(config_dirs())["bionav"]
    default = yaml.safe_load((own / "config.yaml").read_text())["objective"]
    for path in sorted((own / "experiment").glob("*.yaml")):
        node = yaml.safe_load(path.read_text()).get("objective", default)
        objective = objective_from_config(node)
        assert objective.metric and objective.direction in ("minimize", "maximize"), path.name
    cfg = compose(["experiment=cleaning"])
    assert (cfg.objective.metric, cfg.objective.direction) == ("coverage", "maximize")
    assert (compose([]).objective.metric, compose([]).objective.direction) == ("aae", "minimize")


def test_bad_direction_is_a_user_error(tmp_path, textured_folder):
    proc = run_bionav("homing=mfdid", "db=folder", f"db.path={textured_folder}", "objective.direction=down",
                      f"hydra.run.dir={tmp_path / 'run'}", cwd=tmp_path)
    assert proc.returncode == 2
    assert "bad value objective.direction=down" in proc.stderr and "one of minimize, maximize" in proc.stderr
    assert "Traceback" not in proc.stderr


@pytest.mark.slow
def test_optuna_study_of_sift_homing_parameters(tmp_path, textured_folder):
    pytest.importorskip("hydra_plugins.hydra_optuna_sweeper", reason="needs the tune extra: pip install 'bionav[tune]'")
    sweep = tmp_path / "study"
    proc = run_bionav(
        "-m", "hydra/sweeper=optuna", "hydra.sweeper.n_trials=4", "hydra.sweeper.n_jobs=1",
        "hydra.sweeper.direction=minimize", "hydra.sweeper.sampler.seed=0",
        "homing=sift", "homing.search_radius=interval(0.1,0.4)", "homing.combine=choice(average,max)",
        "homing.window=range(5,30,step=5)", "db=folder", f"db.path={textured_folder}",
        f"hydra.sweep.dir={sweep}", cwd=tmp_path,
    )
    assert proc.returncode == 0, proc.stderr
    jobs = {}
    for job in sorted(sweep.glob("[0-9]*")):
        metrics = json.loads((job / "metrics.json").read_text())
        assert metrics["status"] == "completed"
        overrides = dict(o.split("=", 1) for o in yaml.safe_load((job / ".hydra" / "overrides.yaml").read_text()))
        jobs[job.name] = (metrics["aae"], overrides)
    assert len(jobs) == 4
    assert len({o["homing.search_radius"] for _, o in jobs.values()}) == 4  # four different trials
    best_aae, best_overrides = min(jobs.values(), key=lambda item: item[0])
    result = yaml.safe_load((sweep / "optimization_results.yaml").read_text())
    # Optuna's best value is the smallest AAE* in the jobs' metrics.json, its parameters that job's
    assert result["best_value"] == pytest.approx(best_aae, rel=1e-12)
    assert result["best_params"]["homing.combine"] == best_overrides["homing.combine"]
    assert result["best_params"]["homing.search_radius"] == pytest.approx(float(best_overrides["homing.search_radius"]))
    rows = (sweep / "summary.csv").read_text().splitlines()
    assert len(rows) == 5


@pytest.mark.slow
def test_optuna_ranks_failed_jobs_worst(tmp_path):
    pytest.importorskip("hydra_plugins.hydra_optuna_sweeper", reason="needs the tune extra: pip install 'bionav[tune]'")
    sweep = tmp_path / "study"
    proc = run_bionav(
        "-m", "hydra/sweeper=optuna", "hydra.sweeper.n_trials=2", "hydra.sweeper.direction=maximize",
        "objective.metric=rr", "objective.direction=maximize", "homing=mfdid",
        "seed=range(0,5)",
        "db=folder", f"db.path={tmp_path / 'missing'}", f"hydra.sweep.dir={sweep}", cwd=tmp_path,
    )
    assert proc.returncode == 1 and "2 of 2 jobs failed" in proc.stderr, proc.stderr  # the sweep still ends
    result = yaml.safe_load((sweep / "optimization_results.yaml").read_text())
    assert result["best_value"] == -math.inf
    assert all(json.loads(p.read_text())["status"] == "failed" for p in sweep.glob("*/metrics.json"))
