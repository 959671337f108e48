"""Ring-wise centre of gravity of the panoramic mirror image, [cog] and [cog_l].

Thesis eqs. 3.46-3.48: the centre of gravity ``s = (i_s, j_s)`` is computed on
the *raw* panoramic (mirror) image ``P``, ring by ring, and [cog_l] is its
length ``|s|``. Coordinates are measured from the mirror centre (the optical
axis), with the outer mirror radius as unit; only then is ``|s|`` invariant
under a rotation of the robot, as the thesis classifies [cog_l] (3.5.2). [cog]
itself rotates with the robot and is not rotation invariant.

Two inputs are supported:

* :func:`raw_ring_center_of_gravity` -- a real raw mirror image
  (:class:`MirrorImage`: pixels, mirror centre, inner and outer radius).
* :func:`ring_center_of_gravity` -- only the unfolded panorama is available.
  It is mapped back onto a *synthetic mirror image* with an equiangular polar
  mapping: row ``r`` of an ``H``-row panorama lies on the circle of radius
  ``rho_r = 1 - (r + 0.5) (1 - rho_in) / H`` (top row at the outer rim, bottom
  row at the inner radius ``rho_in``, as bionav's unfolding maps
  ``db.unfold.outer_radius`` to the top row), and column ``j`` at polar angle
  ``theta_j = 2 pi j / W`` counter-clockwise from the robot's heading
  (``x`` along the heading, ``y`` to the left). Each unfolded pixel stands for
  an annular sector of area proportional to ``rho_r``; the centre of gravity is
  the area- and intensity-weighted mean of the sector centres
  ``rho_r (cos theta_j, sin theta_j)``. This is the continuum limit of
  rendering the synthetic mirror image and applying eqs. 3.46-3.47, without
  resampling artefacts, and a column roll by ``m`` rotates ``s`` by exactly
  ``2 pi m / W``.

Rings are ``R`` equal-width annuli between the inner and the outer radius,
ring 0 outermost -- the same as the row bands of
:func:`~bionav.homing.signatures.rings.ring_edges`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.homing.signatures.rings import ring_edges


@dataclass(frozen=True)
class MirrorImage:
    """A raw omnidirectional camera frame with its mirror geometry.

    Parameters
    ----------
    image : ndarray, shape (h, w)
        Raw grey-value frame.
    center : tuple of float, optional
        Mirror centre ``(cx, cy)`` in pixels (column, row); default the frame centre.
    inner_radius, outer_radius : float, optional
        Radii in pixels of the used annulus; default ``outer = min(h, w) / 2`` and
        ``inner = inner_fraction * outer`` of the caller.
    """

    image: np.ndarray
    center: tuple[float, float] | None = None
    inner_radius: float | None = None
    outer_radius: float | None = None


def ring_center_of_gravity(image: np.ndarray, *, rings: int = 1, inner_radius: float = 0.2) -> np.ndarray:
    """Centre of gravity per ring of the synthetic mirror image of an unfolded panorama.

    See the module docstring for the mapping (equiangular polar reprojection,
    top row at the outer rim).

    Parameters
    ----------
    image : ndarray, shape (H, W)
        Canonical unfolded panorama (column 0 along the heading, azimuth CCW).
    rings : int
        Number of rings ``R`` (equal row bands).
    inner_radius : float
        Inner radius of the synthetic mirror image as a fraction of its outer
        radius, ``0 <= inner_radius < 1``.

    Returns
    -------
    ndarray, shape (R, 2), float64
        ``(i_s, j_s)`` of every ring in units of the outer radius; ``i`` along the
        robot's heading, ``j`` to its left. A ring with zero total intensity gives ``(0, 0)``.
    """
    img = np.asarray(image, dtype=np.float64)
    if img.ndim != 2:
        raise ValueError(f"expected a 2-D (H, W) panorama, got shape {img.shape}")
    if not 0.0 <= inner_radius < 1.0:
        raise ValueError(f"inner_radius must be in [0, 1), got {inner_radius}")
    h, w = img.shape
    rho = 1.0 - (np.arange(h) + 0.5) * (1.0 - inner_radius) / h
    theta = 2.0 * np.pi * np.arange(w) / w
    weighted = img * rho[:, None]  # intensity times sector area
    edges = ring_edges(h, rings)
    mass = np.add.reduceat(weighted.sum(axis=1), edges[:-1])
    mx = np.add.reduceat(rho * (weighted @ np.cos(theta)), edges[:-1])
    my = np.add.reduceat(rho * (weighted @ np.sin(theta)), edges[:-1])
    out = np.zeros((rings, 2))
    ok = mass != 0
    out[ok, 0] = mx[ok] / mass[ok]
    out[ok, 1] = my[ok] / mass[ok]
    return out


def raw_ring_center_of_gravity(
    raw: MirrorImage | np.ndarray, *, rings: int = 1, inner_radius: float = 0.2
) -> np.ndarray:
    """Centre of gravity per ring of a raw mirror image, [cog] (thesis eqs. 3.46-3.47).

    Parameters
    ----------
    raw : MirrorImage or ndarray, shape (h, w)
        Raw frame; a bare array has its mirror centre at the frame centre and
        outer radius ``min(h, w) / 2``.
    rings : int
        Number of equal-width annuli ``R`` between inner and outer radius, ring 0 outermost.
    inner_radius : float
        Inner radius as a fraction of the outer radius, used when ``raw`` does
        not give one.

    Returns
    -------
    ndarray, shape (R, 2), float64
        ``(i_s, j_s)`` per ring relative to the mirror centre, in units of the
        outer radius, ``i`` to the right (column) and ``j`` up (against the row
        index). Pixels outside the annulus are ignored; an empty or black ring gives ``(0, 0)``.
    """
    if not isinstance(raw, MirrorImage):
        raw = MirrorImage(np.asarray(raw))
    img = np.asarray(raw.image, dtype=np.float64)
    if img.ndim != 2:
        raise ValueError(f"expected a 2-D raw mirror image, got shape {img.shape}")
    h, w = img.shape
    cx, cy = raw.center if raw.center is not None else ((w - 1) / 2.0, (h - 1) / 2.0)
    outer = float(raw.outer_radius) if raw.outer_radius is not None else min(h, w) / 2.0
    inner = float(raw.inner_radius) if raw.inner_radius is not None else inner_radius * outer
    if not 0.0 <= inner < outer:
        raise ValueError(f"need 0 <= inner radius < outer radius, got {inner}, {outer}")
    rows, cols = np.mgrid[0:h, 0:w]
    x = (cols - cx) / outer
    y = (cy - rows) / outer
    rho = np.hypot(x, y)
    width = (1.0 - inner / outer) / rings
    inside = (rho >= inner / outer) & (rho <= 1.0)
    ring = np.minimum(((1.0 - rho[inside]) / width).astype(np.int64), rings - 1)
    vals = img[inside]
    mass = np.bincount(ring, weights=vals, minlength=rings)
    mx = np.bincount(ring, weights=vals * x[inside], minlength=rings)
    my = np.bincount(ring, weights=vals * y[inside], minlength=rings)
    out = np.zeros((rings, 2))
    ok = mass != 0
    out[ok, 0] = mx[ok] / mass[ok]
    out[ok, 1] = my[ok] / mass[ok]
    return out


def render_synthetic_mirror_image(
    image: np.ndarray, *, size: int, inner_radius: float = 0.2
) -> MirrorImage:
    """Render the synthetic mirror image of an unfolded panorama (nearest neighbour).

    The inverse of the mapping of :func:`ring_center_of_gravity`: useful to look
    at, and to check that the continuum formula matches eqs. 3.46-3.47 on pixels.

    Parameters
    ----------
    image : ndarray, shape (H, W)
        Canonical unfolded panorama.
    size : int
        Side of the square output frame in pixels; the outer radius is ``size / 2``.
    inner_radius : float
        Inner radius as a fraction of the outer radius.

    Returns
    -------
    MirrorImage
        Frame with zeros outside the annulus, centre at the frame centre, radii in pixels.
    """
    img = np.asarray(image, dtype=np.float64)
    h, w = img.shape
    c = (size - 1) / 2.0
    outer = size / 2.0
    rows, cols = np.mgrid[0:size, 0:size]
    x = (cols - c) / outer
    y = (c - rows) / outer
    rho = np.hypot(x, y)
    r = np.floor((1.0 - rho) * h / (1.0 - inner_radius)).astype(np.int64)
    j = np.floor(np.mod(np.arctan2(y, x), 2.0 * np.pi) * w / (2.0 * np.pi) + 0.5).astype(np.int64) % w
    inside = (r >= 0) & (r < h)
    out = np.zeros((size, size))
    out[inside] = img[r[inside], j[inside]]
    return MirrorImage(out, center=(c, c), inner_radius=inner_radius * outer, outer_radius=outer)


def cog_length(cog: np.ndarray) -> np.ndarray:
    """Length ``|s|`` of every ring's centre of gravity, [cog_l] (thesis eq. 3.48).

    Parameters
    ----------
    cog : ndarray, shape (R, 2)

    Returns
    -------
    ndarray, shape (R,)
    """
    return np.hypot(cog[:, 0], cog[:, 1])
