"""``experiment=contrast_lda``: which spectral contrast separates sky from objects best (thesis 6.2, 6.3)."""

from __future__ import annotations

from typing import Any

from bionav.experiments.base import Experiment
from bionav.experiments.contrast_lda.config import ContrastLdaConfig
from bionav.spectral.sample_config import DataConfig


class ContrastLda(Experiment):
    """Fisher LDA of every spectral feature on a labelled sample set (``data=``)."""

    Config = ContrastLdaConfig
    plugin_groups = ()
    group_configs = {"data": DataConfig}

    def run(self, ctx) -> dict[str, Any]:
        from bionav.experiments.contrast_lda.run import run

        return run(self.config, ctx)
