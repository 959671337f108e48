"""The warping family of holistic homing methods as plain functions on arrays.

* :func:`warping1d` - 1D warping of horizon strips (Franz et al. 1998).
* :func:`warping2d` - 2D-warping under the equal-distance assumption (Möller 2009).
* :func:`minwarping` - min-warping (Möller, Krzykawski & Gerstmayr 2010).

Per-image work: :func:`scale_plane_stack` (2D methods), after
:func:`bionav.homing.imageops.resize_panorama`,
:func:`~bionav.homing.imageops.butterworth_lowpass` and (1D)
:func:`~bionav.homing.imageops.horizon_strip`.
Conventions: :mod:`bionav.homing.warping.search`.
"""

from bionav.homing.warping.scaleplanes import (
    default_scales,
    default_thresholds,
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
    "default_scales",
    "default_thresholds",
    "magnify_vertical",
    "minwarping",
    "minwarping_scores",
    "scale_plane_stack",
    "warping1d",
    "warping1d_scores",
    "warping2d",
    "warping2d_scores",
]
