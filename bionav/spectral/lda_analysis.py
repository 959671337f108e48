"""Sky/object discrimination per spectral feature: tables 6.2-6.5 of the thesis.

For every feature (single channel, channel pair, all five; see
:func:`bionav.light.bands.feature_subsets`) Fisher's LDA separates sky
(class 1) from objects (class 0) on the counts; reported are ``J``,
``J_sigma`` (receptor noise ``sigma``, thesis: 30 counts) and ``n_f``, the
fraction of samples misclassified by the minimum-error threshold on the
``J``-optimal projection. The bootstrap (10,000 stratified resamples, all
features on the same resamples) then tests which features differ
significantly (5 %, 1 %, 0.1 %).
"""

from __future__ import annotations

import io
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from bionav.files import write_csv_atomic
from bionav.light.bands import CHANNELS, feature_subsets
from bionav.spectral.samples import SampleSet
from bionav.stats import (
    LinearDiscriminant,
    bootstrap_lda,
    fisher_lda,
    pairwise_significance,
    stars,
)

#: The three criteria and whether larger is better.
CRITERIA = {"J": True, "J_sigma": True, "n_f": False}


@dataclass(frozen=True)
class FeatureResult:
    """LDA of one feature.

    Attributes
    ----------
    name : str
        Feature name (``"UV"``, ``"UV-IR"``, ``"all"``).
    channels : tuple of int
        Channel indices.
    lda : LinearDiscriminant
        Plain Fisher LDA (its ``criterion`` is ``J``; its threshold gives ``n_f``).
    lda_sigma : LinearDiscriminant
        LDA with receptor noise (its ``criterion`` is ``J_sigma``).
    """

    name: str
    channels: tuple
    lda: LinearDiscriminant
    lda_sigma: LinearDiscriminant

    @property
    def J(self) -> float:
        return self.lda.criterion

    @property
    def J_sigma(self) -> float:
        return self.lda_sigma.criterion

    @property
    def n_f(self) -> float:
        """Misclassified fraction with the ``J`` direction and its minimum-error threshold."""
        return self.lda.error_fraction


def analyse_features(samples: SampleSet, *, sigma: float = 30.0) -> dict[str, FeatureResult]:
    """LDA of every feature of a sample set.

    Parameters
    ----------
    samples : SampleSet
    sigma : float
        Receptor-noise standard deviation in counts for ``J_sigma``.

    Returns
    -------
    dict
        Feature name -> :class:`FeatureResult`, in the order of
        :func:`~bionav.light.bands.feature_subsets`.
    """
    out = {}
    for name, sub in feature_subsets().items():
        x = samples.counts[:, sub]
        out[name] = FeatureResult(name, sub, fisher_lda(x, samples.is_sky),
                                  fisher_lda(x, samples.is_sky, sigma=sigma))
    return out


@dataclass(frozen=True)
class Significance:
    """Bootstrap significance between features for one criterion.

    Attributes
    ----------
    criterion : str
        ``"J"``, ``"J_sigma"`` or ``"n_f"``.
    names : list of str
        Features in table order.
    estimates : ndarray, shape (K,)
    levels : ndarray, shape (K, K)
        Smallest level (0.05, 0.01, 0.001) at which two features differ; NaN if none.
    ranking : list of str
        Features from best to worst.
    """

    criterion: str
    names: list
    estimates: np.ndarray
    levels: np.ndarray
    ranking: list

    def versus_next(self) -> list[tuple[str, float, str]]:
        """``(feature, estimate, mark)`` best first; the mark is the significance of the
        difference to the next-ranked feature (the thesis' tables 6.3/6.5 read downwards)."""
        idx = {n: i for i, n in enumerate(self.names)}
        rows = []
        for k, name in enumerate(self.ranking):
            mark = ""
            if k + 1 < len(self.ranking):
                mark = stars(self.levels[idx[name], idx[self.ranking[k + 1]]])
            rows.append((name, float(self.estimates[idx[name]]), mark))
        return rows


def learn_discriminants(samples: SampleSet, *, sigma: float = 30.0) -> dict:
    """The ``J_sigma`` discriminant of every feature, learned on a labelled sample set.

    Parameters
    ----------
    samples : SampleSet
        Labelled sky and object samples.
    sigma : float
        Receptor noise (counts) of the noise-aware Fisher criterion.

    Returns
    -------
    dict
        Feature name (:func:`~bionav.light.bands.feature_subsets`) -> its
        ``lda_sigma`` discriminant (:class:`FeatureResult`).
    """
    return {n: r.lda_sigma for n, r in analyse_features(samples, sigma=sigma).items()}


def bootstrap_significance(samples: SampleSet, results: dict[str, FeatureResult], *, sigma: float = 30.0,
                           n_resamples: int = 10_000, rng: np.random.Generator) -> dict[str, Significance]:
    """Pairwise bootstrap significance of J, J_sigma and n_f between all features.

    Parameters
    ----------
    samples : SampleSet
    results : dict
        Output of :func:`analyse_features` (gives names, subsets and estimates).
    sigma : float
        Receptor noise for ``J_sigma``.
    n_resamples : int
        Bootstrap data sets (thesis: 10,000).
    rng : numpy.random.Generator

    Returns
    -------
    dict
        Criterion -> :class:`Significance`.
    """
    names = list(results)
    boot = bootstrap_lda(samples.counts, samples.is_sky, [results[n].channels for n in names], sigma=sigma,
                         n_resamples=n_resamples, rng=rng)
    out = {}
    for crit, larger_better in CRITERIA.items():
        est = np.array([getattr(results[n], crit) for n in names])
        order = np.argsort(-est if larger_better else est, kind="stable")
        out[crit] = Significance(crit, names, est, pairwise_significance(getattr(boot, crit)),
                                 [names[i] for i in order])
    return out


# -- tables --------------------------------------------------------------------

def write_lda_table_csv(results: dict[str, FeatureResult], path) -> Path:
    """``lda_table.csv``: one row per feature with J, J_sigma, n_f (fraction), ranks, direction, threshold."""
    path = Path(path)
    names = list(results)
    ranks = {}
    for crit, larger in CRITERIA.items():
        est = np.array([getattr(results[n], crit) for n in names])
        order = np.argsort(-est if larger else est, kind="stable")
        ranks[crit] = {names[i]: r + 1 for r, i in enumerate(order)}
    header = ["feature", "channels", "J", "J_sigma", "n_f", "n_f_sigma", "rank_J", "rank_J_sigma", "rank_n_f",
              "direction", "threshold", "direction_sigma", "threshold_sigma"]
    rows = []
    for n in names:
        r = results[n]
        rows.append([n, " ".join(CHANNELS[i] for i in r.channels), f"{r.J:.6g}", f"{r.J_sigma:.6g}",
                     f"{r.n_f:.6g}", f"{r.lda_sigma.error_fraction:.6g}", ranks["J"][n], ranks["J_sigma"][n],
                     ranks["n_f"][n], " ".join(f"{v:.6g}" for v in r.lda.direction), f"{r.lda.threshold:.6g}",
                     " ".join(f"{v:.6g}" for v in r.lda_sigma.direction), f"{r.lda_sigma.threshold:.6g}"])
    write_csv_atomic(path, header, rows)
    return path


def _pair_matrix(results, attr, fmt):
    rows = CHANNELS[:-1]
    cols = CHANNELS[1:]
    lines = ["| " + attr + " | " + " | ".join(cols) + " |", "|---" * (len(cols) + 1) + "|"]
    for i, a in enumerate(rows):
        cells = []
        for j, b in enumerate(cols, start=1):
            cells.append(fmt(getattr(results[f"{a}-{b}"], attr)) if j > i else "")
        lines.append(f"| **{a}** | " + " | ".join(cells) + " |")
    return lines


def lda_table_markdown(results: dict[str, FeatureResult], *, title: str = "", sigma: float = 30.0) -> str:
    """Markdown tables in the layout of thesis tables 6.2/6.4 (n_f in per mille, as the thesis prints it)."""
    out = io.StringIO()
    if title:
        out.write(f"# {title}\n\n")
    singles = list(CHANNELS) + ["all"]
    out.write(f"Single-channel and five-channel features (J: eq. 3.16; J_sigma: eq. 3.22 with sigma = {sigma:g} "
              "counts; n_f: misclassified samples, per mille).\n\n")
    out.write("| | " + " | ".join(singles) + " |\n" + "|---" * (len(singles) + 1) + "|\n")
    out.write("| J | " + " | ".join(f"{results[s].J:.2f}" for s in singles) + " |\n")
    out.write("| J_sigma | " + " | ".join(f"{results[s].J_sigma:.2f}" for s in singles) + " |\n")
    out.write("| n_f [‰] | " + " | ".join(f"{1000 * results[s].n_f:.0f}" for s in singles) + " |\n\n")
    out.write("Dual-channel features (2-D LDA on the two channels):\n\n")
    for attr, fmt in (("J", "{:.2f}"), ("J_sigma", "{:.2f}")):
        out.write("\n".join(_pair_matrix(results, attr, fmt.format)) + "\n\n")
    out.write("\n".join(_pair_matrix(results, "n_f", lambda v: f"{1000 * v:.0f}")).replace("| n_f |", "| n_f [‰] |"))
    out.write("\n\nRanking by J: " + ", ".join(sorted(results, key=lambda n: -results[n].J)) + "\n")
    return out.getvalue()


def significance_markdown(sig: dict[str, Significance], *, title: str = "", n_resamples: int = 10_000) -> str:
    """Tables in the layout of thesis tables 6.3/6.5 plus the full pairwise matrices."""
    out = io.StringIO()
    if title:
        out.write(f"# {title}\n\n")
    out.write(f"Bootstrap with {n_resamples} stratified resamples; features ranked best first; the mark is the "
              "significance of the difference to the next-ranked feature (*** 0.1 %, ** 1 %, * 5 %, "
              "blank: not significant).\n\n")
    crits = list(sig)
    out.write("| " + " | ".join(f"{c} | value | sig." for c in crits) + " |\n")
    out.write("|---" * (3 * len(crits)) + "|\n")
    cols = [s.versus_next() for s in sig.values()]
    for k in range(len(cols[0])):
        cells = []
        for crit, col in zip(crits, cols):
            name, value, mark = col[k]
            cells += [name, f"{1000 * value:.0f} ‰" if crit == "n_f" else f"{value:.2f}", mark]
        out.write("| " + " | ".join(cells) + " |\n")
    for crit, s in sig.items():
        out.write(f"\n## Pairwise significance of {crit}\n\n")
        out.write("| | " + " | ".join(s.names) + " |\n" + "|---" * (len(s.names) + 1) + "|\n")
        for i, a in enumerate(s.names):
            out.write(f"| **{a}** | " + " | ".join(stars(s.levels[i, j]) for j in range(len(s.names))) + " |\n")
    return out.getvalue()


def write_significance_csv(s: Significance, path) -> Path:
    """Matrix of smallest significant levels (blank: not significant) for one criterion."""
    path = Path(path)
    write_csv_atomic(path, [s.criterion] + s.names,
                     ([a] + ["" if not np.isfinite(v) else f"{v:g}" for v in s.levels[i]] for i, a in enumerate(s.names)))
    return path
