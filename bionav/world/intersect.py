"""Analytic ray-primitive intersections of the renderer (numba) and their NumPy reference.

Boxes (oriented about the vertical axis), vertical frusta and ellipsoids; a
ray is an origin ``(ox, oy, oz)`` and a unit direction ``(dx, dy, dz)`` in the
world frame (ENU, metres); hit distances are in metres along the ray. Per
panorama column, :func:`_candidates` lists the primitives whose azimuth range
covers it (written unconditionally, counted: no conditional store) and
:func:`_trace` finds the nearest hit among them. :func:`trace_depth_reference`
is a plain NumPy implementation of the same intersection logic that the
kernels are tested against. The shading kernels are in
:mod:`bionav.world.kernels`, the shadow bins in :mod:`bionav.world.shadow_bins`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

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


@njit(cache=True, _nrt=False)
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


@njit(cache=True, _nrt=False)
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


@njit(cache=True, _nrt=False)
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


@njit(cache=True, inline="always")
def _disk_bounds(ox, oy, cx, cy, rad):
    """A footprint disk (centre ``cx, cy``, radius ``rad``, m) seen from ``(ox, oy)``: its nearest and
    farthest horizontal distance, the azimuth of its centre and the half-angle it spans around it
    (``lo = hi = 0`` when the camera stands inside it)."""
    rho = math.sqrt((cx - ox) ** 2 + (cy - oy) ** 2)
    rho_min = max(rho - rad, 0.0)
    rho_max = rho + rad
    ac = math.atan2(cy - oy, cx - ox)
    lo = 0.0
    hi = 0.0
    if rho_min > 0.0:
        hi = math.asin(rad / rho)
        lo = -hi
    return rho_min, rho_max, ac, lo, hi


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
        rho_min, rho_max, ac, lo, hi = _disk_bounds(ox, oy, frusta[i, 0], frusta[i, 1],
                                                    max(frusta[i, 4], frusta[i, 5]))
        zlo = frusta[i, 2]
        zhi = frusta[i, 3]
    else:
        rho_min, rho_max, ac, lo, hi = _disk_bounds(ox, oy, ells[i, 0], ells[i, 1], max(ells[i, 3], ells[i, 4]))
        zlo = ells[i, 2] - ells[i, 5]
        zhi = ells[i, 2] + ells[i, 5]
    el_hi = math.atan2(zhi - oz, rho_min if zhi > oz else rho_max)
    el_lo = math.atan2(zlo - oz, rho_min if zlo < oz else rho_max)
    if rho_min <= 0.0:
        return True, 0.0, 0.0, el_lo, el_hi, 0.0
    return False, ac + lo, ac + hi, el_lo, el_hi, rho_min


@njit(cache=True)
def _stable_argsort(keys):
    """Indices that sort ``keys`` (1-D float64) ascending, equal keys in input order, NaN last.

    The same order as ``np.argsort(keys, kind="stable")``: a bottom-up merge sort written out,
    because numba's own sort cost 2-4 s of compilation on a first run, for a few hundred keys.
    """
    n = keys.shape[0]
    a = np.arange(n)
    b = np.empty(n, np.int64)
    width = 1
    while width < n:
        for lo in range(0, n, 2 * width):
            mid = min(lo + width, n)
            hi = min(lo + 2 * width, n)
            i = lo
            j = mid
            for k in range(lo, hi):
                if i < mid and j < hi:
                    x = keys[a[i]]
                    y = keys[a[j]]
                    # take the right run's key only when strictly smaller (stable); NaN sorts last
                    right = y < x or (x != x and y == y)
                else:
                    right = i >= mid
                if right:
                    b[k] = a[j]
                    j += 1
                else:
                    b[k] = a[i]
                    i += 1
        a, b = b, a
        width *= 2
    return a


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
    order = _stable_argsort(rho_min)
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
