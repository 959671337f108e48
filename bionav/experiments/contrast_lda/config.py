"""Config of ``experiment=contrast_lda`` (thesis 6.2-6.3); its ``data=`` group is
:class:`bionav.spectral.sample_config.DataConfig`.

Checked by the runner before the run (:func:`bionav.experiments.settings.experiment_config`).
"""

from __future__ import annotations

from dataclasses import dataclass

from bionav.validation import bounded


@dataclass
class ContrastLdaConfig:
    """``experiment=contrast_lda`` (thesis 6.2-6.3): sky/object discrimination per spectral feature.

    sigma : receptor noise for J_sigma, ADC counts (thesis: 30).
    n_resamples : bootstrap data sets for the significance tables (0 = skip).
    """

    name: str = "contrast_lda"
    sigma: float = bounded(30.0, gt=0.0, le=1e6)
    n_resamples: int = bounded(10000, ge=0, le=10_000_000)
    plots: bool = True
