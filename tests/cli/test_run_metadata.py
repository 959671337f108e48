"""run.mcap's "plugins" metadata names only the plugins the run's experiment uses (issue 32)."""

import pytest

from bionav.config import compose
from bionav.experiments.configs import EXPERIMENT_CONFIGS
from bionav.experiments.runner import EXPERIMENT_PLUGIN_GROUPS, plugin_versions


def test_every_experiment_declares_its_plugin_groups():
    assert set(EXPERIMENT_PLUGIN_GROUPS) == set(EXPERIMENT_CONFIGS)


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
