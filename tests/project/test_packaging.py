"""Packaging: the wheel ships bionav/conf/ and the entry points; the example plugin installs and is selectable."""

import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
from helpers import run_bionav, source_copy

ROOT = Path(__file__).resolve().parents[2]


def _pip(*args, cwd):
    return subprocess.run([sys.executable, "-m", "pip", *args], cwd=cwd, capture_output=True, text=True)


@pytest.fixture(scope="module")
def wheel(tmp_path_factory):
    out = tmp_path_factory.mktemp("wheel")
    src = source_copy(ROOT, out / "src")  # pip builds in place: never into the checkout
    proc = _pip("wheel", str(src), "--no-deps", "--no-build-isolation", "-w", str(out), "-q", cwd=out)
    assert proc.returncode == 0, proc.stderr
    return next(out.glob("bionav-*.whl"))


@pytest.mark.slow
def test_wheel_ships_configs_and_entry_points(wheel):
    with zipfile.ZipFile(wheel) as z:
        names = set(z.namelist())
        entry_points = next(z.read(n).decode() for n in names if n.endswith("entry_points.txt"))
    for required in ("bionav/conf/config.yaml", "bionav/conf/experiment/grid_homing.yaml",
                     "bionav/conf/db/sim_original.yaml", "bionav/conf/preprocess/bw1.yaml"):
        assert required in names
    assert "[bionav.homing]" in entry_points and "sift = bionav.plugins.homing.sift:SiftHoming" in entry_points
    assert "[bionav.configs]" in entry_points


@pytest.mark.slow
def test_wheel_install_runs_from_outside_the_checkout(wheel, tmp_path):
    target = tmp_path / "site"
    proc = _pip("install", "--no-deps", "--target", str(target), str(wheel), "-q", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    env = {"PYTHONPATH": str(target)}
    proc = run_bionav("--help", cwd=tmp_path, env=env)
    assert proc.returncode == 0, proc.stderr
    assert "sim_original" in proc.stdout and "grid_homing" in proc.stdout


@pytest.mark.slow
def test_regular_install_runs_from_the_checkout_root(wheel, tmp_path):
    """`pip install . && python -m bionav` from the clone's root imports the source tree, which has
    bionav/conf in place: the configs must be found (the README's first Quickstart command)."""
    target = tmp_path / "site"
    assert _pip("install", "--no-deps", "--target", str(target), str(wheel), "-q", cwd=tmp_path).returncode == 0
    proc = run_bionav("--help", cwd=ROOT, env={"PYTHONPATH": str(target), "BIONAV_CACHE": str(tmp_path / "c")})
    assert proc.returncode == 0, proc.stderr
    assert "grid_homing" in proc.stdout and "sim_original" in proc.stdout


@pytest.mark.slow
def test_example_plugin_selected_from_the_cli(tmp_path):
    target = tmp_path / "site"
    example = source_copy(ROOT / "examples" / "bionav-plugin-example", tmp_path / "example")
    proc = _pip("install", "--no-deps", "--no-build-isolation", "--target", str(target), str(example), "-q", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    env = {"PYTHONPATH": os.pathsep.join([str(target), os.environ.get("PYTHONPATH", "")])}
    listing = run_bionav(cwd=tmp_path, env=env, module="bionav.plugins")
    assert "homing=alv" in listing.stdout and "bionav-plugin-example" in listing.stdout
    help_text = run_bionav("--help", cwd=tmp_path, env=env)
    assert "alv" in help_text.stdout and "alv_bright" in help_text.stdout
    cfg = run_bionav("homing=alv", "homing.quantile=0.8", "--cfg", "job", cwd=tmp_path, env=env)
    assert cfg.returncode == 0, cfg.stderr
    assert "quantile: 0.8" in cfg.stdout and "band_deg: 10.0" in cfg.stdout
    bad = run_bionav("homing=alv", "homing.quantile=high", "--cfg", "job", cwd=tmp_path, env=env)
    assert bad.returncode != 0 and "quantile" in bad.stderr
    preset = run_bionav("homing=alv_bright", "--cfg", "job", cwd=tmp_path, env=env)
    assert preset.returncode == 0, preset.stderr
    assert "quantile: 0.9" in preset.stdout and "dark_landmarks: false" in preset.stdout


@pytest.mark.slow
def test_installed_wheel_help_lists_each_group_once(wheel, tmp_path):
    """An installed bionav/conf must not appear a second time as `conf/<group>` groups (issue 20)."""
    target = tmp_path / "site"
    assert _pip("install", "--no-deps", "--target", str(target), str(wheel), "-q", cwd=tmp_path).returncode == 0
    proc = run_bionav("--help", cwd=tmp_path, env={"PYTHONPATH": str(target), "BIONAV_CACHE": str(tmp_path / "c")})
    assert proc.returncode == 0, proc.stderr
    section = proc.stdout.split("== Configuration groups ==", 1)[1].split("== Config ==", 1)[0]
    groups = [line.split(":", 1)[0] for line in section.splitlines() if ": " in line]
    assert "experiment" in groups and len(groups) == len(set(groups)), groups
    assert not [g for g in groups if g.startswith("conf")], groups


def test_wheel_ships_the_seville_world_with_its_licence(wheel):
    with zipfile.ZipFile(wheel) as z:
        names = set(z.namelist())
    for required in ("bionav/data/seville2009/world5000_gray.mat", "bionav/data/seville2009/AntRoutes.mat",
                     "bionav/data/seville2009/LICENSE", "bionav/data/seville2009/CITATION.md",
                     "bionav/conf/db/sim_seville.yaml", "bionav/conf/experiment/route_homing.yaml"):
        assert required in names, required


@pytest.mark.slow
def test_seville_features_work_from_an_installed_wheel(wheel, tmp_path):
    target = tmp_path / "site"
    proc = _pip("install", "--no-deps", "--target", str(target), str(wheel), "-q", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    env = {"PYTHONPATH": str(target)}
    proc = run_bionav("db=sim_seville", "db.grid_shape=[3,2]", "db.image_size=[60,12]", "homing=mfdid", "workers=1",
                      f"hydra.run.dir={tmp_path / 'run'}", cwd=tmp_path, env=env)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert '"status": "completed"' in (tmp_path / "run" / "metrics.json").read_text()
    proc = run_bionav("experiment=route_homing", "db.route=Ant0_Route0", f"hydra.run.dir={tmp_path / 'r2'}",
                      cwd=tmp_path, env=env)
    assert proc.returncode == 2 and "133 routes" in proc.stderr
