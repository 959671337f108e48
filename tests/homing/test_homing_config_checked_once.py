"""A homing config's declared ranges are checked once on either door (issue 28 item 2).

The command line types the ``homing`` node with :func:`bionav.validation.typed_config` (checked there);
``HomingMethod.__init__`` checks instances built in Python, and skips one typed_config already checked
unless its values changed since.
"""

import dataclasses

import pytest
from helpers import assert_fails_cleanly, run_bionav

import bionav.validation as validation
from bionav.config import plugin_config
from bionav.errors import UserError
from bionav.geometry import PanoramaGeometry
from bionav.plugins.homing.sift import SiftConfig, SiftHoming

GEOMETRY = PanoramaGeometry.square_pixels(72, 16)


@pytest.fixture
def homing_checks(monkeypatch):
    """The ``homing`` prefixes :func:`bionav.validation.check_config` is called with, in order."""
    calls = []
    original = validation.check_config

    def counting(config, *, prefix):
        calls.append(prefix)
        return original(config, prefix=prefix)

    monkeypatch.setattr(validation, "check_config", counting)
    return calls


def test_the_command_line_path_checks_once(homing_checks):
    cls, config = plugin_config("homing", {"name": "sift", "sigma": 2.0})  # what ctx.plugin does
    method = cls(config, geometry=GEOMETRY)
    assert method.config.sigma == 2.0
    assert homing_checks == ["homing"]  # in typed_config, not again in HomingMethod.__init__


def test_the_python_api_checks_once(homing_checks):
    SiftHoming(SiftConfig(sigma=2.0), geometry=GEOMETRY)
    assert homing_checks == ["homing"]


def test_the_python_api_refuses_a_bad_value():
    with pytest.raises(UserError, match=r"bad value homing\.sigma=-1.0: .*allowed: a finite number > 0 and <= 10"):
        SiftHoming(SiftConfig(sigma=-1.0), geometry=GEOMETRY)


def test_a_checked_config_changed_afterwards_is_checked_again(homing_checks):
    _, config = plugin_config("homing", {"name": "sift"})
    config.sigma = -1.0  # after typed_config: its earlier check no longer holds
    with pytest.raises(UserError, match=r"bad value homing\.sigma=-1.0"):
        SiftHoming(config, geometry=GEOMETRY)
    assert homing_checks == ["homing", "homing"]
    fresh = dataclasses.replace(plugin_config("homing", {"name": "sift"})[1], sigma=2.0)  # a new instance
    SiftHoming(fresh, geometry=GEOMETRY)
    assert homing_checks == ["homing", "homing", "homing", "homing"]


def test_a_checked_config_changed_to_an_array_is_checked_again():
    """An array's == is element-wise: the "unchanged since the check" test must not trip over it."""
    import numpy as np

    _, config = plugin_config("homing", {"name": "sift"})
    config.image_size = np.array([72, 16])
    with pytest.raises(UserError, match=r"bad value homing\.image_size=\[72 16\]: it is not a list"):
        SiftHoming(config, geometry=GEOMETRY)


@pytest.mark.slow
def test_the_command_line_refuses_a_bad_value_once(tmp_path):
    proc = run_bionav("homing=sift", "homing.sigma=-1", f"hydra.run.dir={tmp_path / 'run'}", cwd=tmp_path)
    assert_fails_cleanly(proc, "bad value homing.sigma=-1.0", "allowed: a finite number > 0 and <= 10", code=2)
    assert not (tmp_path / "run").exists() or not any((tmp_path / "run").iterdir())
