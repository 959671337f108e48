"""Ring segmentation of panoramic images (thesis section 3.5, fig. 3.5)."""

from __future__ import annotations

import numpy as np

from bionav.errors import UserError


def ring_edges(height: int, rings: int) -> np.ndarray:
    """Row boundaries of ``rings`` equal-width rings of an unfolded panorama.

    Concentric rings of equal width on the raw mirror image are equal bands of
    rows in the unfolded image (thesis 3.5). Ring ``k`` holds rows
    ``edges[k] <= r < edges[k + 1]``; ring 0 is the top band (the outer rim of
    the mirror image, highest elevation). When ``height`` is not a multiple of
    ``rings`` the bands differ by at most one row (``edges[k] = floor(k * H / R)``).

    Parameters
    ----------
    height : int
        Number of image rows ``H``.
    rings : int
        Number of rings ``R``, ``1 <= R <= H``.

    Returns
    -------
    ndarray of int, shape (R + 1,)
        ``edges[0] = 0``, ``edges[R] = H``, strictly increasing.

    Raises
    ------
    UserError
        If ``rings`` is not between 1 and ``height``.
    """
    height = int(height)
    rings = int(rings)
    if not 1 <= rings <= height:
        raise UserError(
            f"signature.rings={rings} does not fit an image of {height} rows: a ring is at least one "
            f"row of the unfolded panorama. Choose signature.rings between 1 and {height}, or use a "
            f"larger db.image_size."
        )
    return (np.arange(rings + 1) * height) // rings


def ring_index(height: int, rings: int) -> np.ndarray:
    """Ring number of every row, shape ``(H,)`` (see :func:`ring_edges`)."""
    edges = ring_edges(height, rings)
    return np.repeat(np.arange(rings), np.diff(edges))
