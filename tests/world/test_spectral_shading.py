"""The spectral scenes render through the world kernels: surfaces and shadows against the NumPy reference."""

import numpy as np
import pytest

from bionav.geometry import direction_from_angles
from bionav.light.bands import PEAK_NM, band_integrate
from bionav.light.clouds import CloudLayer
from bionav.light.daylight import (
    SkyState,
    aerosol_optical_depth,
    band_sky_radiance,
    illumination,
    rayleigh_optical_depth,
)
from bionav.light.materials import MATERIALS
from bionav.world.intersect import trace_depth_reference
from bionav.world.lights import DirectionalLight
from bionav.world.scene import Scene
from bionav.world.spectral_shading import spectral_radiance, trace_surfaces
from bionav.world.worlds.garden import backyard_scene, garden_scene


def _rays(n, seed):
    d = np.random.default_rng(seed).normal(size=(n, 3))
    return d / np.linalg.norm(d, axis=1, keepdims=True)


@pytest.mark.parametrize("build", [garden_scene, backyard_scene])
def test_surfaces_of_the_spectral_scenes_match_the_numpy_reference(build):
    scene = build(SkyState(np.deg2rad(40.0), np.deg2rad(-60.0)), seed=1)
    cs = scene._geometry.compiled()
    origin = scene.origin((0.7, 1.3))
    d = _rays(3000, 2)
    hits = trace_surfaces(cs, origin, d)
    want = trace_depth_reference(origin, d, cs.boxes, cs.frusta, cs.ellipsoids)
    np.testing.assert_allclose(hits["depth"], want, rtol=1e-9, atol=1e-9)
    hit = np.isfinite(want)
    assert 0.2 < hit.mean() < 0.95  # sky above, ground and objects below
    np.testing.assert_allclose(hits["point"][hit], origin + want[hit, None] * d[hit], atol=1e-6)
    assert np.all(np.sum(hits["normal"][hit] * d[hit], axis=1) <= 1e-12)  # normals face the ray
    np.testing.assert_allclose(np.linalg.norm(hits["normal"][hit], axis=1), 1.0, atol=1e-9)
    assert np.all(hits["material"][~hit] == -1) and np.all(hits["material"][hit] >= 0)


def test_sun_shadow_of_a_box_on_the_ground():
    scene = Scene()
    ground = scene.material(kind="grass")
    roof = scene.material(kind="concrete")
    scene.box((-50, -50, -1), (50, 50, 0), ground, shadow=False)
    scene.box((-1, -1, 2), (1, 1, 3), roof)  # a slab hovering 2-3 m above the origin
    sun = np.array([0.0, 0.0, 1.0])
    scene.add_light(DirectionalLight(tuple(sun), 1.0))
    origin = (0.0, -10.0, 1.0)
    targets = np.array([[0.0, 0.0, 0.0], [0.9, 0.5, 0.0], [1.2, 0.0, 0.0], [0.0, 5.0, 0.0]])  # under it, under, beside
    d = targets - origin
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    hits = trace_surfaces(scene, origin, d, light=0)
    np.testing.assert_allclose(hits["point"], targets, atol=1e-9)
    np.testing.assert_array_equal(hits["lit"], [0.0, 0.0, 1.0, 1.0])
    np.testing.assert_array_equal(hits["material"], [ground] * 4)
    assert np.all(trace_surfaces(scene, origin, d)["lit"] == 1.0)  # no light traced: all lit


def test_spectral_radiance_of_sunlit_ground_by_hand():
    """A horizontal surface: L = tex int S rho (lit sin(h) E_dir + E_dif) / pi, times the air's
    transmittance exp(-beta t) plus the horizon sky (2 deg up in the ray's azimuth) times the rest."""
    sky = SkyState(np.deg2rad(35.0), np.deg2rad(30.0), clouds=CloudLayer(cover=0.0))
    ill = illumination(sky)
    rho = MATERIALS["concrete"].mean_spectrum()[None, :]
    d = np.array([[0.0, 0.8, -0.6], [0.0, 0.0, 1.0]])
    t = 2000.0  # far enough for the air to matter
    hits = {"depth": np.array([t, np.inf]), "point": np.array([[0.0, 1600.0, 0.0], [0, 0, 0]]),
            "normal": np.array([[0.0, 0.0, 1.0], [0, 0, 0]]), "material": np.array([0, -1]),
            "lit": np.array([1.0, 0.0])}
    kw = dict(spectra=rho, surface=np.array([0, 0]), texture=np.array([1.3, 1.0]), foliage=np.array([False, False]),
              sky=sky, illumination=ill)
    out = spectral_radiance(hits, d, **kw)
    shaded = spectral_radiance({**hits, "lit": np.array([0.0, 0.0])}, d, **kw)
    beta = (rayleigh_optical_depth(np.asarray(PEAK_NM)) / 8000.0
            + aerosol_optical_depth(np.asarray(PEAK_NM), beta=sky.turbidity) / 1200.0)
    trans = np.exp(-beta * t)
    assert np.all((trans > 0.3) & (trans < 0.95))
    horizon = band_sky_radiance(sky, direction_from_angles(np.pi / 2, np.deg2rad(2.0)))
    mu = np.sin(np.deg2rad(35.0))
    lit = 1.3 * band_integrate(rho[0] * (mu * ill.direct_normal + ill.diffuse_horizontal)) / np.pi
    dark = 1.3 * band_integrate(rho[0] * ill.diffuse_horizontal) / np.pi
    np.testing.assert_allclose(out[0], lit * trans + horizon * (1 - trans), rtol=1e-9)
    np.testing.assert_allclose(shaded[0], dark * trans + horizon * (1 - trans), rtol=1e-9)
    np.testing.assert_allclose(out[1], band_sky_radiance(sky, d[1:])[0], rtol=1e-12)  # a miss sees the sky
