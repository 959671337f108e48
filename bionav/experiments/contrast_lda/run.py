"""``experiment=contrast_lda``: which spectral contrast separates sky from objects best (thesis 6.2, 6.3).

``python -m bionav experiment=contrast_lda data=sim_natural|sim_artificial|csv [data.path=FILE]``

Writes ``lda_table.csv``/``lda_table.md`` (tables 6.2/6.4), ``significance.md``
and ``significance_<criterion>.csv`` (tables 6.3/6.5), ``samples.csv`` (the
data analysed), and plots ``plots/uv_g_uv_ir.png`` (fig. 6.3),
``plots/pairs.png`` (figs. 6.4/6.5), ``plots/projection_histograms.png``
(figs. D.1/D.2) and ``plots/criteria.png``. ``metrics.json`` holds ``J``,
``J_sigma`` and ``n_f`` (a fraction), each keyed by feature name.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from bionav.errors import UserError
from bionav.experiments.common import load_samples
from bionav.experiments.contrast_lda import plots as sp
from bionav.experiments.contrast_lda.config import ContrastLdaConfig

#: Names ``data=`` accepts.
DATASETS = ("sim_natural", "sim_artificial", "csv")


def analyse(samples, *, sigma: float, n_resamples: int, rng: np.random.Generator, out_dir, plots_dir,
            title: str = "", plots: bool = True, on_features=None) -> dict:
    """Run the whole analysis on a sample set and write tables and plots.

    Parameters
    ----------
    samples : SampleSet
    sigma : float
        Receptor noise for J_sigma, counts.
    n_resamples : int
        Bootstrap resamples for the significance tables (0 skips them).
    rng : numpy.random.Generator
    out_dir, plots_dir : path-like
        Where tables and figures go.
    title : str
        Title for tables and figures.
    plots : bool
        Draw the figures.
    on_features : callable, optional
        ``on_features(results)`` with the per-feature LDA results, called
        before the (long) bootstrap, e.g. to log them at once.

    Returns
    -------
    dict
        Metrics: ``J``, ``J_sigma``, ``n_f`` keyed by feature, plus scalars.
    """
    from bionav.spectral import lda_analysis as la
    from bionav.spectral.csv_io import write_samples_csv

    out_dir, plots_dir = Path(out_dir), Path(plots_dir)
    results = la.analyse_features(samples, sigma=sigma)
    if on_features is not None:
        on_features(results)
    la.write_lda_table_csv(results, out_dir / "lda_table.csv")
    (out_dir / "lda_table.md").write_text(la.lda_table_markdown(results, title=title, sigma=sigma))
    write_samples_csv(samples, out_dir / "samples.csv")
    if n_resamples > 0:
        sig = la.bootstrap_significance(samples, results, sigma=sigma, n_resamples=n_resamples, rng=rng)
        (out_dir / "significance.md").write_text(la.significance_markdown(sig, title=title, n_resamples=n_resamples))
        for crit, s in sig.items():
            la.write_significance_csv(s, out_dir / f"significance_{crit}.csv")
    if plots:
        sp.plot_pairs(samples, results, plots_dir / "uv_g_uv_ir.png", names=["UV-G", "UV-IR"], title=title)
        sp.plot_pairs(samples, results, plots_dir / "pairs.png", title=title)
        sp.plot_projection_histograms(samples, results, plots_dir / "projection_histograms.png", title=title)
        sp.plot_criteria(results, plots_dir / "criteria.png", title=title)
    best = max(results, key=lambda n: results[n].J)
    return {
        "J": {n: r.J for n, r in results.items()},
        "J_sigma": {n: r.J_sigma for n, r in results.items()},
        "n_f": {n: r.n_f for n, r in results.items()},
        "n_sky": samples.n_sky,
        "n_objects": samples.n_objects,
        "best_feature_J": best,
        "sigma": float(sigma),
    }


SAMPLE_TOPIC = "/spectral5/samples"
SAMPLE_SCHEMA = {
    "type": "object",
    "title": "bionav.Spectral5Sample",
    "description": "One labelled data point of the five-channel sensor (mean counts).",
    "properties": {
        "class": {"type": "string", "enum": ["sky", "object"]},
        "kind": {"type": "string"}, "time": {"type": "string"},
        "uv": {"type": "number"}, "b": {"type": "number"}, "g": {"type": "number"},
        "r": {"type": "number"}, "ir": {"type": "number"},
    },
}

FEATURE_TOPIC = "/contrast_lda/features"
FEATURE_SCHEMA = {
    "type": "object",
    "title": "bionav.SpectralFeatureLda",
    "description": "Fisher LDA of one spectral feature: J, J_sigma (receptor noise) and the misclassified fraction n_f.",
    "properties": {"feature": {"type": "string"}, "J": {"type": "number"}, "J_sigma": {"type": "number"},
                   "n_f": {"type": "number"}},
}


def run(exp: ContrastLdaConfig, ctx) -> dict:
    """Run ``experiment=contrast_lda`` with the checked ``exp`` and the checked ``data`` node (``ctx.nodes``)."""
    data = ctx.nodes.get("data")
    if data is None:
        raise UserError("experiment=contrast_lda needs a data set: data=sim_natural, data=sim_artificial or "
                        "data=csv data.path=FILE.")
    samples = load_samples(data)
    for c, sky, k, t in zip(samples.counts, samples.is_sky, samples.kind, samples.time):
        ctx.log.write(SAMPLE_TOPIC, {"class": "sky" if sky else "object", "kind": str(k), "time": str(t),
                                     **{ch: float(v) for ch, v in zip(("uv", "b", "g", "r", "ir"), c)}},
                      schema_name="bionav.Spectral5Sample", schema=SAMPLE_SCHEMA)
    title = f"{samples.name}: {samples.n_objects} objects, {samples.n_sky} sky"

    def log_features(results) -> None:
        """Each feature's criteria as soon as known (the bootstrap that follows can take minutes)."""
        for name, r in results.items():
            ctx.log.write(FEATURE_TOPIC, {"feature": name, "J": r.J, "J_sigma": r.J_sigma, "n_f": r.n_f},
                          schema_name="bionav.SpectralFeatureLda", schema=FEATURE_SCHEMA)

    return analyse(samples, sigma=exp.sigma, n_resamples=exp.n_resamples,
                   rng=ctx.rng, out_dir=ctx.dir, plots_dir=ctx.plots, title=title,
                   plots=exp.plots, on_features=log_features)
