"""Known-answer tests of the warping building blocks: magnification, templates, filters, signs."""

import numpy as np
import pytest

from bionav.geometry import PanoramaGeometry
from bionav.homing.imageops import butterworth_lowpass, horizon_strip, resize_panorama
from bionav.homing.imageops import vertical_difference as edge_filter  # the scale planes' vertical edge filter
from bionav.homing.warping import (
    default_scales,
    default_thresholds,
    magnify_vertical,
    minwarping,
    scale_plane_stack,
    warping1d,
    warping2d,
)
from bionav.homing.warping.templates import minwarp_template, warp2d_template


def test_default_scales_and_thresholds():
    s = default_scales()
    np.testing.assert_allclose(s, 2.0 ** ((np.arange(9) - 4) / 4))
    tau = default_thresholds(s)
    assert np.all(s[:-1] < tau[:-1]) and np.all(tau[:-1] < s[1:]) and np.isinf(tau[-1])


def test_magnification_follows_the_tangent_law():
    g = PanoramaGeometry(8, 41, 20.0, 0.02)  # +-0.4 rad
    elev = g.row_elevations()
    image = np.repeat(elev[:, None], 8, axis=1).astype(np.float32)  # each pixel shows its elevation
    for m in (1.5, 2.0):
        out = magnify_vertical(image, factor=m, geometry=g)
        np.testing.assert_allclose(out[:, 0], np.arctan(np.tan(elev) / m), atol=2e-3)
    np.testing.assert_array_equal(magnify_vertical(image, factor=1.0, geometry=g), image)


def test_scale_planes_roles():
    g = PanoramaGeometry.square_pixels(16, 9)
    img = np.random.default_rng(0).random((9, 16)).astype(np.float32)
    st = scale_plane_stack(img, geometry=g, scales=[0.5, 1.0, 2.0])
    unit = edge_filter(img)
    np.testing.assert_array_equal(st["snap"][0], unit)  # sigma < 1: snapshot unmagnified
    np.testing.assert_array_equal(st["cur"][2], unit)  # sigma > 1: current view unmagnified
    np.testing.assert_allclose(st["snap"][2], edge_filter(magnify_vertical(img, factor=2.0, geometry=g)))
    np.testing.assert_allclose(st["cur"][0], edge_filter(magnify_vertical(img, factor=2.0, geometry=g)))
    np.testing.assert_allclose(st["snap_norm"], np.abs(st["snap"]).sum(axis=1), rtol=1e-6)


def test_edge_filter_is_the_column_difference():
    img = np.array([[0.0, 1.0], [2.0, 1.0], [5.0, 0.0]], dtype=np.float32)
    np.testing.assert_array_equal(edge_filter(img), [[2.0, 0.0], [3.0, -1.0]])


def test_minwarp_template_hand_checked():
    w = 8
    s = np.array([0.5, 1.0, 2.0])
    vlo, vhi, klo, khi = minwarp_template(w, s, [0.8, 1.3, np.inf])
    # u = 1 (45 deg): reachable v = 1 .. 4 (45 .. 180 deg)
    assert (vlo[1], vhi[1]) == (1, 4)
    # u = 6 (270 deg): reachable v = 4 .. 6
    assert (vlo[6], vhi[6]) == (4, 6)
    # v = u: infinitely far landmark, sigma = 1 -> unit plane
    assert all(klo[u, u] == khi[u, u] == 1 for u in (1, 2, 3, 5, 6, 7))
    # u = 1, v = 2: sigma = sin 90 / sin 45 = 1.41 -> plane 2
    assert klo[1, 2] == khi[1, 2] == 2
    # u = 1, v = 3: sigma = sin 135 / sin 45 = 1 -> plane 1
    assert klo[1, 3] == khi[1, 3] == 1
    # u = 2, v = 3: sigma = sin 135 / sin 90 = 0.71 -> plane 0
    assert klo[2, 3] == khi[2, 3] == 0
    # v = 4 (180 deg): sigma -> 0 -> plane 0
    assert klo[1, 4] == khi[1, 4] == 0
    # unreachable: u = 2, v = 1 (a landmark never drifts towards the focus of expansion)
    assert klo[2, 1] > khi[2, 1]
    # focus of expansion / contraction: every plane with sigma >= 1 / <= 1
    assert (klo[0, 0], khi[0, 0]) == (1, 2)
    assert (klo[4, 4], khi[4, 4]) == (0, 1)


def test_minwarp_template_excludes_scales_beyond_the_last_threshold():
    s = np.array([0.5, 1.0, 1.5])
    tau = np.array([0.75, 1.25, 1.75])
    vlo, vhi, klo, khi = minwarp_template(8, s, tau)
    assert klo[1, 2] == khi[1, 2] == 2  # sigma = 1.41 lies in [1.25, 1.75)
    w = 24
    vlo, vhi, klo, khi = minwarp_template(w, s, tau)
    sigma = np.sin(2 * np.pi * 6 / w) / np.sin(2 * np.pi * 1 / w)  # 3.86
    assert sigma > 1.75 and klo[1, 6] > khi[1, 6]


def test_warp2d_template_closed_form():
    w = 36
    v, k = warp2d_template(w, [0.0, 0.5], default_thresholds(default_scales()))
    np.testing.assert_array_equal(v[0], np.arange(w))  # no movement: no shift
    assert np.all(k[0] == 4)  # sigma = 1
    # rho = 0.5, theta = 90 deg: theta' = atan2(1, -0.5) = 116.6 deg, sigma = 1/sqrt(1.25) = 0.894
    assert v[1, 9] == round(np.degrees(np.arctan2(1, -0.5)) / 10)
    s = default_scales()
    tau = default_thresholds(s)
    assert k[1, 9] == np.searchsorted(tau, 1 / np.sqrt(1.25), side="right")
    # theta = 0 (landmark ahead): sigma = 1 / (1 - rho) = 2 -> last plane
    assert v[1, 0] == 0 and k[1, 0] == 8


def test_butterworth_keeps_constants_and_removes_fine_detail():
    img = np.full((10, 32), 0.3, dtype=np.float32)
    np.testing.assert_allclose(butterworth_lowpass(img, cutoff=0.1), 0.3, atol=1e-6)
    x = np.arange(32)
    stripes = np.tile(0.5 + 0.5 * np.cos(np.pi * x), (10, 1)).astype(np.float32)  # Nyquist
    out = butterworth_lowpass(stripes, cutoff=0.1, order=3)
    np.testing.assert_allclose(out, 0.5, atol=1e-3)
    with pytest.raises(ValueError):
        butterworth_lowpass(img, cutoff=0.0)


def test_resize_updates_geometry_and_strip_takes_the_horizon():
    g = PanoramaGeometry.square_pixels(64, 21)
    img = np.zeros((21, 64), np.float32)
    img[10] = 1.0
    out, g2 = resize_panorama(img, geometry=g, size=[32, 21])
    assert out.shape == (21, 32) and g2.width == 32 and g2.rad_per_row == g.rad_per_row
    np.testing.assert_allclose(horizon_strip(out, geometry=g2, rows=1), 1.0)
    np.testing.assert_allclose(horizon_strip(out, geometry=g2, rows=5), 0.2)


@pytest.mark.parametrize("shift", [0, 5, -7, 20])
def test_rolled_view_gives_psi_equal_to_the_roll(shift):
    """A current view rotated by psi at the snapshot position is the snapshot rolled by -psi."""
    w, h = 48, 12
    rng = np.random.default_rng(shift + 10)
    g = PanoramaGeometry.square_pixels(w, h)
    import cv2

    snap = cv2.GaussianBlur(rng.random((h, w)).astype(np.float32), (0, 0), 1.0)
    cur = np.roll(snap, -shift, axis=1)
    psi = 2 * np.pi * shift / w
    wrap = lambda a: (a + np.pi) % (2 * np.pi) - np.pi  # noqa: E731
    S, C = scale_plane_stack(snap, geometry=g), scale_plane_stack(cur, geometry=g)
    for r in (
        minwarping(S, C, n_alpha=48, n_psi=48),
        minwarping(S, C, n_alpha=24, n_psi=48, compass_fraction=0.2),
        warping2d(S, C, n_alpha=48, n_psi=48, n_rho=4),
    ):
        assert abs(wrap(r.psi - psi)) < 1e-9
    s1, s2 = horizon_strip(snap, geometry=g), horizon_strip(cur, geometry=g)
    r = warping1d(s1, s2, n_alpha=12, n_psi=48, n_rho=4)
    assert abs(wrap(r.psi - psi)) < 1e-9 and r.rho == 0.0
