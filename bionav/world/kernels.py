"""Numba ray-casting kernels (intersection, texture sampling, Lambertian shading).

One primary ray per pixel (or per sub-pixel when supersampling), analytic
intersections with boxes, vertical frusta and ellipsoids, trilinear mip-mapped
textures, hemispherical ambient light plus point/directional lights with hard
shadows. :func:`trace_depth_reference` is a plain NumPy implementation of the
intersection logic that the kernel is tested against.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

EPS = 1e-6
INF = 1e30


@njit(cache=True, inline="always")
def _slab(l, d, h):
    """Entry/exit parameters of a ray against the slab ``|x| <= h`` (one axis)."""
    if abs(d) < 1e-12:
        if abs(l) > h:
            return INF, -INF  # never inside
        return -INF, INF
    t1 = (-h - l) / d
    t2 = (h - l) / d
    if t1 > t2:
        return t2, t1
    return t1, t2


@njit(cache=True, inline="always")
def _hit_box(ox, oy, oz, dx, dy, dz, B, i):
    """Nearest hit with box ``B[i]``; returns (t, face, qx, qy, qz, ldx, ldy, ldz) in the box frame."""
    cx, cy, cz, hx, hy, hz = B[i, 0], B[i, 1], B[i, 2], B[i, 3], B[i, 4], B[i, 5]
    cs, sn, inside = B[i, 6], B[i, 7], B[i, 8]
    px = ox - cx
    py = oy - cy
    lx = cs * px + sn * py
    ly = -sn * px + cs * py
    lz = oz - cz
    ldx = cs * dx + sn * dy
    ldy = -sn * dx + cs * dy
    ldz = dz
    a0, a1 = _slab(lx, ldx, hx)
    b0, b1 = _slab(ly, ldy, hy)
    c0, c1 = _slab(lz, ldz, hz)
    tnear = a0
    ax_near = 0
    if b0 > tnear:
        tnear = b0
        ax_near = 1
    if c0 > tnear:
        tnear = c0
        ax_near = 2
    tfar = a1
    ax_far = 0
    if b1 < tfar:
        tfar = b1
        ax_far = 1
    if c1 < tfar:
        tfar = c1
        ax_far = 2
    if tnear > tfar or tfar <= EPS:
        return INF, -1, 0.0, 0.0, 0.0, ldx, ldy, ldz
    if inside > 0.5 or tnear <= EPS:
        t = tfar
        ax = ax_far
        dcomp = ldx if ax == 0 else (ldy if ax == 1 else ldz)
        face = 2 * ax + (1 if dcomp > 0 else 0)  # leaving through the face the ray points at
    else:
        t = tnear
        ax = ax_near
        dcomp = ldx if ax == 0 else (ldy if ax == 1 else ldz)
        face = 2 * ax + (0 if dcomp > 0 else 1)  # entering through the face that looks at the ray
    return t, face, lx + t * ldx, ly + t * ldy, lz + t * ldz, ldx, ldy, ldz


@njit(cache=True)
def _hit_frustum(ox, oy, oz, dx, dy, dz, F, i):
    """Nearest hit with frustum ``F[i]``; returns (t, face) with face 0 side, 1 bottom, 2 top."""
    cx, cy, z0, z1, r0, r1 = F[i, 0], F[i, 1], F[i, 2], F[i, 3], F[i, 4], F[i, 5]
    k = (r1 - r0) / (z1 - z0)
    px = ox - cx
    py = oy - cy
    w = r0 + k * (oz - z0)
    best = INF
    face = -1
    a = dx * dx + dy * dy - k * k * dz * dz
    bq = 2.0 * (px * dx + py * dy - k * w * dz)
    c = px * px + py * py - w * w
    if abs(a) > 1e-12:
        disc = bq * bq - 4.0 * a * c
        if disc >= 0.0:
            sq = math.sqrt(disc)
            ta = (-bq - sq) / (2.0 * a)
            tb = (-bq + sq) / (2.0 * a)
            if ta > tb:
                ta, tb = tb, ta
            for t in (ta, tb):
                if t > EPS and t < best:
                    z = oz + t * dz
                    if z >= z0 and z <= z1 and w + k * dz * t >= 0.0:
                        best = t
                        face = 0
                        break
    elif abs(bq) > 1e-12:
        t = -c / bq
        z = oz + t * dz
        if t > EPS and z >= z0 and z <= z1 and w + k * dz * t >= 0.0:
            best = t
            face = 0
    if abs(dz) > 1e-12:
        for cap in range(2):
            zc = z0 if cap == 0 else z1
            rc = r0 if cap == 0 else r1
            if rc <= 0.0:
                continue
            t = (zc - oz) / dz
            if t > EPS and t < best:
                qx = px + t * dx
                qy = py + t * dy
                if qx * qx + qy * qy <= rc * rc:
                    best = t
                    face = 1 + cap
    return best, face


@njit(cache=True)
def _hit_ellipsoid(ox, oy, oz, dx, dy, dz, E, i):
    """Nearest hit with ellipsoid ``E[i]``; returns t (INF if missed)."""
    px = (ox - E[i, 0]) / E[i, 3]
    py = (oy - E[i, 1]) / E[i, 4]
    pz = (oz - E[i, 2]) / E[i, 5]
    qx = dx / E[i, 3]
    qy = dy / E[i, 4]
    qz = dz / E[i, 5]
    a = qx * qx + qy * qy + qz * qz
    b = 2.0 * (px * qx + py * qy + pz * qz)
    c = px * px + py * py + pz * pz - 1.0
    disc = b * b - 4.0 * a * c
    if disc < 0.0:
        return INF
    sq = math.sqrt(disc)
    t = (-b - sq) / (2.0 * a)
    if t > EPS:
        return t
    t = (-b + sq) / (2.0 * a)
    if t > EPS:
        return t
    return INF


@njit(cache=True, inline="always")
def _hit_prim(ox, oy, oz, dx, dy, dz, kind, i, boxes, frusta, ells):
    """Hit distance and face of one primitive (``kind`` 0 box, 1 frustum, 2 ellipsoid)."""
    if kind == 0:
        t, fc, _, _, _, _, _, _ = _hit_box(ox, oy, oz, dx, dy, dz, boxes, i)
        return t, fc
    if kind == 1:
        return _hit_frustum(ox, oy, oz, dx, dy, dz, frusta, i)
    return _hit_ellipsoid(ox, oy, oz, dx, dy, dz, ells, i), 0


@njit(cache=True)
def _trace(ox, oy, oz, dx, dy, dz, el, cands, j, n_cands, el_lo, el_hi, rho_min, prim_kind, prim_idx,
           boxes, frusta, ells):
    """Nearest primitive along a ray among the column's candidates.

    Candidates are sorted by their horizontal distance ``rho_min`` from the
    camera, a lower bound of the hit distance, so the loop stops as soon as
    no remaining candidate can be nearer than the best hit. Candidates whose
    elevation band does not hold ``el`` are skipped.

    Returns (t, kind, index, face); kind 0 box, 1 frustum, 2 ellipsoid, -1 none.
    """
    best = INF
    kind = -1
    idx = -1
    face = -1
    for q in range(n_cands):
        p = cands[j, q]
        if rho_min[p] >= best:
            break
        if el < el_lo[p] or el > el_hi[p]:
            continue
        k = prim_kind[p]
        i = prim_idx[p]
        t, fc = _hit_prim(ox, oy, oz, dx, dy, dz, k, i, boxes, frusta, ells)
        if t < best:
            best, kind, idx, face = t, k, i, fc
    return best, kind, idx, face


@njit(cache=True)
def _prim_bounds(ox, oy, oz, kind, i, boxes, frusta, ells):
    """Angular bounds of a primitive seen from ``(ox, oy, oz)``.

    Returns ``(all_az, az_lo, az_hi, el_lo, el_hi, rho_min)``: azimuth range
    (radians, world frame; ``all_az`` when the camera stands above/inside the
    footprint), elevation range, and the horizontal distance from the camera
    to the primitive's footprint (a lower bound of any hit distance).
    """
    lo = 0.0
    hi = 0.0
    if kind == 0:
        cx, cy, cz = boxes[i, 0], boxes[i, 1], boxes[i, 2]
        hx, hy, hz = boxes[i, 3], boxes[i, 4], boxes[i, 5]
        cs, sn = boxes[i, 6], boxes[i, 7]
        if boxes[i, 8] > 0.5:  # room shell: everything
            return True, 0.0, 0.0, -10.0, 10.0, 0.0
        px = ox - cx
        py = oy - cy
        lx = cs * px + sn * py
        ly = -sn * px + cs * py
        ex = max(abs(lx) - hx, 0.0)
        ey = max(abs(ly) - hy, 0.0)
        rho_min = math.sqrt(ex * ex + ey * ey)
        rho_max = 0.0
        ac = math.atan2(cy - oy, cx - ox)
        lo = INF
        hi = -INF
        for sx in (-1.0, 1.0):
            for sy in (-1.0, 1.0):
                qx = cx + cs * sx * hx - sn * sy * hy - ox
                qy = cy + sn * sx * hx + cs * sy * hy - oy
                rho_max = max(rho_max, math.sqrt(qx * qx + qy * qy))
                if rho_min > 0.0:
                    da = (math.atan2(qy, qx) - ac + math.pi) % (2 * math.pi) - math.pi
                    lo = min(lo, da)
                    hi = max(hi, da)
        zlo = cz - hz
        zhi = cz + hz
    elif kind == 1:
        cx, cy = frusta[i, 0], frusta[i, 1]
        rad = max(frusta[i, 4], frusta[i, 5])
        rho = math.sqrt((cx - ox) ** 2 + (cy - oy) ** 2)
        rho_min = max(rho - rad, 0.0)
        rho_max = rho + rad
        ac = math.atan2(cy - oy, cx - ox)
        if rho_min > 0.0:
            hi = math.asin(rad / rho)
            lo = -hi
        zlo = frusta[i, 2]
        zhi = frusta[i, 3]
    else:
        cx, cy = ells[i, 0], ells[i, 1]
        rad = max(ells[i, 3], ells[i, 4])
        rho = math.sqrt((cx - ox) ** 2 + (cy - oy) ** 2)
        rho_min = max(rho - rad, 0.0)
        rho_max = rho + rad
        ac = math.atan2(cy - oy, cx - ox)
        if rho_min > 0.0:
            hi = math.asin(rad / rho)
            lo = -hi
        zlo = ells[i, 2] - ells[i, 5]
        zhi = ells[i, 2] + ells[i, 5]
    el_hi = math.atan2(zhi - oz, rho_min if zhi > oz else rho_max)
    el_lo = math.atan2(zlo - oz, rho_min if zlo < oz else rho_max)
    if rho_min <= 0.0:
        return True, 0.0, 0.0, el_lo, el_hi, 0.0
    return False, ac + lo, ac + hi, el_lo, el_hi, rho_min


@njit(cache=True)
def _candidates(ox, oy, oz, az, margin, prim_kind, prim_idx, boxes, frusta, ells):
    """Per-column candidate primitives (sorted near to far) and per-primitive elevation bands.

    ``margin`` (radians) widens the bands to cover sub-pixel rays.

    Returns
    -------
    cands : ndarray (W, n) int, counts : ndarray (W,) int, el_lo, el_hi, rho_min : ndarray (n,)
    """
    n = prim_kind.shape[0]
    W = az.shape[0]
    all_az = np.zeros(n, np.bool_)
    az_lo = np.empty(n)
    az_hi = np.empty(n)
    el_lo = np.empty(n)
    el_hi = np.empty(n)
    rho_min = np.empty(n)
    for p in range(n):
        a, lo, hi, elo, ehi, rm = _prim_bounds(ox, oy, oz, prim_kind[p], prim_idx[p], boxes, frusta, ells)
        all_az[p] = a
        az_lo[p] = lo - margin
        az_hi[p] = hi + margin
        el_lo[p] = elo - margin
        el_hi[p] = ehi + margin
        rho_min[p] = rm
    order = np.argsort(rho_min, kind="mergesort")
    cands = np.empty((W, n), np.int64)
    counts = np.zeros(W, np.int64)
    two_pi = 2.0 * math.pi
    for q in range(n):
        p = order[q]
        if all_az[p]:
            for j in range(W):
                cands[j, counts[j]] = p
                counts[j] += 1
            continue
        width = az_hi[p] - az_lo[p]
        for j in range(W):
            # written unconditionally, counted where the column lies in the
            # primitive's azimuth range (no conditional store; counts[j] <= q < n,
            # and entries from counts[j] on are never read)
            cands[j, counts[j]] = p
            counts[j] += (az[j] - az_lo[p]) % two_pi <= width
    return cands, counts, el_lo, el_hi, rho_min


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
def build_shadow_bins(light_params, spheres, casters):
    """Per-light bins listing the casters that can block a shadow ray through each bin.

    Point lights bin the direction from the light into a cube map of
    ``6 x G x G`` cells; a caster enters every cell whose cone of directions
    meets the cone around its bounding sphere. Directional lights bin the
    projection of the point onto the plane orthogonal to the light direction.

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
    n_cube = 6 * g * g
    nbmax = max(n_cube, SHADOW_BINS_SUN * SHADOW_BINS_SUN)
    # cube cell centres and angular radii (same for every point light)
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
    grids = np.zeros((nl, 6))
    for k in range(nl):
        if light_params[k, 0] > 0.5:
            e1x, e1y, e1z, e2x, e2y, e2z = _sun_basis(light_params[k, 1], light_params[k, 2], light_params[k, 3])
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
            grids[k, 0] = lo_a
            grids[k, 1] = max((hi_a - lo_a) / SHADOW_BINS_SUN, 1e-9) * (1 + 1e-9)
            grids[k, 2] = SHADOW_BINS_SUN
            grids[k, 3] = lo_b
            grids[k, 4] = max((hi_b - lo_b) / SHADOW_BINS_SUN, 1e-9) * (1 + 1e-9)
            grids[k, 5] = SHADOW_BINS_SUN
    counts = np.zeros((nl, nbmax + 1), np.int64)
    items = np.empty((nl, 1), np.int64)
    fill = np.zeros((nl, nbmax + 1), np.int64)
    for sweep in range(2):
        if sweep == 1:
            total = 0
            for k in range(nl):
                acc = 0
                for i in range(nbmax + 1):
                    c = counts[k, i]
                    counts[k, i] = acc
                    acc += c
                total = max(total, acc)
            items = np.full((nl, max(total, 1)), -1, np.int64)
            fill = counts.copy()
        for k in range(nl):
            for q in range(casters.shape[0]):
                p = casters[q]
                if light_params[k, 0] < 0.5:
                    vx = spheres[p, 0] - light_params[k, 1]
                    vy = spheres[p, 1] - light_params[k, 2]
                    vz = spheres[p, 2] - light_params[k, 3]
                    d = math.sqrt(vx * vx + vy * vy + vz * vz)
                    rad = spheres[p, 3]
                    everywhere = d <= rad
                    half = 0.0 if everywhere else math.asin(rad / d)
                    for c in range(n_cube):
                        if not everywhere:
                            cosang = (cell_dir[c, 0] * vx + cell_dir[c, 1] * vy + cell_dir[c, 2] * vz) / d
                            if math.acos(max(-1.0, min(1.0, cosang))) > cell_rad[c] + half:
                                continue
                        if sweep == 0:
                            counts[k, c] += 1
                        else:
                            items[k, fill[k, c]] = p
                            fill[k, c] += 1
                else:
                    e1x, e1y, e1z, e2x, e2y, e2z = _sun_basis(light_params[k, 1], light_params[k, 2],
                                                              light_params[k, 3])
                    pa = spheres[p, 0] * e1x + spheres[p, 1] * e1y + spheres[p, 2] * e1z
                    pb = spheres[p, 0] * e2x + spheres[p, 1] * e2y + spheres[p, 2] * e2z
                    na = int(grids[k, 2])
                    nb = int(grids[k, 5])
                    a0 = max(int(math.floor((pa - spheres[p, 3] - grids[k, 0]) / grids[k, 1])), 0)
                    a1 = min(int(math.floor((pa + spheres[p, 3] - grids[k, 0]) / grids[k, 1])), na - 1)
                    b0 = max(int(math.floor((pb - spheres[p, 3] - grids[k, 3]) / grids[k, 4])), 0)
                    b1 = min(int(math.floor((pb + spheres[p, 3] - grids[k, 3]) / grids[k, 4])), nb - 1)
                    for bb in range(b0, b1 + 1):
                        for aa in range(a0, a1 + 1):
                            c = bb * na + aa
                            if sweep == 0:
                                counts[k, c] += 1
                            else:
                                items[k, fill[k, c]] = p
                                fill[k, c] += 1
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


@njit(cache=True)
def _surface(kind, idx, face, t, ox, oy, oz, dx, dy, dz, boxes, frusta, ells):
    """Normal (world frame, facing the ray), surface coordinates (u, v) in metres and face extents."""
    hx = ox + t * dx
    hy = oy + t * dy
    hz = oz + t * dz
    if kind == 0:
        b = boxes[idx]
        _, _, qx, qy, qz, _, _, _ = _hit_box(ox, oy, oz, dx, dy, dz, boxes, idx)
        ax = face // 2
        sgn = 1.0 if face % 2 == 1 else -1.0
        lnx = sgn if ax == 0 else 0.0
        lny = sgn if ax == 1 else 0.0
        lnz = sgn if ax == 2 else 0.0
        nx = b[6] * lnx - b[7] * lny
        ny = b[7] * lnx + b[6] * lny
        nz = lnz
        if ax == 0:
            u, v, eu, ev = qy + b[4], qz + b[5], 2 * b[4], 2 * b[5]
        elif ax == 1:
            u, v, eu, ev = qx + b[3], qz + b[5], 2 * b[3], 2 * b[5]
        else:
            u, v, eu, ev = qx + b[3], qy + b[4], 2 * b[3], 2 * b[4]
    elif kind == 1:
        f = frusta[idx]
        qx = hx - f[0]
        qy = hy - f[1]
        rm = 0.5 * (f[4] + f[5])
        if face == 0:
            k = (f[5] - f[4]) / (f[3] - f[2])
            rho = math.sqrt(qx * qx + qy * qy)
            if rho < 1e-12:
                rho = 1e-12
            nx, ny, nz = qx / rho, qy / rho, -k
            nn = math.sqrt(nx * nx + ny * ny + nz * nz)
            nx, ny, nz = nx / nn, ny / nn, nz / nn
            ang = math.atan2(qy, qx) + math.pi
            u, v, eu, ev = ang * rm, hz - f[2], 2 * math.pi * rm, f[3] - f[2]
        else:
            rc = f[4] if face == 1 else f[5]
            nx, ny, nz = 0.0, 0.0, (-1.0 if face == 1 else 1.0)
            u, v, eu, ev = qx + rc, qy + rc, 2 * rc, 2 * rc
    else:
        e = ells[idx]
        px = (hx - e[0]) / e[3]
        py = (hy - e[1]) / e[4]
        pz = (hz - e[2]) / e[5]
        nx, ny, nz = px / e[3], py / e[4], pz / e[5]
        nn = math.sqrt(nx * nx + ny * ny + nz * nz)
        nx, ny, nz = nx / nn, ny / nn, nz / nn
        rm = 0.5 * (e[3] + e[4])
        pz = min(1.0, max(-1.0, pz))
        u = (math.atan2(py, px) + math.pi) * rm
        v = (math.asin(pz) + 0.5 * math.pi) * e[5]
        eu, ev = 2 * math.pi * rm, math.pi * e[5]
    if nx * dx + ny * dy + nz * dz > 0.0:
        nx, ny, nz = -nx, -ny, -nz
    return hx, hy, hz, nx, ny, nz, u, v, eu, ev


@njit(cache=True)
def _bilinear(tex, base, size, uu, vv):
    x = uu * size - 0.5
    y = vv * size - 0.5
    x0 = math.floor(x)
    y0 = math.floor(y)
    fx = x - x0
    fy = y - y0
    ix0 = int(x0) % size
    iy0 = int(y0) % size
    ix1 = (ix0 + 1) % size
    iy1 = (iy0 + 1) % size
    a = tex[base + iy0 * size + ix0]
    b = tex[base + iy0 * size + ix1]
    c = tex[base + iy1 * size + ix0]
    d = tex[base + iy1 * size + ix1]
    return (a * (1 - fx) + b * fx) * (1 - fy) + (c * (1 - fx) + d * fx) * fy


@njit(cache=True)
def _sample_texture(tex, tex_id, size, uu, vv, lod):
    """Trilinear sample of texture ``tex_id`` at normalised (uu, vv) and level of detail ``lod``."""
    n_levels = 0
    s = size
    while s >= 1:
        n_levels += 1
        s //= 2
    per_tex = 0
    s = size
    for _ in range(n_levels):
        per_tex += s * s
        s //= 2
    if lod < 0.0:
        lod = 0.0
    if lod > n_levels - 1:
        lod = float(n_levels - 1)
    l0 = int(math.floor(lod))
    fr = lod - l0
    base = tex_id * per_tex
    s = size
    for _ in range(l0):
        base += s * s
        s //= 2
    v0 = _bilinear(tex, base, s, uu, vv)
    if fr < 1e-3 or s == 1:
        return v0
    v1 = _bilinear(tex, base + s * s, s // 2, uu, vv)
    return v0 * (1.0 - fr) + v1 * fr


@njit(cache=True, parallel=True)
def render_kernel(ox, oy, oz, az, el, pix_angle,
                  boxes, box_mats, frusta, frustum_mats, ells, ell_mats,
                  prim_kind, prim_idx, spheres, shadow_grids, shadow_starts, shadow_items,
                  mat_tex, mat_fit, mat_scale, mat_albedo, mat_emission, tex, tex_size,
                  light_params, light_power, amb_up, amb_down, shadows,
                  out, depth, sky_mask):
    """Render radiance for the ray grid ``az`` (W,) x ``el`` (H,) from ``(ox, oy, oz)``.

    Writes ``out`` (H, W, C) radiance, ``depth`` (H, W) hit distance in metres
    (inf for misses) and ``sky_mask`` (H, W) True where nothing was hit.
    """
    H = el.shape[0]
    W = az.shape[0]
    C = out.shape[2]
    nl = light_params.shape[0]
    cands, counts, el_lo, el_hi, rho_min = _candidates(ox, oy, oz, az, 2.0 * pix_angle, prim_kind, prim_idx,
                                                       boxes, frusta, ells)
    for r in prange(H):  # rows are independent: the result does not depend on the number of threads
        E = np.empty(C)
        Eg = np.empty(C)
        ce = math.cos(el[r])
        se = math.sin(el[r])
        for j in range(W):
            dx = ce * math.cos(az[j])
            dy = ce * math.sin(az[j])
            dz = se
            t, kind, idx, face = _trace(ox, oy, oz, dx, dy, dz, el[r], cands, j, counts[j], el_lo, el_hi,
                                        rho_min, prim_kind, prim_idx, boxes, frusta, ells)
            if kind < 0:
                sky_mask[r, j] = True
                depth[r, j] = np.inf
                for c in range(C):
                    out[r, j, c] = 0.0
                continue
            depth[r, j] = t
            hx, hy, hz, nx, ny, nz, u, v, eu, ev = _surface(kind, idx, face, t, ox, oy, oz, dx, dy, dz,
                                                            boxes, frusta, ells)
            if kind == 0:
                m = box_mats[idx, face]
            elif kind == 1:
                m = frustum_mats[idx, face]
            else:
                m = ell_mats[idx]
            if mat_fit[m] > 0.5:
                su = eu
                sv = ev
            else:
                su = mat_scale[m, 0]
                sv = mat_scale[m, 1]
            cosi = abs(nx * dx + ny * dy + nz * dz)
            if cosi < 0.2:
                cosi = 0.2
            foot = t * pix_angle / cosi
            texel = foot * tex_size / min(su, sv)
            lod = math.log2(texel) if texel > 1e-9 else 0.0
            tv = _sample_texture(tex, mat_tex[m], tex_size, u / su, v / sv, lod)
            wup = 0.5 * (1.0 + nz)
            for c in range(C):
                E[c] = amb_down[c] + (amb_up[c] - amb_down[c]) * wup
            px = hx + 1e-4 * nx
            py = hy + 1e-4 * ny
            pz = hz + 1e-4 * nz
            # lights of one group (the point lights of one light band) share one shadow ray,
            # aimed at the group's light that contributes most to this point
            k = 0
            while k < nl:
                grp = light_params[k, 5]
                for c in range(C):
                    Eg[c] = 0.0
                best_fac = 0.0
                best_k = -1
                bx = by = bz = bt = 0.0
                while k < nl and light_params[k, 5] == grp:
                    if light_params[k, 0] < 0.5:
                        lx = light_params[k, 1] - hx
                        ly = light_params[k, 2] - hy
                        lz = light_params[k, 3] - hz
                        d2 = lx * lx + ly * ly + lz * lz
                        dist = math.sqrt(d2)
                        lx /= dist
                        ly /= dist
                        lz /= dist
                        tmax = dist - 1e-3
                        fac = nx * lx + ny * ly + nz * lz
                        if light_params[k, 4] > 0.5:
                            fac *= lz if lz > 0.0 else 0.0
                        fac /= max(d2, 1e-4)
                    else:
                        lx = light_params[k, 1]
                        ly = light_params[k, 2]
                        lz = light_params[k, 3]
                        tmax = INF
                        fac = nx * lx + ny * ly + nz * lz
                    if fac > 0.0:
                        for c in range(C):
                            Eg[c] += light_power[k, c] * fac
                        if fac > best_fac:
                            best_fac = fac
                            best_k = k
                            bx, by, bz, bt = lx, ly, lz, tmax
                    k += 1
                if best_k < 0:
                    continue
                if shadows and _occluded(best_k, px, py, pz, bx, by, bz, bt, light_params,
                                         shadow_grids, shadow_starts, shadow_items,
                                         prim_kind, prim_idx, spheres, boxes, frusta, ells):
                    continue
                for c in range(C):
                    E[c] += Eg[c]
            for c in range(C):
                out[r, j, c] = tv * (mat_albedo[m, c] * E[c] + mat_emission[m, c])


@njit(cache=True, parallel=True)
def depth_kernel(ox, oy, oz, az, el, pix_angle, prim_kind, prim_idx, spheres, boxes, frusta, ells,
                 depth, kind_out, index_out):
    """Hit distance (inf for misses), primitive kind and index for every ray of the grid."""
    cands, counts, el_lo, el_hi, rho_min = _candidates(ox, oy, oz, az, 2.0 * pix_angle, prim_kind, prim_idx,
                                                       boxes, frusta, ells)
    for r in prange(el.shape[0]):
        ce = math.cos(el[r])
        se = math.sin(el[r])
        for j in range(az.shape[0]):
            t, kind, idx, _ = _trace(ox, oy, oz, ce * math.cos(az[j]), ce * math.sin(az[j]), se, el[r],
                                     cands, j, counts[j], el_lo, el_hi, rho_min, prim_kind, prim_idx,
                                     boxes, frusta, ells)
            depth[r, j] = t if kind >= 0 else np.inf
            kind_out[r, j] = kind
            index_out[r, j] = idx


def trace_depth_reference(origin, directions, boxes, frusta, ells):
    """Plain NumPy reference of the intersection logic (no shading).

    Parameters
    ----------
    origin : array_like, shape (3,)
        Ray origin (metres, world frame).
    directions : ndarray, shape (N, 3)
        Unit ray directions.
    boxes, frusta, ells : ndarray
        Primitive rows as in :class:`bionav.world.scene.CompiledScene`.

    Returns
    -------
    ndarray, shape (N,)
        Distance to the nearest hit (inf where nothing is hit).
    """
    o = np.asarray(origin, float)
    d = np.asarray(directions, float)
    best = np.full(len(d), np.inf)
    with np.errstate(divide="ignore", invalid="ignore"):
        for b in boxes:
            c, h, cs, sn, inside = b[0:3], b[3:6], b[6], b[7], b[8]
            p = o - c
            lo = np.array([cs * p[0] + sn * p[1], -sn * p[0] + cs * p[1], p[2]])
            ld = np.stack([cs * d[:, 0] + sn * d[:, 1], -sn * d[:, 0] + cs * d[:, 1], d[:, 2]], axis=1)
            t1 = (-h - lo) / ld
            t2 = (h - lo) / ld
            par = np.abs(ld) < 1e-12
            out_slab = np.abs(lo) > h
            t1 = np.where(par, np.where(out_slab, np.inf, -np.inf), t1)
            t2 = np.where(par, np.where(out_slab, -np.inf, np.inf), t2)
            tn = np.minimum(t1, t2).max(axis=1)
            tf = np.maximum(t1, t2).min(axis=1)
            ok = (tn <= tf) & (tf > EPS)
            t = np.where((inside > 0.5) | (tn <= EPS), tf, tn)
            best = np.where(ok & (t < best), t, best)
        for f in frusta:
            cx, cy, z0, z1, r0, r1 = f[:6]
            k = (r1 - r0) / (z1 - z0)
            px, py = o[0] - cx, o[1] - cy
            w = r0 + k * (o[2] - z0)
            a = d[:, 0] ** 2 + d[:, 1] ** 2 - k * k * d[:, 2] ** 2
            bq = 2 * (px * d[:, 0] + py * d[:, 1] - k * w * d[:, 2])
            c = px * px + py * py - w * w
            disc = bq * bq - 4 * a * c
            sq = np.sqrt(np.maximum(disc, 0))
            quad = (np.abs(a) > 1e-12) & (disc >= 0)
            lin = (np.abs(a) <= 1e-12) & (np.abs(bq) > 1e-12)
            for t, use in (((-bq - sq) / (2 * a), quad), ((-bq + sq) / (2 * a), quad), (-c / bq, lin)):
                z = o[2] + t * d[:, 2]
                valid = use & (t > EPS) & (z >= z0) & (z <= z1) & (w + k * d[:, 2] * t >= 0) & np.isfinite(t)
                best = np.where(valid & (t < best), t, best)
            for zc, rc in ((z0, r0), (z1, r1)):
                if rc <= 0:
                    continue
                t = (zc - o[2]) / d[:, 2]
                q2 = (px + t * d[:, 0]) ** 2 + (py + t * d[:, 1]) ** 2
                valid = (t > EPS) & (q2 <= rc * rc) & np.isfinite(t)
                best = np.where(valid & (t < best), t, best)
        for e in ells:
            r = e[3:6]
            p = (o - e[:3]) / r
            q = d / r
            a = (q * q).sum(1)
            b = 2 * (q @ p)
            c = p @ p - 1
            disc = b * b - 4 * a * c
            sq = np.sqrt(np.maximum(disc, 0))
            ta = (-b - sq) / (2 * a)
            tb = (-b + sq) / (2 * a)
            t = np.where(ta > EPS, ta, np.where(tb > EPS, tb, np.inf))
            t = np.where(disc >= 0, t, np.inf)
            best = np.minimum(best, t)
    return best
