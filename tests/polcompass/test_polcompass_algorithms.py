"""Compass algorithms: eqs. 4.2-4.6, least squares, calibration, error function."""

import numpy as np
import pytest

from bionav.geometry import wrap_axial
from bionav.light import SkyModel, SunPosition
from bionav.polcompass import (
    ChainParameters,
    CompassOptics,
    CompassScene,
    EvectorPredictor,
    SimulatedCompassHardware,
    UnitCalibration,
    calibrate_from_rotation,
    candidate_pair,
    choose_candidate,
    counts_to_volts,
    delogarithmise,
    fit_scan_heading,
    heading_errors,
    least_squares_evector,
    sample_mismatch,
    solve_pose,
    two_unit_evector,
    volts_to_decades,
    zenith_heading,
)
from bionav.polcompass.optics import cone_samples, sensor_frame

ALPHA = np.array([0.0, np.pi / 3, 2 * np.pi / 3])


def test_delogarithmise_inverts_eq_4_2():
    # x = d cos(...) = 0.5  ->  p = log10(1.5 / 0.5) = log10(3) decades
    assert delogarithmise(np.log10(3.0)) == pytest.approx(0.5)
    assert delogarithmise(0.0) == 0.0
    x = np.linspace(-0.95, 0.95, 21)
    np.testing.assert_allclose(delogarithmise(np.log10((1 + x) / (1 - x))), x, atol=1e-12)
    # The log-ratio amplifier at 0.5 V/decade around 2.5 V: 3.0 V is one decade.
    assert volts_to_decades(3.0) == pytest.approx(1.0)


@pytest.mark.parametrize("angle", np.linspace(-np.pi / 2, np.pi / 2, 13, endpoint=False))
@pytest.mark.parametrize("degree", [0.05, 0.4, 0.9])
def test_two_unit_and_least_squares_recover_angle_exactly(angle, degree):
    x = degree * np.cos(2 * angle - 2 * ALPHA)
    for i, j in [(0, 1), (1, 2), (0, 2)]:
        a, d = two_unit_evector(x[i], x[j], ALPHA[i], ALPHA[j])
        assert wrap_axial(a - angle) == pytest.approx(0.0, abs=1e-12)
        assert d == pytest.approx(degree)
    a, d = least_squares_evector(x, ALPHA)
    assert wrap_axial(a - angle) == pytest.approx(0.0, abs=1e-12)
    assert d == pytest.approx(degree)


def test_eq_4_4_ratio_form_matches():
    angle, degree = 0.3, 0.5
    x = degree * np.cos(2 * angle - 2 * ALPHA)
    f = x[0] / x[1]
    tan2 = (f * np.cos(2 * ALPHA[1]) - np.cos(2 * ALPHA[0])) / (np.sin(2 * ALPHA[0]) - f * np.sin(2 * ALPHA[1]))
    assert np.tan(2 * angle) == pytest.approx(tan2)


def test_candidate_pair_eq_4_6_and_choice():
    a, b = candidate_pair(np.array([0.4, -0.4, 0.0]))
    np.testing.assert_allclose(b, [0.4 - np.pi, -0.4 + np.pi, -np.pi])
    chosen, resolved = choose_candidate(a, b, np.array([1.0, 0.2, 0.5]), np.array([0.1, 0.3, 0.5]), margin=0.01)
    np.testing.assert_allclose(chosen, [b[0], a[1], a[2]])
    np.testing.assert_array_equal(resolved, [True, True, False])


def test_heading_errors_remove_offset_and_axial():
    ref = np.linspace(-np.pi, np.pi, 8, endpoint=False)
    est = ref + 0.2 + np.array([0.01, -0.01, 0.0, 0.0, 0.02, -0.02, 0.0, 0.0])
    est[3] += np.pi  # half-turn flip: invisible when axial
    e = heading_errors(est, ref, axial=True)
    assert e.offset == pytest.approx(0.2, abs=1e-12)
    # Symmetric perturbations leave the offset at 0.2; errors are the perturbations.
    assert e.rmse_deg == pytest.approx(np.degrees(np.sqrt((2 * 0.01**2 + 2 * 0.02**2) / 8)), rel=1e-9)
    assert e.mae_deg == pytest.approx(np.degrees(0.06 / 8))
    full = heading_errors(est, ref, axial=False, remove_offset=False)
    assert np.max(np.abs(full.errors)) == pytest.approx(np.pi - 0.2, abs=1e-9)


def test_cone_samples_and_sensor_frame():
    d, w = cone_samples(np.deg2rad(10.0))
    assert w.sum() == pytest.approx(1.0)
    assert np.all(d[:, 2] >= np.cos(np.deg2rad(10.0)))
    f = sensor_frame(0.3, 0.2)
    np.testing.assert_allclose(f.T @ f, np.eye(3), atol=1e-12)
    assert np.linalg.det(f) == pytest.approx(1.0)
    np.testing.assert_allclose(sensor_frame(0.3, 0.0)[:, 0], [np.cos(0.3), np.sin(0.3), 0.0])


def _rotation_readings(hardware, scene, pans, rng=None, n=1):
    volts = []
    for p in pans:
        scene.set_pose(p, 0.0)
        volts.append(hardware.volts(scene, rng, n=n))
    return np.concatenate(volts)


def test_compass_recovers_headings_exactly_from_noiseless_readings():
    sky = SkyModel(SunPosition(np.deg2rad(40.0), np.deg2rad(30.0)))
    hardware = SimulatedCompassHardware()
    scene = CompassScene(sky, mount_heading=0.3)
    pans = np.deg2rad(np.arange(-159.0, 160.0, 3.0))
    volts = _rotation_readings(hardware, scene, pans)
    cal = UnitCalibration.nominal()
    x = delogarithmise(volts_to_decades(volts, center_v=cal.center_v, volts_per_decade=cal.volts_per_decade))
    angle, degree = least_squares_evector(x, cal.unit_angles)
    heading = zenith_heading(angle, sun_azimuth=sky.sun.azimuth)
    np.testing.assert_allclose(wrap_axial(heading - (0.3 + pans)), 0.0, atol=1e-10)
    # The zenith degree seen through the 10 degree cone is a little below the point value
    # eta * d_max * sin^2(60) / (1 + cos^2(60)) = 0.99 * 0.76 * 0.6 (e-vectors fan out in the cone).
    assert 0.97 * 0.99 * 0.76 * 0.6 < degree[0] < 0.99 * 0.76 * 0.6
    # Through the 10-bit ADC the error stays within the quantisation.
    counts = hardware.counts(scene, None)
    x_q = delogarithmise(volts_to_decades(counts_to_volts(counts)))
    a_q, _ = least_squares_evector(x_q, ALPHA)
    assert abs(wrap_axial(zenith_heading(a_q, sun_azimuth=sky.sun.azimuth) - (0.3 + pans[-1]))) < np.deg2rad(0.3)


def test_calibration_recovers_component_tolerances():
    sky = SkyModel(SunPosition(0.0, np.deg2rad(30.0)))
    mismatch = sample_mismatch(np.random.default_rng(2), gain_sigma=0.05, offset_sigma_v=0.05, angle_sigma=np.deg2rad(2.0))
    hardware = SimulatedCompassHardware(mismatch=mismatch)
    scene = CompassScene(sky, mount_heading=-1.0)
    pans = np.deg2rad(np.arange(-159.0, 160.0, 3.0))
    volts = _rotation_readings(hardware, scene, pans)
    cal = calibrate_from_rotation(volts, pans)
    chain = ChainParameters()
    log_ratio = np.log10(mismatch.sensitivity_ratio)
    true_center = chain.center_v + mismatch.offset_v + chain.volts_per_decade * mismatch.gain * log_ratio
    np.testing.assert_allclose(cal.center_v, true_center, atol=2e-4)
    true_gain = 0.5 * mismatch.gain
    np.testing.assert_allclose(cal.volts_per_decade / true_gain, np.mean(cal.volts_per_decade / true_gain), rtol=1e-3)
    true_angles = ALPHA + mismatch.angle_error
    np.testing.assert_allclose(wrap_axial(cal.unit_angles - true_angles - (cal.unit_angles[0] - true_angles[0])), 0.0, atol=1e-4)

    def rmse(c):
        x = delogarithmise(volts_to_decades(volts, center_v=c.center_v, volts_per_decade=c.volts_per_decade))
        a, _ = least_squares_evector(x, c.unit_angles)
        return heading_errors(zenith_heading(a), pans, axial=True).rmse_deg

    assert rmse(UnitCalibration.nominal()) > 1.0
    assert rmse(cal) < 0.05
    with pytest.raises(Exception, match="180 degrees"):
        calibrate_from_rotation(volts[:20], pans[:20])


def test_error_function_resolves_tilted_views_only():
    sky = SkyModel(SunPosition(0.5, np.deg2rad(30.0)))
    optics = CompassOptics()
    predictor = EvectorPredictor(SkyModel(sky.sun), optics)
    for true_heading in [-2.5, -0.4, 1.2, 2.9]:
        for tilt, expect_resolved in [(np.deg2rad(25.0), True), (0.0, False)]:
            _, q, u = optics.stokes(sky, true_heading, tilt)
            x = optics.unit_signals(q, u)
            angle, _ = least_squares_evector(x, ALPHA)
            sol = solve_pose(x, float(angle), tilt, predictor=predictor, unit_angles=ALPHA, margin=1e-6)
            assert sol.resolved is expect_resolved
            if expect_resolved:
                assert sol.heading == pytest.approx(true_heading, abs=1e-9)
            else:
                assert abs(wrap_axial(sol.heading - true_heading)) < 1e-9
                assert sol.error == pytest.approx(sol.alternative_error, abs=1e-12)


def test_scan_fit_recovers_mount_heading_and_resolves_ambiguity():
    sky = SkyModel(SunPosition(-2.0, np.deg2rad(45.0)))
    optics = CompassOptics()
    pans, tilts = np.meshgrid(np.deg2rad(np.arange(-150.0, 151.0, 50.0)), np.deg2rad([-30.0, 0.0, 30.0]))
    pans, tilts = pans.ravel(), tilts.ravel()
    mount = 0.7
    _, q, u = optics.stokes(sky, mount + pans, tilts)
    angles = 0.5 * np.arctan2(u, q)
    degrees = 0.99 * np.hypot(q, u)
    fit = fit_scan_heading(angles, degrees, pans, tilts, predictor=EvectorPredictor(SkyModel(sky.sun), optics))
    assert fit.heading == pytest.approx(mount, abs=1e-7)
    assert fit.resolved
    assert fit.n_used == np.sum(degrees >= 0.05)  # the points next to the sun are dropped
    assert fit.n_used >= pans.size - 3


def test_evector_from_compass_counts_refuses_an_unknown_solver():
    """The Python API's own argument check (the config path checks experiment.solver's declared choices)."""
    from bionav.polcompass import evector_from_compass_counts

    counts = np.full((2, 3), 512.0)
    cal = UnitCalibration.nominal()
    angle_ls, _, _ = evector_from_compass_counts(counts, cal, solver="least_squares")
    angle_2u, _, _ = evector_from_compass_counts(counts, cal, solver="two_unit")
    assert angle_ls.shape == angle_2u.shape == (2,)
    with pytest.raises(ValueError, match="solver must be 'least_squares' or 'two_unit', got 'bad'"):
        evector_from_compass_counts(counts, cal, solver="bad")
