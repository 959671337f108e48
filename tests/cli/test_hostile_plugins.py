"""Hostile plugin installs (issue 13 item 9): two real third-party distributions claim one name.

The distributions are real ``.dist-info`` folders with entry points on a ``PYTHONPATH`` entry, so
``importlib.metadata`` finds them exactly as it finds pip-installed packages; nothing of the
registry is mocked. The duplicate must block only its own name: the built-in methods, another
third-party plugin and ``python -m bionav.plugins`` stay usable.
"""

from __future__ import annotations

import os

import pytest
from helpers import install_plugin_dist as install
from helpers import run_bionav

PLUGIN = """
from dataclasses import dataclass

from bionav.homing.base import HomeVector, HomingMethod
from bionav.validation import bounded


class Twin(HomingMethod):
    @dataclass
    class Config:
        gain: float = bounded(1.0, gt=0.0, le=10.0)

    requires_alignment = False

    def home_vector(self, snapshot, current, *, neighbours=None):
        return HomeVector(0.0)
"""


@pytest.fixture
def site(tmp_path):
    site = tmp_path / "site"
    install(site, "acme-homing", {"bionav.homing": {"twin": "acme_twin:Twin", "solo": "acme_twin:Twin"}},
            {"acme_twin": PLUGIN})
    install(site, "other-homing", {"bionav.homing": {"twin": "other_twin:Twin"}}, {"other_twin": PLUGIN})
    return site


def env_with(site):
    return {"PYTHONPATH": os.pathsep.join([str(site), os.environ.get("PYTHONPATH", "")]).rstrip(os.pathsep)}


def test_duplicate_name_blocks_only_that_name(tmp_path, site):
    env = env_with(site)
    proc = run_bionav("homing=twin", f"hydra.run.dir={tmp_path / 'run'}", cwd=tmp_path, env=env)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    assert "Traceback" not in proc.stderr, proc.stderr
    errors = [line for line in proc.stderr.splitlines() if line.startswith("bionav: error:")]
    assert len(errors) == 1, proc.stderr
    message = errors[0]
    assert "acme-homing" in message and "other-homing" in message and "'twin'" in message
    assert "pip uninstall" in message and "rename" in message
    assert not (tmp_path / "run").exists() or not any((tmp_path / "run").iterdir())


@pytest.mark.slow
def test_other_plugins_and_builtins_stay_usable(tmp_path, site):
    env = env_with(site)
    for homing in ("mfdid", "solo"):  # a built-in and the other plugin of one of the two distributions
        proc = run_bionav(f"homing={homing}", "--cfg", "job", cwd=tmp_path, env=env)
        assert proc.returncode == 0, proc.stderr
        assert f"name: {homing}" in proc.stdout
    proc = run_bionav("homing=solo", "homing.gain=-2", cwd=tmp_path, env=env)  # its typed range is checked
    assert proc.returncode == 2 and "homing.gain=-2" in proc.stderr and "Traceback" not in proc.stderr


def test_plugin_listing_shows_everything_and_names_the_conflict(tmp_path, site):
    proc = run_bionav(cwd=tmp_path, env=env_with(site), module="bionav.plugins")
    assert proc.returncode == 0, proc.stderr
    out = proc.stdout
    assert "homing=sift" in out and "homing=minwarping" in out and "homing=solo" in out  # built-in list intact
    twin = [line for line in out.splitlines() if "homing=twin" in line]
    assert twin and "FAILED" in twin[0]
    assert "acme-homing" in out and "other-homing" in out


def test_unknown_homing_still_lists_all_names(tmp_path, site):
    proc = run_bionav("homing=nope", cwd=tmp_path, env=env_with(site))
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert "sift" in proc.stderr and "solo" in proc.stderr


def test_plugin_list_into_a_closed_pipe_ends_quietly(tmp_path):
    from helpers import run_into_closed_pipe

    proc = run_into_closed_pipe(module="bionav.plugins", cwd=tmp_path)
    assert proc.returncode == 141, proc.stderr
    assert "Traceback" not in proc.stderr and "BrokenPipeError" not in proc.stderr, proc.stderr
