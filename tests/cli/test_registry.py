"""Registry failure modes: broken plugin, duplicate name, missing Config, lookup by name or class."""

import warnings

import pytest

from bionav import registry
from bionav.errors import PluginError

GOOD = """
from dataclasses import dataclass
from bionav.homing.base import HomingMethod, HomeVector

@dataclass
class Cfg:
    gain: float = 1.0

class Good(HomingMethod):
    Config = Cfg
    def home_vector(self, s, c, *, neighbours=None):
        return HomeVector(0.0)

class NoConfig(HomingMethod):
    pass
"""


def test_builtins_are_registered_through_entry_points():
    entries = registry.entry_points_of("homing")
    assert {"sift", "mfdid"} <= set(entries)
    assert entries["sift"].distribution == "bionav"
    assert registry.load_plugin("homing", "sift").__name__ == "SiftHoming"


def test_lookup_accepts_name_or_class(fake_distributions):
    fake_distributions("fake-good", {"bionav.homing": {"good": "fakeplug_good:Good"}}, {"fakeplug_good": GOOD})
    cls = registry.load_plugin("homing", "good")
    assert registry.load_plugin("homing", cls) is cls


def test_unknown_name_lists_available():
    with pytest.raises(PluginError, match="Available: .*mfdid.*sift"):
        registry.load_plugin("homing", "nonexistent")


def test_broken_plugin_is_a_warning_and_an_error_only_when_selected(fake_distributions):
    fake_distributions(
        "fake-broken",
        {"bionav.homing": {"broken": "fakeplug_broken:Method"}},
        {"fakeplug_broken": "import a_module_that_does_not_exist\n"},
    )
    with pytest.warns(registry.PluginWarning, match="broken.*fake-broken"):
        loaded = registry.plugins_of("homing")
    assert loaded["broken"].cls is None and "ModuleNotFoundError" in loaded["broken"].error
    assert loaded["sift"].cls is not None  # others unaffected
    with pytest.raises(PluginError, match="fake-broken.*failed to load.*a_module_that_does_not_exist"):
        registry.load_plugin("homing", "broken")


def test_missing_attribute_and_missing_config(fake_distributions):
    fake_distributions(
        "fake-attrs",
        {"bionav.homing": {"noattr": "fakeplug_attrs:DoesNotExist", "nocfg": "fakeplug_attrs:NoConfig"}},
        {"fakeplug_attrs": GOOD},
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        loaded = registry.plugins_of("homing")
    assert "AttributeError" in loaded["noattr"].error
    assert "Config" in loaded["nocfg"].error
    with pytest.raises(PluginError, match="fake-attrs"):
        registry.load_plugin("homing", "nocfg")


def test_duplicate_name_from_two_distributions_names_both(fake_distributions):
    fake_distributions("fake-one", {"bionav.homing": {"twin": "fakeplug_one:Good"}}, {"fakeplug_one": GOOD})
    fake_distributions("fake-two", {"bionav.homing": {"twin": "fakeplug_two:Good"}}, {"fakeplug_two": GOOD})
    # issue 13 item 9: the duplicate blocks only its own name (tests/cli/test_hostile_plugins.py covers the CLI)
    assert {"twin", "sift", "mfdid"} <= set(registry.entry_points_of("homing"))
    with pytest.raises(PluginError, match="fake-one.*fake-two|fake-two.*fake-one"):
        registry.load_plugin("homing", "twin")
    assert registry.load_plugin("homing", "sift").__name__ == "SiftHoming"


def test_entry_points_are_read_once(fake_distributions, monkeypatch):
    registry.entry_points_of("homing")
    calls = []
    monkeypatch.setattr(registry.importlib_metadata, "entry_points", lambda: calls.append(1))
    registry.entry_points_of("homing")
    registry.load_plugin("homing", "sift")
    assert calls == []


EXPERIMENT = """
from dataclasses import dataclass
from bionav.experiments import Experiment
from bionav.validation import bounded

@dataclass
class SpinConfig:
    turns: int = bounded(2, ge=1, le=10)

class Spin(Experiment):
    Config = SpinConfig
    plugin_groups = ()

    def run(self, ctx):
        return {"turns": self.config.turns}

class NoRun:
    Config = SpinConfig
"""


def test_experiments_are_plugins_like_the_others(fake_distributions):
    """Issue 39: bionav's experiments come from entry points; a third-party one is listed, loaded and composed
    with no YAML (its keys from its Config); a broken one is a warning until selected; a duplicate blocks its name."""
    import warnings

    from bionav.config import compose
    from bionav.experiments.settings import experiment_config

    builtin = registry.entry_points_of("experiment")
    assert {"grid_homing", "cleaning", "pol_recordings"} <= set(builtin)
    assert builtin["grid_homing"].distribution == "bionav"
    fake_distributions("fake-spin", {"bionav.experiments": {"spin": "fakeexp_spin:Spin", "norun": "fakeexp_spin:NoRun",
                                                             "broken": "fakeexp_missing:Spin"}},
                       {"fakeexp_spin": EXPERIMENT})
    fake_distributions("fake-twin", {"bionav.experiments": {"grid_homing": "fakeexp_spin:Spin"}})
    assert "spin" in registry.names_by_group()["experiment"]  # listed from the entry points alone
    cfg = compose(["experiment=spin", "experiment.turns=3"])
    assert dict(cfg.experiment) == {"turns": 3, "name": "spin"}
    assert experiment_config(cfg).turns == 3
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        loaded = registry.plugins_of("experiment")
    messages = " ".join(str(w.message) for w in caught)
    assert "fake-spin" in messages and "broken" in messages and "norun" in messages
    assert "no `run(self, ctx)` method" in loaded["norun"].error
    assert loaded["spin"].cls.__name__ == "Spin" and loaded["cleaning"].cls is not None
    with pytest.raises(PluginError, match="fake-twin"):  # two distributions claim grid_homing
        registry.load_plugin("experiment", "grid_homing")
    assert registry.load_plugin("experiment", "cleaning").__name__ == "Cleaning"  # the others stay usable
    with pytest.raises(PluginError, match="experiment plugin 'broken'.*fake-spin.*fakeexp_missing"):
        registry.load_plugin("experiment", "broken")
