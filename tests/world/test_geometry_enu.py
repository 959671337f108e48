"""The ENU section of bionav.geometry: one argument order, closed-form values."""

import numpy as np

from bionav.geometry import (
    angles_from_direction,
    azimuth_to_compass,
    compass_to_azimuth,
    direction_from_angles,
    parabolic_peak_offset,
    wrap_axial,
)


def test_direction_from_angles_known_directions():
    np.testing.assert_allclose(direction_from_angles(0.0, 0.0), [1.0, 0.0, 0.0], atol=1e-15)  # east
    np.testing.assert_allclose(direction_from_angles(np.pi / 2, 0.0), [0.0, 1.0, 0.0], atol=1e-15)  # north
    np.testing.assert_allclose(direction_from_angles(1.0, np.pi / 2), [0.0, 0.0, 1.0], atol=1e-15)  # zenith
    d = direction_from_angles(np.pi / 4, np.pi / 6)
    np.testing.assert_allclose(d, [np.cos(np.pi / 6) / np.sqrt(2), np.cos(np.pi / 6) / np.sqrt(2), 0.5], atol=1e-15)


def test_angles_round_trip_and_broadcast():
    az = np.linspace(-3.0, 3.0, 7)
    el = np.linspace(-1.2, 1.2, 7)
    d = direction_from_angles(az[:, None], el[None, :])
    assert d.shape == (7, 7, 3)
    np.testing.assert_allclose(np.linalg.norm(d, axis=-1), 1.0, atol=1e-15)
    a, e = angles_from_direction(d)
    np.testing.assert_allclose(a, np.broadcast_to(az[:, None], (7, 7)), atol=1e-12)
    np.testing.assert_allclose(e, np.broadcast_to(el[None, :], (7, 7)), atol=1e-12)


def test_compass_bearings():
    # north is bearing 0 and azimuth pi/2; east is bearing pi/2 and azimuth 0; west bearing 3pi/2
    np.testing.assert_allclose(compass_to_azimuth([0.0, np.pi / 2, 3 * np.pi / 2]), [np.pi / 2, 0.0, -np.pi])
    np.testing.assert_allclose(azimuth_to_compass([np.pi / 2, 0.0, -np.pi / 2]), [0.0, np.pi / 2, np.pi])
    b = np.linspace(0.0, 2 * np.pi, 9, endpoint=False)
    np.testing.assert_allclose(azimuth_to_compass(compass_to_azimuth(b)), b, atol=1e-12)


def test_wrap_axial_period_pi():
    np.testing.assert_allclose(wrap_axial([0.0, np.pi, np.pi / 2, -np.pi / 2, 2.0]),
                               [0.0, 0.0, -np.pi / 2, -np.pi / 2, 2.0 - np.pi])


def test_parabolic_peak_offset_is_the_vertex_of_three_samples():
    """Samples of -(x - v)^2 + 2 at x = -1, 0, 1 put the vertex at v, for a scalar and for arrays."""
    v = np.array([0.3, -0.45, 0.0, 0.5])
    y = [-(x - v) ** 2 + 2.0 for x in (-1.0, 0.0, 1.0)]
    np.testing.assert_allclose(parabolic_peak_offset(*y), v, atol=1e-12)
    assert float(parabolic_peak_offset(1.0, 3.0, 2.0)) == 0.5 * (1.0 - 2.0) / (1.0 - 6.0 + 2.0)  # 1/6 by hand
    assert float(parabolic_peak_offset(1.0, 1.0, 1.0)) == 0.0  # flat: no peak
    assert float(parabolic_peak_offset(2.0, 1.0, 3.0)) == 0.0  # bends up: no peak (negate for a minimum)
    assert float(parabolic_peak_offset(-2.0, -1.0, -3.0)) == 0.5 * (-2.0 + 3.0) / (-2.0 + 2.0 - 3.0)
