"""Numba ray-casting kernels (surfaces, texture sampling, Lambertian shading).

One primary ray per pixel (or per sub-pixel when supersampling), analytic
intersections with boxes, vertical frusta and ellipsoids
(:mod:`bionav.world.intersect`), trilinear mip-mapped textures, hemispherical
ambient light plus point/directional lights with hard shadows
(:mod:`bionav.world.shadow_bins`). :func:`~bionav.world.intersect.trace_depth_reference`
is a plain NumPy implementation of the intersection logic that the kernels are
tested against.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from bionav.world.intersect import INF, _candidates, _hit_box, _trace
from bionav.world.shadow_bins import _occluded


@njit(cache=True, _nrt=False)
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


@njit(cache=True, inline="always")
def _material(kind, idx, face, box_mats, frustum_mats, ell_mats):
    """Material index of face ``face`` of primitive ``idx`` of ``kind`` (0 box, 1 frustum, 2 ellipsoid)."""
    if kind == 0:
        return box_mats[idx, face]
    if kind == 1:
        return frustum_mats[idx, face]
    return ell_mats[idx]


@njit(cache=True, _nrt=False)
def _bilinear(tex, base, size, uu, vv):
    x = uu * size - 0.5
    y = vv * size - 0.5
    x0 = math.floor(x)
    y0 = math.floor(y)
    fx = x - x0
    fy = y - y0
    if size & (size - 1) == 0:  # a power of two (every mip level): the same wrap as % without a division
        m = size - 1
        ix0 = int(x0) & m
        iy0 = int(y0) & m
        ix1 = (ix0 + 1) & m
        iy1 = (iy0 + 1) & m
    else:
        ix0 = int(x0) % size
        iy0 = int(y0) % size
        ix1 = (ix0 + 1) % size
        iy1 = (iy0 + 1) % size
    a = tex[base + iy0 * size + ix0]
    b = tex[base + iy0 * size + ix1]
    c = tex[base + iy1 * size + ix0]
    d = tex[base + iy1 * size + ix1]
    return (a * (1 - fx) + b * fx) * (1 - fy) + (c * (1 - fx) + d * fx) * fy


@njit(cache=True, _nrt=False)
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


@njit(cache=True, inline="always")
def _texture_value(m, t, u, v, eu, ev, cosi, pix_angle, mat_tex, mat_fit, mat_scale, tex, tex_size):
    """Texture value of material ``m`` at surface coordinates ``(u, v)`` (metres) seen at distance ``t``
    under incidence cosine ``cosi``: the mip level follows the pixel's footprint (``cosi`` floored at 0.2);
    a fitted material spans its face (``eu``, ``ev``), else it repeats every ``mat_scale`` metres."""
    if mat_fit[m] > 0.5:
        su = eu
        sv = ev
    else:
        su = mat_scale[m, 0]
        sv = mat_scale[m, 1]
    if cosi < 0.2:
        cosi = 0.2
    foot = t * pix_angle / cosi
    texel = foot * tex_size / min(su, sv)
    lod = math.log2(texel) if texel > 1e-9 else 0.0
    return _sample_texture(tex, mat_tex[m], tex_size, u / su, v / sv, lod)


@njit(cache=True, inline="always")
def _light_at(k, light_params, hx, hy, hz, nx, ny, nz):
    """Light ``k`` at surface point ``h`` with normal ``n``: unit direction to the light, the shadow ray's
    length (inf for the sun) and the irradiance factor (cosine, a spot's downward lobe, 1/d^2 for point lights)."""
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
    return lx, ly, lz, tmax, fac


@njit(cache=True, nogil=True)
def render_kernel(ox, oy, oz, az, el, pix_angle,
                  boxes, box_mats, frusta, frustum_mats, ells, ell_mats,
                  prim_kind, prim_idx, spheres, shadow_grids, shadow_starts, shadow_items,
                  mat_tex, mat_fit, mat_scale, mat_albedo, mat_emission, tex, tex_size,
                  light_params, light_power, amb_up, amb_down, shadows,
                  out, depth, sky_mask):
    """Render radiance for the ray grid ``az`` (W,) x ``el`` (H,) from ``(ox, oy, oz)``.

    Writes ``out`` (H, W, C) radiance, ``depth`` (H, W) hit distance in metres
    (inf for misses) and ``sky_mask`` (H, W) True where nothing was hit.

    Serial and GIL-free: every ray is independent, so callers split the columns over threads
    (:func:`bionav.world.render.render_ray_grid`) with identical results. It was a
    ``parallel=True`` kernel, whose compilation was most of a first run's wait (numba's parallel
    passes about doubled it).
    """
    C = out.shape[2]
    cands, counts, el_lo, el_hi, rho_min = _candidates(ox, oy, oz, az, 2.0 * pix_angle, prim_kind, prim_idx,
                                                       boxes, frusta, ells)
    _render_rows(ox, oy, oz, az, el, pix_angle, boxes, box_mats, frusta, frustum_mats, ells, ell_mats,
                 prim_kind, prim_idx, spheres, shadow_grids, shadow_starts, shadow_items,
                 mat_tex, mat_fit, mat_scale, mat_albedo, mat_emission, tex, tex_size,
                 light_params, light_power, amb_up, amb_down, shadows,
                 cands, counts, el_lo, el_hi, rho_min, np.empty(C), np.empty(C), out, depth, sky_mask)


@njit(cache=True, _nrt=False)
def _render_rows(ox, oy, oz, az, el, pix_angle, boxes, box_mats, frusta, frustum_mats, ells, ell_mats,
                 prim_kind, prim_idx, spheres, shadow_grids, shadow_starts, shadow_items,
                 mat_tex, mat_fit, mat_scale, mat_albedo, mat_emission, tex, tex_size,
                 light_params, light_power, amb_up, amb_down, shadows,
                 cands, counts, el_lo, el_hi, rho_min, E, Eg, out, depth, sky_mask):
    """The rays of :func:`render_kernel`, given its candidate lists and two scratch vectors ``E``, ``Eg`` (C,).

    Compiled without numba's reference counting (``_nrt=False``, as are the per-ray helpers it
    calls: they allocate nothing): with it, every call of a helper counted its array arguments up
    and down with atomic instructions, half the render's time in a serial kernel.
    """
    H = el.shape[0]
    W = az.shape[0]
    C = out.shape[2]
    nl = light_params.shape[0]
    for r in range(H):
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
            m = _material(kind, idx, face, box_mats, frustum_mats, ell_mats)
            tv = _texture_value(m, t, u, v, eu, ev, abs(nx * dx + ny * dy + nz * dz), pix_angle,
                                mat_tex, mat_fit, mat_scale, tex, tex_size)
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
                    lx, ly, lz, tmax, fac = _light_at(k, light_params, hx, hy, hz, nx, ny, nz)
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



@njit(cache=True, parallel=True)
def surface_kernel(ox, oy, oz, az, dirs, n_bins, boxes, box_mats, frusta, frustum_mats, ells, ell_mats,
                   prim_kind, prim_idx, spheres, shadow_grids, shadow_starts, shadow_items, light_params, light,
                   depth, point, normal, mat, lit):
    """Nearest surface along each ray of a list, and whether a light reaches it (for shading outside numba).

    Rays ``dirs`` (N, 3) (unit, world frame) start at ``(ox, oy, oz)``;
    ``az`` (N,) are their azimuths (``atan2(dy, dx)``, radians). The
    candidate primitives are listed per azimuth bin (``n_bins`` bins over the
    full circle, each list widened by half a bin), so the lists cost
    ``n_bins`` rows whatever the number of rays. Writes ``depth`` (N,)
    hit distance in metres (inf for misses), ``point`` (N, 3) the hit,
    ``normal`` (N, 3) the unit normal facing the ray, ``mat`` (N,) the material
    index (-1 for misses) and ``lit`` (N,) 1.0 where nothing casts a shadow
    between the hit (lifted 1 mm along the normal) and light ``light`` (an
    index into ``light_params``; -1: every hit is lit), else 0.0.
    """
    N = dirs.shape[0]
    width = 2.0 * math.pi / n_bins
    centres = (np.arange(n_bins) + 0.5) * width
    cands, counts, el_lo, el_hi, rho_min = _candidates(ox, oy, oz, centres, 0.5 * width + 1e-9, prim_kind,
                                                       prim_idx, boxes, frusta, ells)
    for n in prange(N):  # rays are independent: the result does not depend on the number of threads
        dx = dirs[n, 0]
        dy = dirs[n, 1]
        dz = dirs[n, 2]
        el = math.asin(min(1.0, max(-1.0, dz)))
        b = min(int((az[n] % (2.0 * math.pi)) / width), n_bins - 1)
        t, kind, idx, face = _trace(ox, oy, oz, dx, dy, dz, el, cands, b, counts[b], el_lo, el_hi,
                                    rho_min, prim_kind, prim_idx, boxes, frusta, ells)
        if kind < 0:
            depth[n] = np.inf
            for a in range(3):
                point[n, a] = 0.0
                normal[n, a] = 0.0
            mat[n] = -1
            lit[n] = 0.0
            continue
        hx, hy, hz, nx, ny, nz, _, _, _, _ = _surface(kind, idx, face, t, ox, oy, oz, dx, dy, dz,
                                                      boxes, frusta, ells)
        m = _material(kind, idx, face, box_mats, frustum_mats, ell_mats)
        shaded = False
        if light >= 0:
            shaded = _occluded(light, hx + 1e-3 * nx, hy + 1e-3 * ny, hz + 1e-3 * nz, light_params[light, 1],
                               light_params[light, 2], light_params[light, 3], INF, light_params,
                               shadow_grids, shadow_starts, shadow_items, prim_kind, prim_idx, spheres,
                               boxes, frusta, ells)
        depth[n] = t
        point[n, 0] = hx
        point[n, 1] = hy
        point[n, 2] = hz
        normal[n, 0] = nx
        normal[n, 1] = ny
        normal[n, 2] = nz
        mat[n] = m
        lit[n] = 0.0 if shaded else 1.0
