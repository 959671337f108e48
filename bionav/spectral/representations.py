"""Images a homing method sees, made from five-channel panoramas (thesis 6.5, beyond it).

Representations of a five-channel count image ``(H, W, 5)``:

* a single channel ``"UV"`` .. ``"IR"``: ``counts / 4095``;
* a dual-channel contrast ``"UV-IR"`` etc.: ``0.5 + (X - Y) / 2048`` clipped to
  [0, 1] (a fixed map, so an illumination change that shifts all log channels
  equally leaves the image unchanged);
* a binary skyline ``"skyline:<feature>"``: 1 where the feature's linear
  discriminant (sky = class 1, e.g. the ``J_sigma`` line learned on natural
  samples) says *object*, 0 where it says *sky*.

All are float32 in [0, 1], the input contract of bionav's homing methods.
"""

from __future__ import annotations

import numpy as np

from bionav.light.bands import CHANNELS, dual_contrasts, feature_subsets
from bionav.spectral.scan import sky_mask

SKYLINE_PREFIX = "skyline:"


def representation_names() -> list[str]:
    """Every representation: 5 channels, 10 contrasts, 16 skylines."""
    return list(CHANNELS) + list(dual_contrasts()) + [SKYLINE_PREFIX + f for f in feature_subsets()]


def check_representation(name: str) -> str:
    """Return ``name`` if it is a known representation, else raise ``ValueError`` listing them."""
    if name not in representation_names():
        raise ValueError(f"unknown representation {name!r}; choose from {', '.join(representation_names())}")
    return name


def representation_image(counts, name: str, *, discriminants: dict | None = None,
                         full_scale: float = 4095.0, threshold: str = "learned") -> np.ndarray:
    """One representation of a five-channel count image.

    Parameters
    ----------
    counts : array_like, shape (..., 5)
        Channel counts UV, B, G, R, IR (log signals).
    name : str
        ``"UV"``, ``"UV-IR"``, ``"skyline:UV-IR"``, ... (see module docstring).
    discriminants : dict, optional
        Feature -> fitted :class:`bionav.stats.LinearDiscriminant`; needed for skylines.
    full_scale : float
        ADC full scale.
    threshold : {"learned", "local"}
        Class border of a skyline (:func:`bionav.spectral.scan.image_discriminant`); with
        ``"local"`` every image (the last three axes ``(H, W, 5)`` of ``counts``)
        gets its own threshold.

    Returns
    -------
    ndarray, float32, shape (...)
    """
    c = np.asarray(counts, dtype=float)
    check_representation(name)
    if name in CHANNELS:
        return np.clip(c[..., CHANNELS.index(name)] / full_scale, 0, 1).astype(np.float32)
    if not name.startswith(SKYLINE_PREFIX):
        i, j = dual_contrasts()[name]
        return np.clip(0.5 + (c[..., i] - c[..., j]) / 2048.0, 0, 1).astype(np.float32)
    feature = name[len(SKYLINE_PREFIX):]
    if not discriminants or feature not in discriminants:
        raise ValueError(f"representation {name!r} needs a discriminant for feature {feature!r}")
    d = discriminants[feature]
    if threshold == "local" and c.ndim > 3:  # a stack of images: each its own threshold
        flat = c.reshape((-1,) + c.shape[-3:])
        sky = np.stack([sky_mask(im, feature, d, threshold=threshold) for im in flat]).reshape(c.shape[:-1])
    else:
        sky = sky_mask(c, feature, d, threshold=threshold)
    return (~sky).astype(np.float32)
