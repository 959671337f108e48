"""The first run's kernel warm-up (bionav.experiments.warmup) runs only bionav's own homing methods.

A third-party homing plugin's ``home_vector`` may write files, drive devices or sleep; a second
process calling it unasked would do all that twice (and corrupt, e.g., the ground truth of
tests/cli/test_hostile_long_rows.py). The plugin below appends one line per home vector to a file:
a run of the 3 x 3 database must leave exactly its 9 x 8 = 72 pairs there, with the numba cache
empty (where a warm-up of a bionav method would start).
"""

from __future__ import annotations

import os

import pytest
from helpers import install_plugin_dist, pythonpath_with, run_bionav, write_tiny_folder

COUNTING_PLUGIN = '''
import os
from dataclasses import dataclass

from bionav.homing.base import HomeVector, HomingMethod


class CountingHoming(HomingMethod):
    """Test-only: points along +x (angle 0) and appends a line per home vector to $COUNT_LOG."""

    @dataclass
    class Config:
        pass

    requires_alignment = False

    def home_vector(self, snapshot, current, *, neighbours=None):
        with open(os.environ["COUNT_LOG"], "a") as f:
            f.write("pair\\n")
        return HomeVector(0.0)
'''


def test_bionav_methods_are_warmed_and_plugins_are_not():
    from bionav.experiments.warmup import _ships_with_bionav

    assert _ships_with_bionav("sift") and _ships_with_bionav("minwarping")
    assert not _ships_with_bionav("no_such_method")


def test_a_third_party_method_is_called_only_by_the_run(tmp_path):
    site = tmp_path / "site"
    install_plugin_dist(site, "counting-homing", {"bionav.homing": {"counting": "counting_homing:CountingHoming"}},
                        {"counting_homing": COUNTING_PLUGIN})
    tiny = write_tiny_folder(tmp_path / "tiny")
    log = tmp_path / "pairs.log"
    env = {"COUNT_LOG": str(log), "NUMBA_CACHE_DIR": str(tmp_path / "numba"), **pythonpath_with(site)}
    if os.environ.get("BIONAV_NO_WARMUP"):
        pytest.skip("BIONAV_NO_WARMUP is set here, so no warm-up would start either way")
    proc = run_bionav("homing=counting", "db=folder", f"db.path={tiny}", "workers=1", "bionav.cache_prepared=false",
                      f"hydra.run.dir={tmp_path / 'run'}", cwd=tmp_path, env=env)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert log.read_text().count("pair") == 9 * 8


def test_the_warmup_compiles_the_shadow_bins_a_rendering_run_then_loads(tmp_path):
    """For a synthetic database the warm-up builds a one-light scene's shadow bins first: the run's own
    scene (other lights, casters) then loads the compiled code from numba's cache instead of compiling."""
    import subprocess
    import sys

    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "numba")}
    warm = subprocess.run([sys.executable, "-c", "from bionav.experiments.warmup import warm_shadow_bins; "
                           "warm_shadow_bins()"], env=env, capture_output=True, text=True, timeout=600)
    assert warm.returncode == 0, warm.stderr[-2000:]
    check = ("from bionav.db.standins import get_spec\n"
             "from bionav.world.shadow_bins import build_shadow_bins\n"
             "cs = get_spec('sim_original').builder(0).scene.compiled()\n"
             "assert cs.shadow_grids is None  # lazily built\n"
             "grids, starts, items = cs.shadow_bins()\n"
             "s = build_shadow_bins.stats\n"
             "print(sum(s.cache_hits.values()), sum(s.cache_misses.values()), len(cs.light_params), items.shape[0])\n")
    run = subprocess.run([sys.executable, "-c", check], env=env, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-2000:]
    hits, misses, n_lights, rows = map(int, run.stdout.split())
    assert (hits, misses) == (1, 0)
    assert n_lights > 1 and rows == n_lights  # a scene unlike the warm-up's, still the same compiled code


def test_the_warmup_learns_whether_the_run_renders(monkeypatch, tmp_path):
    from omegaconf import OmegaConf

    from bionav.experiments import warmup

    started = []
    monkeypatch.delenv("BIONAV_NO_WARMUP", raising=False)
    monkeypatch.setattr(warmup.subprocess, "Popen", lambda argv, **kw: started.append(argv))
    monkeypatch.setattr(warmup, "_marker", lambda method: tmp_path / "no-marker-yet")
    cfg = OmegaConf.create({"homing": {"name": "sift"}, "db": {"source": "synthetic", "name": "sim_original"}})
    warmup.start_warmup(cfg, used_groups=("homing",))
    cfg.db.source = "folder"
    warmup.start_warmup(cfg, used_groups=("homing",))
    assert [argv[-1] for argv in started] == ["render", "no-render"]
