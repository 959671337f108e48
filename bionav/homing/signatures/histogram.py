"""Ring-wise intensity histograms and entropies, [hist] and [ent] (thesis eqs. 3.53-3.54).

Both are rotation invariant (a column roll does not change a ring's pixel values).

Choices the thesis leaves open (documented here):

* Bins: ``B`` equal bins over an intensity range ``[lo, hi]``: bin ``b`` holds
  ``lo + b (hi - lo) / B <= I < lo + (b + 1) (hi - lo) / B``, the last bin
  includes ``hi``, values outside fall into the end bins. The range is either
  fixed (``value_range=(0, 1)``, bionav's image range, so all images share
  their bins) or each image's own ``[min, max]`` (``value_range=None``). The
  latter keeps the histogram informative after preprocessing that compresses
  the range (an edge-filtered, low-passed panorama may lie entirely in
  ``[0, 0.02]``); a constant image puts every pixel into bin 0.
* [hist] holds *relative* frequencies (counts divided by the ring's pixel
  count) instead of the raw counts of eq. 3.53, so that rings of unequal row
  counts (``H`` not a multiple of ``R``) and different image sizes weigh alike.
  For one image size and ring count this only rescales the potential.
* [ent] uses these relative frequencies ``p_b`` in eq. 3.54,
  ``S = -sum_b p_b ln p_b`` with ``0 ln 0 = 0`` (the Shannon entropy in nats;
  eq. 3.54 printed with counts ``h_b`` is not an entropy).
"""

from __future__ import annotations

import numpy as np

from bionav.homing.signatures.rings import ring_edges, ring_index


def ring_histogram(
    image: np.ndarray, *, rings: int = 1, bins: int = 16, value_range: tuple[float, float] | None = (0.0, 1.0)
) -> np.ndarray:
    """Relative intensity histogram of each ring, [hist].

    Parameters
    ----------
    image : ndarray, shape (H, W)
        Unfolded panorama, intensities nominally in ``[0, 1]``.
    rings : int
        Number of rings ``R``.
    bins : int
        Number of bins ``B``.
    value_range : (float, float) or None
        Intensity range ``(lo, hi)`` the bins span; ``None`` = the image's own ``(min, max)``.

    Returns
    -------
    ndarray, shape (R, B), float64
        Fraction of ring ``k``'s pixels in bin ``b``; each row sums to 1.
    """
    img = np.asarray(image, dtype=np.float64)
    if img.ndim != 2:
        raise ValueError(f"expected a 2-D (H, W) panorama, got shape {img.shape}")
    bins = int(bins)
    if bins < 1:
        raise ValueError(f"bins must be >= 1, got {bins}")
    h, w = img.shape
    lo, hi = (float(img.min()), float(img.max())) if value_range is None else map(float, value_range)
    if not hi >= lo:
        raise ValueError(f"value_range must have lo <= hi, got {value_range}")
    scale = bins / (hi - lo) if hi > lo else 0.0
    b = np.clip(np.floor((img - lo) * scale), 0, bins - 1).astype(np.int64)
    ring = np.broadcast_to(ring_index(h, rings)[:, None], (h, w))
    counts = np.bincount((ring * bins + b).ravel(), minlength=rings * bins).reshape(rings, bins)
    return counts / (np.diff(ring_edges(h, rings)) * w)[:, None]


def ring_entropy(
    image: np.ndarray, *, rings: int = 1, bins: int = 16, value_range: tuple[float, float] | None = (0.0, 1.0)
) -> np.ndarray:
    """Shannon entropy (nats) of each ring's intensity histogram, [ent].

    Parameters
    ----------
    image : ndarray, shape (H, W)
    rings : int
    bins : int
    value_range : (float, float) or None
        As in :func:`ring_histogram`.

    Returns
    -------
    ndarray, shape (R,), float64
        ``-sum_b p_b ln p_b`` with ``p`` from :func:`ring_histogram`; between 0
        (one bin) and ``ln B`` (uniform).
    """
    p = ring_histogram(image, rings=rings, bins=bins, value_range=value_range)
    logp = np.log(p, out=np.zeros_like(p), where=p > 0)
    return -(p * logp).sum(axis=1)
