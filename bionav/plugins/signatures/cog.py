"""Centre-of-gravity signatures [cog] and [cog_l] (thesis eqs. 3.46-3.48).

Computed ring by ring on the raw panoramic mirror image, as the thesis says.
When no raw image is given (``raw=None``, the usual case for databases of
unfolded images and always for the matched-filter's predicted images), the
unfolded image is reprojected onto a *synthetic mirror image* by an
equiangular polar mapping (top row at the outer rim, azimuth counter-clockwise
from the heading, bottom row at ``inner_radius`` of the outer radius); see
:mod:`bionav.homing.signatures.cog` for the exact mapping.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.homing.signatures.base import Signature
from bionav.validation import bounded


@dataclass
class CogConfig:
    """Parameters of the centre-of-gravity signatures.

    rings : number of concentric rings ``R`` of the mirror image (thesis sweep:
        1, 5, 10, 15, 20, 25).
    inner_radius : inner radius of the mirror annulus as a fraction of the outer
        radius, for the synthetic mirror image and for raw frames that do not
        state it.
    """

    rings: int = bounded(20, ge=1, le=1000)
    inner_radius: float = bounded(0.2, ge=0.0, lt=1.0)


def _cog(signature: Signature, image, raw) -> np.ndarray:
    from bionav.homing.signatures.cog import raw_ring_center_of_gravity, ring_center_of_gravity

    cfg = signature.config
    if raw is not None:
        return raw_ring_center_of_gravity(raw, rings=cfg.rings, inner_radius=cfg.inner_radius)
    return ring_center_of_gravity(image, rings=cfg.rings, inner_radius=cfg.inner_radius)


class Cog(Signature):
    """[cog]: centre of gravity ``(i_s, j_s)`` of every ring; shape ``(2 R,)``.

    Uses ``raw`` (an ndarray or :class:`bionav.homing.signatures.cog.MirrorImage`)
    when given, else the synthetic mirror image of the unfolded panorama.
    Not rotation invariant (``s`` rotates with the robot).
    """

    Config = CogConfig
    name = "cog"
    rotation_invariant = False
    uses_raw = True

    def compute(self, image, *, raw=None) -> np.ndarray:
        return _cog(self, image, raw).ravel()


class CogL(Signature):
    """[cog_l]: length ``|s|`` of every ring's centre of gravity; shape ``(R,)``.

    Same raw/synthetic input as :class:`Cog`; rotation invariant because ``s`` is
    measured from the mirror centre.
    """

    Config = CogConfig
    name = "cog_l"
    rotation_invariant = True
    uses_raw = True

    def compute(self, image, *, raw=None) -> np.ndarray:
        from bionav.homing.signatures.cog import cog_length

        return cog_length(_cog(self, image, raw))
