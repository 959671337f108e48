"""Spectral shading of ray-cast surfaces under spectral daylight (five sensor bands).

The geometry goes through the renderer's numba kernels (:func:`trace_surfaces`:
:func:`bionav.world.kernels.surface_kernel`, the same intersections and hard
shadows as :func:`bionav.world.render.render_panorama`); the light is the
spectral daylight of :mod:`bionav.light.daylight` and the reflectance the
measured or tabulated spectra of :mod:`bionav.light.materials`.
:func:`spectral_radiance` shades the hits:

``L_b = tex * int S_b rho (sunlit * cos_i * E_dir + (1 + n_z)/2 * E_diff + (1 - n_z)/2 * a_g * E_glob) dlambda / pi``

attenuated towards the sensor by the air (extinction per band) plus airlight
(the sky radiance 2 degrees above the horizon in the ray's azimuth); ``S_b`` is
the channel sensitivity, ``a_g = 0.15`` the ground's albedo, foliage is lit in
patches (sun flecks). Lines of sight that hit nothing get the sky radiance with
clouds (:func:`bionav.light.daylight.band_sky_radiance`).

Frame: east-north-up, metres; radiances in W m^-2 sr^-1 nm^-1 integrated over
each band's sensitivity (the sensor model's unit).
"""

from __future__ import annotations

import numpy as np

from bionav.geometry import direction_from_angles
from bionav.light.bands import PEAK_NM, band_integrate
from bionav.light.daylight import Illumination, SkyState, aerosol_optical_depth, band_sky_radiance, rayleigh_optical_depth
from bionav.world.kernels import surface_kernel
from bionav.world.render import _run_threads
from bionav.world.scene import CompiledScene, Scene

#: Grey albedo of the ground that lights surfaces tilted towards it.
GROUND_ALBEDO = 0.15
#: Azimuth bins of the candidate lists of :func:`trace_surfaces` (one per degree).
AZIMUTH_BINS = 360


def trace_surfaces(scene: Scene | CompiledScene, origin, directions, *, light: int = -1,
                   threads: int | None = 1) -> dict:
    """The nearest surface along each ray, and whether a light reaches it.

    Parameters
    ----------
    scene : Scene or CompiledScene
    origin : array_like, shape (3,)
        Ray origin ``(x, y, z)`` in metres.
    directions : array_like, shape (N, 3)
        Unit ray directions (world frame).
    light : int
        Index of the light (in ``scene.lights``) whose hard shadows to trace;
        -1: none (every hit counts as lit).
    threads : int or None
        Threads of the ray-parallel kernel (``None``: numba's default); one by
        default, as :func:`bionav.world.render.render_panorama`. Results are
        identical for any number of threads.

    Returns
    -------
    dict
        ``depth`` (N,) metres (inf for misses), ``point`` (N, 3), ``normal``
        (N, 3) unit normal facing the ray, ``material`` (N,) material index
        (-1 for misses), ``lit`` (N,) 1.0 where the light is not blocked, else 0.0.
    """
    cs = scene if isinstance(scene, CompiledScene) else scene.compiled()
    d = np.ascontiguousarray(np.asarray(directions, np.float64).reshape(-1, 3))
    n = d.shape[0]
    az = np.ascontiguousarray(np.arctan2(d[:, 1], d[:, 0]))
    out = {"depth": np.empty(n), "point": np.empty((n, 3)), "normal": np.empty((n, 3)),
           "material": np.empty(n, np.int64), "lit": np.empty(n)}
    ox, oy, oz = (float(v) for v in origin)
    _run_threads(threads, surface_kernel, ox, oy, oz, az, d, AZIMUTH_BINS, cs.boxes, cs.box_mats, cs.frusta,
                 cs.frustum_mats, cs.ellipsoids, cs.ellipsoid_mats, cs.prim_kind, cs.prim_idx, cs.spheres,
                 *cs.shadow_bins(), cs.light_params, int(light), out["depth"],
                 out["point"], out["normal"], out["material"], out["lit"])
    return out


def spectral_radiance(hits: dict, directions, *, spectra: np.ndarray, surface: np.ndarray, texture: np.ndarray,
                      foliage: np.ndarray, sky: SkyState, illumination: Illumination,
                      origin_m=(0.0, 0.0)) -> np.ndarray:
    """Band radiance ``(N, 5)`` along rays whose surfaces :func:`trace_surfaces` found.

    Parameters
    ----------
    hits : dict
        :func:`trace_surfaces`' result for the rays (its ``lit`` for the sun).
    directions : array_like, shape (N, 3)
        The rays' unit directions (east-north-up).
    spectra : ndarray, shape (M, L)
        Reflectance spectra on :data:`~bionav.light.bands.WAVELENGTHS_NM`.
    surface : ndarray of int, shape (N,)
        Row of ``spectra`` of each hit surface (any value for misses).
    texture : ndarray, shape (N,)
        Multiplicative texture at each hit.
    foliage : ndarray of bool, shape (N,)
        Hits on foliage (lit by the sun in flecks).
    sky : SkyState
        The sky (sun direction, turbidity, clouds).
    illumination : Illumination
        :func:`bionav.light.daylight.illumination` of ``sky`` at the observer.
    origin_m : tuple of float
        Observer position (east, north), metres (parallax of the clouds).

    Returns
    -------
    ndarray, shape (N, 5)
        Band radiance; the sky's where nothing was hit.
    """
    d = np.asarray(directions, dtype=float).reshape(-1, 3)
    depth = hits["depth"]
    sky_ray = ~np.isfinite(depth)
    out = np.zeros((d.shape[0], 5))
    if np.any(sky_ray):
        out[sky_ray] = band_sky_radiance(sky, d[sky_ray], origin_m=origin_m)
    hit = ~sky_ray
    if not np.any(hit):
        return out
    ill = illumination
    # per spectrum and channel: int S_b rho E dlambda of each light component, shape (M, 5)
    m = surface[hit]
    e_dir = band_integrate(spectra * ill.direct_normal)[m]
    e_dif = band_integrate(spectra * ill.diffuse_horizontal)[m]
    e_glob = band_integrate(spectra * ill.global_horizontal)[m]
    p = hits["point"][hit]
    n = hits["normal"][hit]
    sun = sky.sun_direction
    cos_i = np.clip(n @ sun, 0, None)
    lit = hits["lit"][hit] if sun[2] > 0 else np.ones(p.shape[0])
    fleck = 0.5 + 0.5 * np.sin(p @ np.array([3.1, 2.3, 4.7]) + np.sin(p @ np.array([1.3, -2.9, 0.7])) * 2)
    lit = np.where(foliage[hit], lit * fleck, lit)
    sky_view = (1 + n[:, 2:3]) / 2
    refl_irr = lit[:, None] * cos_i[:, None] * e_dir + sky_view * e_dif + (1 - sky_view) * GROUND_ALBEDO * e_glob
    rad = texture[hit][:, None] * refl_irr / np.pi
    beta = (rayleigh_optical_depth(np.asarray(PEAK_NM)) / 8000.0
            + aerosol_optical_depth(np.asarray(PEAK_NM), beta=sky.turbidity) / 1200.0)
    trans = np.exp(-beta * depth[hit, None])
    az = np.arctan2(d[hit, 1], d[hit, 0])
    horizon = band_sky_radiance(sky, direction_from_angles(az, np.deg2rad(2.0)), origin_m=origin_m)
    out[hit] = rad * trans + horizon * (1 - trans)
    return out
