"""Image-similarity measures for the stability of channels and contrasts over time (thesis 6.4.2).

Eqs. 6.1-6.7 compare an input ``A`` (the first scan of the day) with ``B`` (a
later scan) — a single-channel image or a dual-channel contrast image (the
difference of two log channels), or their sky/object separation images.
"""

from __future__ import annotations

import numpy as np

#: Names of the seven measures, in the thesis' order (eqs. 6.1-6.7).
MEASURES = ("MSE", "RMSD", "logNRMSD", "PSNR", "CorrCoeff", "logMSEstd", "logMSEvar")


def stability_measures(a, b) -> dict[str, float]:
    """The seven measures of thesis eqs. 6.1-6.7 between two images of equal shape.

    Parameters
    ----------
    a : array_like
        Reference image ``A`` (any shape), e.g. counts or count differences.
    b : array_like
        Compared image ``B``, same shape.

    Returns
    -------
    dict
        ``MSE = mean((A - B)^2)`` (6.1); ``RMSD = sqrt(MSE)`` (6.2);
        ``logNRMSD = log10(RMSD / (max A - min A))`` (6.3);
        ``PSNR = 10 log10(max(A)^2 / MSE)`` (6.4);
        ``CorrCoeff``: Pearson's correlation (6.5; the thesis prints the
        product of the variances in the denominator, which is not scale
        invariant; the square root of it, as here, is the correlation
        coefficient the name refers to);
        ``logMSEstd = log10(MSE / sqrt(VAR(A) VAR(B)))`` (6.6);
        ``logMSEvar = log10(MSE / VAR(A))`` (6.7).
        Logarithms of zero give ``-inf``, divisions by a zero variance or
        range ``nan``/``inf`` (numpy semantics, no warnings).
    """
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    if a.shape != b.shape:
        raise ValueError(f"images differ in shape: {a.shape} vs {b.shape}")
    with np.errstate(divide="ignore", invalid="ignore"):
        mse = float(np.mean((a - b) ** 2))
        rmsd = float(np.sqrt(mse))
        var_a, var_b = float(np.var(a)), float(np.var(b))
        cov = float(np.mean((a - a.mean()) * (b - b.mean())))
        return {
            "MSE": mse,
            "RMSD": rmsd,
            "logNRMSD": float(np.log10(np.float64(rmsd) / (a.max() - a.min()))),
            "PSNR": float(10 * np.log10(np.float64(a.max()) ** 2 / mse)),
            "CorrCoeff": float(np.float64(cov) / np.sqrt(var_a * var_b)),
            "logMSEstd": float(np.log10(np.float64(mse) / np.sqrt(var_a * var_b))),
            "logMSEvar": float(np.log10(np.float64(mse) / var_a)),
        }
