"""signature=zernike (Sun, Yue & Mangan 2020): orthogonality, rotation invariance, heading from phases, homing."""

from __future__ import annotations

import numpy as np
import pytest

from bionav.db.mesh import mesh_world, seville_world_path
from bionav.errors import UserError
from bionav.geometry import PanoramaGeometry, angular_difference
from bionav.homing.signatures.zernike import radial_polynomial, zernike_indices, zernike_moments
from bionav.plugins.signatures.zernike import Zernike
from bionav.world.mesh_render import render_mesh_panorama


def test_indices_and_radial_polynomials_closed_forms():
    assert zernike_indices(2).tolist() == [[0, 0], [1, 1], [2, 0], [2, 2]]
    rho = np.linspace(0, 1, 11)
    np.testing.assert_allclose(radial_polynomial(2, 0, rho), 2 * rho ** 2 - 1)
    np.testing.assert_allclose(radial_polynomial(4, 2, rho), 4 * rho ** 4 - 3 * rho ** 2)
    # orthogonality: int_0^1 R_n^m R_n'^m rho drho = delta / (2 (n + 1))
    x = (np.arange(20000) + 0.5) / 20000
    for n, n2, m in [(2, 4, 0), (3, 5, 1), (4, 4, 2), (6, 6, 0)]:
        val = np.sum(radial_polynomial(n, m, x) * radial_polynomial(n2, m, x) * x) / 20000
        assert val == pytest.approx(1 / (2 * (n + 1)) if n == n2 else 0.0, abs=1e-6)


def test_moments_of_a_known_image():
    # a uniform disc: Z_00 = (1/pi) * area = 1 exactly; every moment with m > 0 vanishes
    z, idx = zernike_moments(np.ones((50, 64)), order=6)
    assert z[0] == pytest.approx(1.0)
    assert np.abs(z[idx[:, 1] > 0]).max() < 1e-12
    # one bright column at theta = 2 pi j / W: the phase of Z_nm is -m theta
    img = np.zeros((30, 64))
    img[:, 16] = 1.0
    z, idx = zernike_moments(img, order=5)
    sel = (idx[:, 0] == 3) & (idx[:, 1] == 3)
    assert np.angle(z[sel][0]) == pytest.approx(np.angle(np.exp(-3j * 2 * np.pi * 16 / 64)))


@pytest.fixture(scope="module")
def views():
    world = mesh_world(seville_world_path())
    g = PanoramaGeometry.square_pixels(180, 30)
    v0 = render_mesh_panorama(world, position=(4.0, 6.0, 0.05), geometry=g)[..., 0]
    return world, g, v0


def test_amplitudes_rotation_invariant_and_phases_give_heading(views):
    world, g, v0 = views
    sig = Zernike()
    a0 = sig.compute(v0)
    for k in (1, 23, 90, 151):
        rolled = np.roll(v0, -k, axis=1)  # the view at heading 2 pi k / W
        np.testing.assert_allclose(sig.compute(rolled), a0, rtol=1e-10, atol=1e-12)
        est = sig.rotation(rolled, v0)
        assert angular_difference(est, 2 * np.pi * k / 180) < 1e-3
    # a heading that is not a whole column: rendered, not rolled
    h = 1.234
    vh = render_mesh_panorama(world, position=(4.0, 6.0, 0.05), heading=h, geometry=g)[..., 0]
    assert angular_difference(sig.rotation(vh, v0), h) < np.deg2rad(3)
    assert np.abs(sig.compute(vh) - a0).max() < 0.05 * np.abs(a0).max()
    # skyline mode: moments of the binary sky mask
    sky = Zernike({"mode": "skyline", "threshold": 0.7})
    assert angular_difference(sky.rotation(np.roll(v0, -40, 1), v0), 2 * np.pi * 40 / 180) < 1e-3


def test_zernike_potential_grows_away_from_the_snapshot_and_drives_parameter_homing(views):
    from bionav.plugins.homing.parameter import ParameterHoming

    world, g, _v0 = views
    sig = Zernike()

    def f(x, y, heading=0.0):
        return sig.compute(render_mesh_panorama(world, position=(x, y, 0.05), heading=heading, geometry=g)[..., 0])

    snap = f(4.0, 6.0)
    angles = np.arange(8) * np.pi / 4

    def mean_potential(d):  # current views at arbitrary headings: the amplitudes need no alignment
        return np.mean([np.sum((f(4 + d * np.cos(a), 6 + d * np.sin(a), heading=1.7 * a) - snap) ** 2) for a in angles])

    assert mean_potential(0.05) < 0.7 * mean_potential(0.2)  # measured ratio 0.44 (catchment ~0.2 m at 5 cm height)
    homing = ParameterHoming({"gradient": "test_steps"}, geometry=g, signature=sig)
    assert not homing.requires_alignment and homing.uses_test_steps
    prep = {d: homing.prepare(render_mesh_panorama(world, position=(4.1 + 0.05 * d[0], 6.0 + 0.05 * d[1], 0.05),
                                                   geometry=g)[..., 0])
            for d in [(0, 0), (1, 0), (-1, 0), (0, 1), (0, -1)]}
    hv = homing.home_vector({"f": snap}, prep[(0, 0)], neighbours={d: p for d, p in prep.items() if d != (0, 0)})
    assert hv.valid and hv.extras["potential"] > 0


def test_bad_zernike_options():
    with pytest.raises(UserError, match="signature.order"):
        Zernike({"order": 0})
    with pytest.raises(UserError, match="signature.mode"):
        Zernike({"mode": "edges"})
    with pytest.raises(UserError, match="signature.threshold"):
        Zernike({"threshold": 2.0})


def test_zernike_indices_refuses_an_order_outside_0_to_60():
    """The function's own argument check (signature.order is checked against its declared 1..40 on the way in)."""
    assert len(zernike_indices(60)) == 61 * 62 // 2 - sum((n + 1) // 2 for n in range(61))
    with pytest.raises(ValueError, match=r"order must lie in 0\.\.60 .*, got 61"):
        zernike_indices(61)
