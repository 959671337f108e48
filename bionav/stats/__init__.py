"""Statistics shared by bionav's experiments (thesis section 3.3).

* Fisher's linear discriminant, with and without receptor noise
  (:func:`fisher_lda`, :func:`fisher_criterion`, :func:`optimal_criterion`).
* The minimum-misclassification threshold on a projection
  (:func:`min_error_threshold`, batched :func:`min_errors`) and the unsupervised
  two-group threshold of Otsu (:func:`otsu_threshold`).
* Jackknife standard errors (:func:`jackknife`).
* Bootstrap: one-sample intervals (:func:`bootstrap_interval`), the paired
  comparison of two methods with BCa intervals (:func:`paired_bootstrap_difference`),
  LDA criteria of many feature subsets on shared resamples (:func:`bootstrap_lda`)
  and the pairwise significance between them (:func:`pairwise_significance`).
"""

from bionav.stats.bootstrap import (
    SIGNIFICANCE_LEVELS,
    BootstrapDifference,
    Interval,
    bootstrap_interval,
    paired_bootstrap_difference,
    stars,
)
from bionav.stats.jackknife import JackknifeResult, jackknife
from bionav.stats.lda import (
    LinearDiscriminant,
    class_scatter,
    fisher_criterion,
    fisher_lda,
    optimal_criterion,
)
from bionav.stats.lda_bootstrap import LdaBootstrap, bootstrap_lda
from bionav.stats.significance import pairwise_significance
from bionav.stats.threshold import Threshold, min_error_threshold, min_errors, otsu_threshold

__all__ = [
    "SIGNIFICANCE_LEVELS",
    "BootstrapDifference",
    "Interval",
    "JackknifeResult",
    "LdaBootstrap",
    "LinearDiscriminant",
    "Threshold",
    "bootstrap_interval",
    "bootstrap_lda",
    "class_scatter",
    "fisher_criterion",
    "fisher_lda",
    "jackknife",
    "min_error_threshold",
    "min_errors",
    "optimal_criterion",
    "otsu_threshold",
    "pairwise_significance",
    "paired_bootstrap_difference",
    "stars",
]
