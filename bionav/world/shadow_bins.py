"""Hard shadows of the renderer (numba): shadow-caster bins per light and the occlusion test.

Each light gets a grid of bins over the directions (point lights: a cube map of
:data:`SHADOW_CUBE` cells per face side, seen from the light) or over the plane
orthogonal to the light (directional lights: :data:`SHADOW_BINS_SUN` squared
bins), listing the shadow-casting primitives whose bounding sphere touches the
bin (CSR arrays). :func:`_occluded` tests a ray towards one light against its
bin only. World frame ENU, metres.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from bionav.world.intersect import INF, _hit_prim

SHADOW_CUBE = 32
SHADOW_BINS_SUN = 128


@njit(cache=True)
def _sun_basis(sx, sy, sz):
    """Two unit vectors orthogonal to the sun direction ``(sx, sy, sz)``."""
    if abs(sz) < 0.9:
        ax, ay, az_ = 0.0, 0.0, 1.0
    else:
        ax, ay, az_ = 1.0, 0.0, 0.0
    e1x = ay * sz - az_ * sy
    e1y = az_ * sx - ax * sz
    e1z = ax * sy - ay * sx
    n = math.sqrt(e1x * e1x + e1y * e1y + e1z * e1z)
    e1x, e1y, e1z = e1x / n, e1y / n, e1z / n
    e2x = sy * e1z - sz * e1y
    e2y = sz * e1x - sx * e1z
    e2z = sx * e1y - sy * e1x
    return e1x, e1y, e1z, e2x, e2y, e2z


@njit(cache=True, inline="always")
def _cube_cell(wx, wy, wz):
    """Cube-map cell of a direction (not necessarily unit): ``face * G * G + row * G + col``."""
    ax = abs(wx)
    ay = abs(wy)
    az_ = abs(wz)
    if ax >= ay and ax >= az_:
        face = 0 if wx < 0 else 1
        m, a, b = ax, wy, wz
    elif ay >= az_:
        face = 2 if wy < 0 else 3
        m, a, b = ay, wx, wz
    else:
        face = 4 if wz < 0 else 5
        m, a, b = az_, wx, wy
    g = SHADOW_CUBE
    ia = int((a / m + 1.0) * 0.5 * g)
    ib = int((b / m + 1.0) * 0.5 * g)
    ia = min(max(ia, 0), g - 1)
    ib = min(max(ib, 0), g - 1)
    return face * g * g + ib * g + ia


@njit(cache=True)
def _cube_dir(face, ua, ub):
    """Unit direction of cube-map face coordinates ``ua, ub`` in [-1, 1]."""
    sgn = 1.0 if face % 2 == 1 else -1.0
    ax = face // 2
    if ax == 0:
        x, y, z = sgn, ua, ub
    elif ax == 1:
        x, y, z = ua, sgn, ub
    else:
        x, y, z = ua, ub, sgn
    n = math.sqrt(x * x + y * y + z * z)
    return x / n, y / n, z / n


@njit(cache=True)
def _cube_cells(g):
    """Unit directions ``(6 g g, 3)`` of the cube-map cell centres and their angular radii (radians)."""
    n_cube = 6 * g * g
    cell_dir = np.empty((n_cube, 3))
    cell_rad = np.empty(n_cube)
    for face in range(6):
        for ib in range(g):
            for ia in range(g):
                c = face * g * g + ib * g + ia
                ua = -1.0 + (ia + 0.5) * 2.0 / g
                ub = -1.0 + (ib + 0.5) * 2.0 / g
                x, y, z = _cube_dir(face, ua, ub)
                cell_dir[c, 0], cell_dir[c, 1], cell_dir[c, 2] = x, y, z
                r = 0.0
                for sa in (-1.0, 1.0):
                    for sb in (-1.0, 1.0):
                        x2, y2, z2 = _cube_dir(face, ua + sa / g, ub + sb / g)
                        r = max(r, math.acos(min(1.0, x * x2 + y * y2 + z * z2)))
                cell_rad[c] = r * 1.01 + 1e-9
    return cell_dir, cell_rad


@njit(cache=True)
def _sun_grid(light, spheres, casters, grid):
    """Fill ``grid`` (6,) of a directional light: the casters' projected extent in ``SHADOW_BINS_SUN`` bins a side."""
    e1x, e1y, e1z, e2x, e2y, e2z = _sun_basis(light[1], light[2], light[3])
    lo_a = INF
    hi_a = -INF
    lo_b = INF
    hi_b = -INF
    for q in range(casters.shape[0]):
        p = casters[q]
        pa = spheres[p, 0] * e1x + spheres[p, 1] * e1y + spheres[p, 2] * e1z
        pb = spheres[p, 0] * e2x + spheres[p, 1] * e2y + spheres[p, 2] * e2z
        lo_a = min(lo_a, pa - spheres[p, 3])
        hi_a = max(hi_a, pa + spheres[p, 3])
        lo_b = min(lo_b, pb - spheres[p, 3])
        hi_b = max(hi_b, pb + spheres[p, 3])
    if lo_a > hi_a:
        lo_a, hi_a, lo_b, hi_b = 0.0, 1.0, 0.0, 1.0
    grid[0] = lo_a
    grid[1] = max((hi_a - lo_a) / SHADOW_BINS_SUN, 1e-9) * (1 + 1e-9)
    grid[2] = SHADOW_BINS_SUN
    grid[3] = lo_b
    grid[4] = max((hi_b - lo_b) / SHADOW_BINS_SUN, 1e-9) * (1 + 1e-9)
    grid[5] = SHADOW_BINS_SUN


@njit(cache=True)
def _offsets_from_counts(counts):
    """Counts per light and bin to CSR offsets, in place; returns the largest total over the lights."""
    total = 0
    for k in range(counts.shape[0]):
        acc = 0
        for i in range(counts.shape[1]):
            c = counts[k, i]
            counts[k, i] = acc
            acc += c
        total = max(total, acc)
    return total


@njit(cache=True, inline="always")
def _enter(k, c, p, sweep, counts, items, fill):
    """Count caster ``p`` in bin ``c`` of light ``k`` (sweep 0) or list it there (sweep 1)."""
    if sweep == 0:
        counts[k, c] += 1
    else:
        items[k, fill[k, c]] = p
        fill[k, c] += 1


@njit(cache=True)
def _bin_point_light(k, p, light, spheres, cell_dir, cell_rad, sweep, counts, items, fill):
    """Enter caster ``p`` in every cube cell of point light ``k`` whose cone meets its bounding sphere's."""
    vx = spheres[p, 0] - light[1]
    vy = spheres[p, 1] - light[2]
    vz = spheres[p, 2] - light[3]
    d = math.sqrt(vx * vx + vy * vy + vz * vz)
    rad = spheres[p, 3]
    everywhere = d <= rad
    half = 0.0 if everywhere else math.asin(rad / d)
    for c in range(cell_dir.shape[0]):
        if not everywhere:
            cosang = (cell_dir[c, 0] * vx + cell_dir[c, 1] * vy + cell_dir[c, 2] * vz) / d
            if math.acos(max(-1.0, min(1.0, cosang))) > cell_rad[c] + half:
                continue
        _enter(k, c, p, sweep, counts, items, fill)


@njit(cache=True)
def _bin_sun(k, p, light, spheres, grid, sweep, counts, items, fill):
    """Enter caster ``p`` in every bin of directional light ``k`` its bounding sphere's projection covers."""
    e1x, e1y, e1z, e2x, e2y, e2z = _sun_basis(light[1], light[2], light[3])
    pa = spheres[p, 0] * e1x + spheres[p, 1] * e1y + spheres[p, 2] * e1z
    pb = spheres[p, 0] * e2x + spheres[p, 1] * e2y + spheres[p, 2] * e2z
    na = int(grid[2])
    nb = int(grid[5])
    a0 = max(int(math.floor((pa - spheres[p, 3] - grid[0]) / grid[1])), 0)
    a1 = min(int(math.floor((pa + spheres[p, 3] - grid[0]) / grid[1])), na - 1)
    b0 = max(int(math.floor((pb - spheres[p, 3] - grid[3]) / grid[4])), 0)
    b1 = min(int(math.floor((pb + spheres[p, 3] - grid[3]) / grid[4])), nb - 1)
    for bb in range(b0, b1 + 1):
        for aa in range(a0, a1 + 1):
            _enter(k, bb * na + aa, p, sweep, counts, items, fill)


@njit(cache=True)
def build_shadow_bins(light_params, spheres, casters):
    """Per-light bins listing the casters that can block a shadow ray through each bin.

    Point lights bin the direction from the light into a cube map of
    ``6 x G x G`` cells; a caster enters every cell whose cone of directions
    meets the cone around its bounding sphere. Directional lights bin the
    projection of the point onto the plane orthogonal to the light direction.
    Two sweeps over the casters: the first counts per bin, the second lists.

    Returns
    -------
    grids : ndarray (L, 6)
        Directional lights: ``a_origin, a_step, n_a, b_origin, b_step, n_b``.
    starts : ndarray (L, n_bins_max + 1) int
        CSR offsets into ``items`` per light and bin.
    items : ndarray (L, total) int
        Unified primitive indices.
    """
    nl = light_params.shape[0]
    g = SHADOW_CUBE
    nbmax = max(6 * g * g, SHADOW_BINS_SUN * SHADOW_BINS_SUN)
    cell_dir, cell_rad = _cube_cells(g)  # the same for every point light
    grids = np.zeros((nl, 6))
    for k in range(nl):
        if light_params[k, 0] > 0.5:
            _sun_grid(light_params[k], spheres, casters, grids[k])
    counts = np.zeros((nl, nbmax + 1), np.int64)
    items = np.empty((nl, 1), np.int64)
    fill = np.zeros((nl, nbmax + 1), np.int64)
    for sweep in range(2):
        if sweep == 1:
            total = _offsets_from_counts(counts)
            items = np.full((nl, max(total, 1)), -1, np.int64)
            fill = counts.copy()
        for k in range(nl):
            for q in range(casters.shape[0]):
                p = casters[q]
                if light_params[k, 0] < 0.5:
                    _bin_point_light(k, p, light_params[k], spheres, cell_dir, cell_rad, sweep, counts, items, fill)
                else:
                    _bin_sun(k, p, light_params[k], spheres, grids[k], sweep, counts, items, fill)
    return grids, counts, items


@njit(cache=True, inline="always")
def _occluded(k, ox, oy, oz, dx, dy, dz, tmax, lights, grids, starts, items, prim_kind, prim_idx, spheres,
              boxes, frusta, ells):
    """True if a shadow-casting primitive lies on the ray (towards light ``k``) before ``tmax``."""
    if lights[k, 0] < 0.5:
        cell = _cube_cell(-dx, -dy, -dz)  # direction from the light to the point
    else:
        na = int(grids[k, 2])
        nb = int(grids[k, 5])
        e1x, e1y, e1z, e2x, e2y, e2z = _sun_basis(lights[k, 1], lights[k, 2], lights[k, 3])
        ba = int(math.floor((ox * e1x + oy * e1y + oz * e1z - grids[k, 0]) / grids[k, 1]))
        bb = int(math.floor((ox * e2x + oy * e2y + oz * e2z - grids[k, 3]) / grids[k, 4]))
        if ba < 0 or ba >= na or bb < 0 or bb >= nb:
            return False
        cell = bb * na + ba
    for q in range(starts[k, cell], starts[k, cell + 1]):
        p = items[k, q]
        cx = spheres[p, 0] - ox
        cy = spheres[p, 1] - oy
        cz = spheres[p, 2] - oz
        rad = spheres[p, 3]
        s = cx * dx + cy * dy + cz * dz
        if s < -rad or s > tmax + rad:
            continue
        if cx * cx + cy * cy + cz * cz - s * s > rad * rad:
            continue
        t, _ = _hit_prim(ox, oy, oz, dx, dy, dz, prim_kind[p], prim_idx[p], boxes, frusta, ells)
        if t < tmax:
            return True
    return False

