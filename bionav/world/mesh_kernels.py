"""Numba kernels for ray casting triangle meshes through a uniform xy grid.

Acceleration structure: a uniform grid over the mesh's ``x, y`` bounding box
(cells of equal size, about :data:`TRIANGLES_PER_CELL` triangles each on
average). Every cell lists the triangles whose ``x, y`` bounding box overlaps
it and stores the ``z`` range of those triangles. A ray walks the cells it
crosses in order (Amanatides & Woo 1987, "A fast voxel traversal algorithm for
ray tracing", Eurographics) and tests only the triangles of cells whose ``z``
range it passes through (Möller & Trumbore 1997, "Fast, minimum storage
ray-triangle intersection", J. Graphics Tools, doi:10.1080/10867651.1997.10487468).
Worlds of habitats are flat (wide in x, y, shallow in z), so a 2-D grid with
per-cell ``z`` ranges prunes as well as a 3-D grid at a fraction of the memory.

:func:`trace_reference` is the brute-force NumPy version the kernels are
tested against.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

INF = 1e30
#: Average triangles per grid cell the grid is sized for.
TRIANGLES_PER_CELL = 2.0


@njit(cache=True)
def _fill_grid(tri, x0, y0, cell, nx, ny, counts_only, starts, items, zlo, zhi):
    n = tri.shape[0]
    fill = np.zeros(nx * ny, np.int64)
    for i in range(n):
        xmin = min(tri[i, 0, 0], min(tri[i, 1, 0], tri[i, 2, 0]))
        xmax = max(tri[i, 0, 0], max(tri[i, 1, 0], tri[i, 2, 0]))
        ymin = min(tri[i, 0, 1], min(tri[i, 1, 1], tri[i, 2, 1]))
        ymax = max(tri[i, 0, 1], max(tri[i, 1, 1], tri[i, 2, 1]))
        zmin = min(tri[i, 0, 2], min(tri[i, 1, 2], tri[i, 2, 2]))
        zmax = max(tri[i, 0, 2], max(tri[i, 1, 2], tri[i, 2, 2]))
        i0 = min(max(int((xmin - x0) / cell), 0), nx - 1)
        i1 = min(max(int((xmax - x0) / cell), 0), nx - 1)
        j0 = min(max(int((ymin - y0) / cell), 0), ny - 1)
        j1 = min(max(int((ymax - y0) / cell), 0), ny - 1)
        for a in range(i0, i1 + 1):
            for b in range(j0, j1 + 1):
                c = a * ny + b
                if counts_only:
                    fill[c] += 1
                else:
                    items[starts[c] + fill[c]] = i
                    fill[c] += 1
                    if zmin < zlo[c]:
                        zlo[c] = zmin
                    if zmax > zhi[c]:
                        zhi[c] = zmax
    return fill


def edge_form(triangles: np.ndarray) -> np.ndarray:
    """Triangles as rows ``(a, b - a, c - a)``, shape ``(N, 9)`` (what the kernels intersect)."""
    t = np.asarray(triangles, np.float64)
    return np.ascontiguousarray(np.concatenate([t[:, 0], t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]], axis=1))


def build_grid(triangles: np.ndarray, *, per_cell: float = TRIANGLES_PER_CELL):
    """Uniform ``x, y`` grid over a triangle soup.

    Parameters
    ----------
    triangles : ndarray, shape (N, 3, 3)
    per_cell : float
        Target average of triangles per cell.

    Returns
    -------
    dict
        ``origin`` (x0, y0), ``cell`` (metres), ``shape`` (nx, ny), ``starts``
        (nx*ny + 1,), ``items`` (M,), ``zlo``/``zhi`` (nx*ny,) z range per cell
        (``+inf``/``-inf`` for empty cells).
    """
    tri = np.ascontiguousarray(triangles, dtype=np.float64)
    v = tri.reshape(-1, 3)
    lo = v.min(axis=0)
    hi = v.max(axis=0)
    ext = np.maximum(hi[:2] - lo[:2], 1e-6)
    n_cells = max(1.0, len(tri) / per_cell)
    cell = float(max(math.sqrt(ext[0] * ext[1] / n_cells), 1e-4))
    nx = int(min(max(1, math.ceil(ext[0] / cell)), 4096))
    ny = int(min(max(1, math.ceil(ext[1] / cell)), 4096))
    cell = float(max(ext[0] / nx, ext[1] / ny))
    nx = max(1, int(math.ceil(ext[0] / cell - 1e-9)))
    ny = max(1, int(math.ceil(ext[1] / cell - 1e-9)))
    dummy = np.zeros(1, np.int64)
    zdummy = np.zeros(1)
    counts = _fill_grid(tri, lo[0], lo[1], cell, nx, ny, True, dummy, dummy, zdummy, zdummy)
    starts = np.zeros(nx * ny + 1, np.int64)
    np.cumsum(counts, out=starts[1:])
    items = np.empty(int(starts[-1]), np.int64)
    zlo = np.full(nx * ny, np.inf)
    zhi = np.full(nx * ny, -np.inf)
    _fill_grid(tri, lo[0], lo[1], cell, nx, ny, False, starts, items, zlo, zhi)
    return {"origin": (float(lo[0]), float(lo[1])), "cell": cell, "shape": (nx, ny), "starts": starts,
            "items": items, "zlo": zlo, "zhi": zhi, "zmin": float(lo[2]), "zmax": float(hi[2])}


@njit(cache=True, inline="always")
def _hit_triangle(ox, oy, oz, dx, dy, dz, tri, i, tmin, tmax):
    """Möller-Trumbore: ray parameter of the hit with triangle ``i`` in ``(tmin, tmax)``, else INF.

    ``tri`` is the edge form of :func:`edge_form`: corner ``a`` and edges ``b - a``, ``c - a``.
    """
    ax, ay, az = tri[i, 0], tri[i, 1], tri[i, 2]
    e1x, e1y, e1z = tri[i, 3], tri[i, 4], tri[i, 5]
    e2x, e2y, e2z = tri[i, 6], tri[i, 7], tri[i, 8]
    px = dy * e2z - dz * e2y
    py = dz * e2x - dx * e2z
    pz = dx * e2y - dy * e2x
    det = e1x * px + e1y * py + e1z * pz
    if abs(det) < 1e-14:
        return INF
    inv = 1.0 / det
    sx = ox - ax
    sy = oy - ay
    sz = oz - az
    u = (sx * px + sy * py + sz * pz) * inv
    if u < 0.0 or u > 1.0:
        return INF
    qx = sy * e1z - sz * e1y
    qy = sz * e1x - sx * e1z
    qz = sx * e1y - sy * e1x
    v = (dx * qx + dy * qy + dz * qz) * inv
    if v < 0.0 or u + v > 1.0:
        return INF
    t = (e2x * qx + e2y * qy + e2z * qz) * inv
    if t <= tmin or t >= tmax:
        return INF
    return t


@njit(cache=True, inline="always")
def _dda_axis(o, d, g0, i, cell):
    """Grid walk along one axis: (step, ray parameter of the next cell boundary, parameter per cell)."""
    if d > 0.0:
        return 1, (g0 + (i + 1) * cell - o) / d, cell / d
    if d < 0.0:
        return -1, (g0 + i * cell - o) / d, -cell / d
    return 0, INF, INF


@njit(cache=True)
def trace_ray(ox, oy, oz, dx, dy, dz, tmax, tri, gx0, gy0, cell, nx, ny, starts, items, zlo, zhi, zmax_world):
    """Nearest triangle hit along a ray within ``(0, tmax)``.

    Returns
    -------
    (t, index)
        Ray parameter (metres for a unit direction) and triangle index, or ``(INF, -1)``.
    """
    # clip the ray to the grid's xy box and to the world's top
    t0 = 1e-9
    t1 = tmax
    if dz > 0.0:
        if oz > zmax_world:
            return INF, -1
        t1 = min(t1, (zmax_world - oz) / dz)
    elif dz == 0.0 and oz > zmax_world:
        return INF, -1
    gx1 = gx0 + nx * cell
    gy1 = gy0 + ny * cell
    if abs(dx) < 1e-15:
        if ox < gx0 or ox > gx1:
            return INF, -1
    else:
        ta = (gx0 - ox) / dx
        tb = (gx1 - ox) / dx
        if ta > tb:
            ta, tb = tb, ta
        t0 = max(t0, ta)
        t1 = min(t1, tb)
    if abs(dy) < 1e-15:
        if oy < gy0 or oy > gy1:
            return INF, -1
    else:
        ta = (gy0 - oy) / dy
        tb = (gy1 - oy) / dy
        if ta > tb:
            ta, tb = tb, ta
        t0 = max(t0, ta)
        t1 = min(t1, tb)
    if t0 > t1:
        return INF, -1
    px = ox + dx * t0
    py = oy + dy * t0
    ix = min(max(int((px - gx0) / cell), 0), nx - 1)
    iy = min(max(int((py - gy0) / cell), 0), ny - 1)
    stepx, tnx, tdx = _dda_axis(ox, dx, gx0, ix, cell)
    stepy, tny, tdy = _dda_axis(oy, dy, gy0, iy, cell)
    best = INF
    best_i = -1
    tc0 = t0
    while True:
        tc1 = min(min(tnx, tny), t1)
        c = ix * ny + iy
        if starts[c + 1] > starts[c]:
            za = oz + dz * tc0
            zb = oz + dz * tc1
            if za > zb:
                za, zb = zb, za
            if zb >= zlo[c] and za <= zhi[c]:
                for k in range(starts[c], starts[c + 1]):
                    i = items[k]
                    t = _hit_triangle(ox, oy, oz, dx, dy, dz, tri, i, 1e-9, best)
                    if t < best:
                        best = t
                        best_i = i
        if best <= tc1 + 1e-12 or tc1 >= t1:
            break
        tc0 = tc1
        if tnx < tny:
            ix += stepx
            tnx += tdx
            if ix < 0 or ix >= nx:
                break
        else:
            iy += stepy
            tny += tdy
            if iy < 0 or iy >= ny:
                break
    if best < tmax:
        return best, best_i
    return INF, -1


@njit(cache=True, parallel=True)
def cast_kernel(ox, oy, oz, az, el, tri, gx0, gy0, cell, nx, ny, starts, items, zlo, zhi, zmax_world,
                ground_z, has_ground, depth, index):
    """Cast the ray grid ``az`` (W,) x ``el`` (H,) from ``(ox, oy, oz)``.

    Writes ``depth`` (H, W): distance of the nearest surface (``inf`` for sky)
    and ``index`` (H, W): triangle index, ``-2`` for the ground plane, ``-1``
    for sky.
    """
    H = el.shape[0]
    W = az.shape[0]
    for r in prange(H):
        ce = math.cos(el[r])
        dz = math.sin(el[r])
        tg = INF
        if has_ground and dz < 0.0 and oz > ground_z:
            tg = (ground_z - oz) / dz
        for j in range(W):
            dx = ce * math.cos(az[j])
            dy = ce * math.sin(az[j])
            t, i = trace_ray(ox, oy, oz, dx, dy, dz, tg, tri, gx0, gy0, cell, nx, ny, starts, items, zlo, zhi,
                             zmax_world)
            if i >= 0:
                depth[r, j] = t
                index[r, j] = i
            elif tg < INF:
                depth[r, j] = tg
                index[r, j] = -2
            else:
                depth[r, j] = np.inf
                index[r, j] = -1


@njit(cache=True, parallel=True)
def vertical_kernel(xs, ys, z_start, up, tri, gx0, gy0, cell, nx, ny, starts, items, zlo, zhi, zmax_world, out_t):
    """Distance along a vertical ray (``up``: +z, else -z) from ``(x, y, z_start)`` to the nearest triangle."""
    for k in prange(xs.shape[0]):
        dz = 1.0 if up else -1.0
        t, _i = trace_ray(xs[k], ys[k], z_start[k], 0.0, 0.0, dz, INF, tri, gx0, gy0, cell, nx, ny, starts, items,
                          zlo, zhi, zmax_world)
        out_t[k] = t


def trace_reference(origin, directions, triangles, *, ground_z=None):
    """Brute-force nearest hits (NumPy, every ray against every triangle): the kernels' test oracle.

    Parameters
    ----------
    origin : (3,) float
    directions : ndarray, shape (N, 3), unit vectors
    triangles : ndarray, shape (M, 3, 3)
    ground_z : float, optional
        Height of an infinite ground plane (hit from above only).

    Returns
    -------
    depth : ndarray, shape (N,)
        ``inf`` where nothing is hit.
    index : ndarray, shape (N,)
        Triangle index, -2 for the ground plane, -1 for nothing.
    """
    o = np.asarray(origin, float)
    d = np.asarray(directions, float).reshape(-1, 3)
    tri = np.asarray(triangles, float)
    a = tri[:, 0]
    e1 = tri[:, 1] - a
    e2 = tri[:, 2] - a
    p = np.cross(d[:, None, :], e2[None, :, :])
    det = np.einsum("nmk,mk->nm", p, e1)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / det
        s = o[None, :] - a
        u = np.einsum("nmk,mk->nm", p, s) * inv
        q = np.cross(s, e1)
        v = (d @ q.T) * inv
        t = np.einsum("mk,mk->m", e2, q)[None, :] * inv
    ok = (np.abs(det) >= 1e-14) & (u >= 0) & (u <= 1) & (v >= 0) & (u + v <= 1) & (t > 1e-9)
    t = np.where(ok, t, np.inf)
    index = np.where(np.isfinite(t).any(axis=1), np.argmin(t, axis=1), -1)
    depth = t.min(axis=1) if t.shape[1] else np.full(len(d), np.inf)
    if ground_z is not None:
        with np.errstate(divide="ignore", invalid="ignore"):
            tg = np.where((d[:, 2] < 0) & (o[2] > ground_z), (ground_z - o[2]) / d[:, 2], np.inf)
        g = tg < depth
        depth = np.where(g, tg, depth)
        index = np.where(g, -2, index)
    return depth, index
