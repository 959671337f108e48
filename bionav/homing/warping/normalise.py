"""The last step of the 8-bit column distances: one plane's diagonal sums to NSAD bytes.

Shared by the scalar kernel (:mod:`bionav.homing.warping.distance`) and the explicit-vector
kernel (:mod:`bionav.homing.warping.vkernels`), which must agree bit for bit; it lives apart
from both so that neither imports the other.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(nogil=True, fastmath=True, cache=True, inline="always")
def _normalise_plane(acc, na, cn2, qf, t, out_k, step):
    """One plane's diagonal sums ``acc`` (W, W) to 8-bit NSAD, de-interleaved into
    ``out_k[d, i % step, i // step]``; ``t`` (W,) is scratch."""
    width = na.shape[0]
    n = width // step
    for d in range(width):
        nb = cn2[d:d + width]
        ac = acc[d]
        for i in range(width):
            # the norms' sum in 32 bits (AVX2 has no packed 64-bit integer to float
            # conversion, so an int64 sum kept this loop scalar there); a zero sum
            # means two zero columns, whose distance sum is 0 as well: dividing it by 1
            # gives the old 0.5 without a branch
            den = np.float32(max(np.int32(na[i] + nb[i]), np.int32(1)))
            t[i] = np.uint8(np.float32(ac[i]) * qf / den + np.float32(0.5))
        o = out_k[d]
        if step == 1:
            o0 = o[0]
            for m in range(n):
                o0[m] = t[m]
        elif step == 3:  # constant stride, one phase at a time: byte shuffles
            for rr in range(3):
                orr = o[rr]
                for m in range(n):
                    orr[m] = t[3 * m + rr]
        else:
            for rr in range(step):
                orr = o[rr]
                for m in range(n):
                    orr[m] = t[m * step + rr]
