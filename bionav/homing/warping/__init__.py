"""The warping family of holistic homing methods as plain functions on arrays.

* :func:`warping1d` - 1D warping of horizon strips (Franz et al. 1998).
* :func:`warping2d` - 2D-warping under the equal-distance assumption (Möller 2009).
* :func:`minwarping` - min-warping (Möller, Krzykawski & Gerstmayr 2010).

Per-image work: :func:`resize_panorama`, :func:`butterworth_lowpass`,
:func:`scale_plane_stack` (2D methods) and :func:`horizon_strip` (1D).
Conventions: :mod:`bionav.homing.warping.search`.
"""

from bionav.homing.warping.preprocess import butterworth_lowpass, horizon_strip, resize_panorama
from bionav.homing.warping.scaleplanes import (
    default_scales,
    default_thresholds,
    edge_filter,
    magnify_vertical,
    scale_plane_stack,
)
from bionav.homing.warping.search import (
    WarpingResult,
    minwarping,
    minwarping_scores,
    warping2d,
    warping2d_scores,
)
from bionav.homing.warping.warping1d import warping1d, warping1d_scores

__all__ = [
    "WarpingResult",
    "butterworth_lowpass",
    "default_scales",
    "default_thresholds",
    "edge_filter",
    "horizon_strip",
    "magnify_vertical",
    "minwarping",
    "minwarping_scores",
    "resize_panorama",
    "scale_plane_stack",
    "warping1d",
    "warping1d_scores",
    "warping2d",
    "warping2d_scores",
]
