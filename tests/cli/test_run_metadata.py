"""run.mcap's "plugins" metadata names only the plugins the run's experiment uses (issue 32)."""

import pytest

from bionav import registry
from bionav.config import compose
from bionav.experiments.base import DEFAULT_PLUGIN_GROUPS
from bionav.experiments.runner import plugin_versions


def test_every_builtin_experiment_declares_its_plugin_groups():
    """Each of bionav's experiment plugins names the groups it reads (the base class' default is every group)."""
    plugins = registry.plugins_of("experiment", warn=False)
    builtin = {n: p.cls for n, p in plugins.items() if p.entry.distribution == "bionav"}
    assert len(builtin) >= 10
    for name, cls in builtin.items():
        assert "plugin_groups" in vars(cls), name
        assert set(cls.plugin_groups) <= set(DEFAULT_PLUGIN_GROUPS), name


@pytest.mark.parametrize("overrides, recorded", [
    ([], {"homing": "sift"}),
    (["experiment=pol_compass", "mode=rotation"], {"sensor": "polcompass_sim", "pantilt": "sim"}),
    (["experiment=pol_recordings"], {"decoder": "sky_fit"}),
    (["experiment=contrast_lda"], {}),
    (["experiment=route_homing"], {"homing": "mfdid"}),
    (["experiment=route_homing", "experiment.methods=[windowed]"], {}),
    (["experiment=param_sweep_grid"], {"homing": "parameter", "signature": "mffc_phase"}),
])
def test_plugins_metadata_names_what_the_experiment_uses(overrides, recorded):
    got = plugin_versions(compose(overrides))
    assert {k: v.split(" ")[0] for k, v in got.items() if k != "bionav"} == recorded
