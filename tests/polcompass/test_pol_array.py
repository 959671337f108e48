"""The POL-OP array chain and the decoders on simulated counts with known answers."""

import numpy as np
import pytest

from bionav.geometry import wrap_angle
from bionav.light import SkyModel, SunPosition
from bionav.polcompass.array import (
    PolArray,
    counts_from_stokes,
    evectors_from_counts,
    log_ratios_from_counts,
    stokes_from_sky,
)
from bionav.polcompass.decoders import sky_table, sun_from_sky_fit
from bionav.polcompass.published_decoders import (
    sun_from_eigenvector,
    sun_from_four_zeros,
    sun_from_mean_vector,
    sun_from_sol,
    sun_from_two_units,
)


def test_thesis_array_recovers_angle_and_degree_exactly():
    arr = PolArray.thesis()
    a, d = np.deg2rad(np.array([-70.0, -10.0, 25.0, 80.0])), np.array([0.2, 0.5, 0.7, 0.3])
    q = np.repeat((d * np.cos(2 * a))[:, None], 3, axis=1)
    u = np.repeat((d * np.sin(2 * a))[:, None], 3, axis=1)
    counts = counts_from_stokes(np.full(q.shape, 1000.0), q, u, arr)
    # eq. 4.2 closed form for unit i: log10((1 + d cos(2a - 2alpha_i)) / (1 - d cos(2a - 2alpha_i)))
    c = d[:, None] * np.cos(2 * a[:, None] - 2 * np.deg2rad([0.0, 60.0, 120.0]))
    np.testing.assert_allclose(log_ratios_from_counts(counts, arr)[..., 0], np.log10((1 + c) / (1 - c)), atol=1e-12)
    ev = evectors_from_counts(counts, arr)
    np.testing.assert_allclose(wrap_angle(2 * (ev.angle - a[:, None])), 0.0, atol=1e-9)
    np.testing.assert_allclose(ev.degree, np.repeat(d[:, None], 3, axis=1), atol=1e-9)


def test_fan8_two_pol_ops_give_the_unit_angle_and_evector_in_the_sensor_frame():
    arr = PolArray.fan8()
    a = np.deg2rad(np.linspace(-80, 80, 8))
    counts = counts_from_stokes(np.full((1, 8), 500.0), (0.4 * np.cos(2 * a))[None], (0.4 * np.sin(2 * a))[None], arr)
    ev = evectors_from_counts(counts, arr)
    np.testing.assert_allclose(wrap_angle(2 * (ev.angle[0] - a)), 0.0, atol=1e-9)
    frames = arr.unit_frames()
    expect = np.cos(a)[:, None] * frames[:, :, 0] + np.sin(a)[:, None] * frames[:, :, 1]
    np.testing.assert_allclose(np.abs(np.sum(ev.evector[0] * expect, axis=-1)), 1.0, atol=1e-9)
    # e-vectors lie in each unit's image plane
    np.testing.assert_allclose(np.sum(ev.evector[0] * frames[:, :, 2], axis=-1), 0.0, atol=1e-12)


def _simulated(sun_sensor_deg, elevation_deg):
    """Fan-8 counts under a Rayleigh sky with the sun at known sensor azimuths."""
    arr = PolArray.fan8()
    phi = np.deg2rad(np.asarray(sun_sensor_deg, float))
    sky = SkyModel(SunPosition(0.0, np.deg2rad(elevation_deg)), max_degree=0.6)
    intensity, q, u = stokes_from_sky(sky, arr, -phi)  # sun at world azimuth 0, sensor heading -phi
    counts = counts_from_stokes(1000.0 * intensity, q, u, arr)
    ev = evectors_from_counts(counts, arr)
    return arr, ev, np.ones(ev.angle.shape, bool), phi


@pytest.mark.parametrize("elevation_deg", [20.0, 45.0, 65.0])
def test_perpendicular_decoders_find_the_sun_exactly(elevation_deg):
    phis = np.arange(-170.0, 180.0, 37.0)
    arr, ev, valid, phi = _simulated(phis, elevation_deg)
    el = np.deg2rad(elevation_deg)
    table = sky_table(arr, el, n_grid=720)
    for est, tol, partner_tol in (
        (sun_from_sky_fit(ev, valid, table=table, array=arr, sun_elevation=el), 0.05, 45.5),
        (sun_from_sky_fit(ev, valid, table=table, array=arr, residual="angle"), 0.05, 45.5),
        (sun_from_two_units(ev, valid, sun_elevation=el), 1e-6, 1e-6),
        (sun_from_eigenvector(ev, valid), 1e-6, 1e-6),
        (sun_from_mean_vector(ev, valid), 1e-6, 1e-6),
    ):
        np.testing.assert_allclose(np.degrees(wrap_angle(est.azimuth - phi)), 0.0, atol=tol)
        # the eq. 4.6 partner lies about a half turn away (sky_fit: best within 45 deg of it), the choice was clear
        np.testing.assert_allclose(np.degrees(np.abs(wrap_angle(est.alternative - phi))), 180.0, atol=partner_tol)
        assert est.resolved.all()


def test_dropping_units_keeps_the_answer_and_no_units_gives_nan():
    arr, ev, valid, phi = _simulated([30.0, -100.0], 35.0)
    el = np.deg2rad(35.0)
    valid[:, [0, 3, 5]] = False
    est = sun_from_sky_fit(ev, valid, table=sky_table(arr, el), array=arr, sun_elevation=el)
    np.testing.assert_allclose(np.degrees(wrap_angle(est.azimuth - phi)), 0.0, atol=0.05)
    est = sun_from_eigenvector(ev, np.zeros_like(valid))
    assert np.isnan(est.azimuth).all() and not est.resolved.any()


@pytest.mark.parametrize("elevation_deg", [20.0, 40.0])
def test_sky_fit_rejects_a_unit_seeing_leaves_and_keeps_the_clean_units_heading(elevation_deg):
    # unit 3 sees leaves: its e-vector turned by 40 degrees (a polarized reflection), the other 7 see the sky;
    # closed form: the fit of the 7 clean units alone gives the sun exactly, and so must the robust fit of all 8
    arr = PolArray.fan8()
    phi = np.deg2rad(np.arange(-170.0, 180.0, 23.0))
    el = np.deg2rad(elevation_deg)
    intensity, q, u = stokes_from_sky(SkyModel(SunPosition(0.0, el), max_degree=0.6), arr, -phi)
    turn = np.deg2rad(80.0)  # twice the e-vector turn
    q[:, 3], u[:, 3] = np.cos(turn) * q[:, 3] - np.sin(turn) * u[:, 3], np.sin(turn) * q[:, 3] + np.cos(turn) * u[:, 3]
    ev = evectors_from_counts(counts_from_stokes(1000.0 * intensity, q, u, arr), arr)
    valid = np.ones(ev.angle.shape, bool)
    clean = valid.copy()
    clean[:, 3] = False
    table = sky_table(arr, el)

    def err_deg(v, **kw):
        est = sun_from_sky_fit(ev, v, table=table, array=arr, sun_elevation=el, **kw)
        return np.abs(np.degrees(wrap_angle(est.azimuth - phi)))

    np.testing.assert_allclose(err_deg(clean), 0.0, atol=0.05)
    np.testing.assert_allclose(err_deg(valid), 0.0, atol=0.05)  # default: Cauchy rounds, then the outlier rejected
    assert err_deg(valid, robust_iterations=0).mean() > 4.0  # plain least squares is pulled off by the leaves
    assert err_deg(valid, reject=None).mean() > 0.5  # Cauchy weights alone keep some of the leaves' pull


def test_sol_population_vector_points_to_a_cosine_intensity_peak():
    # closed form: i_k = cos(theta_k - phi) makes the SOL first harmonic point at phi
    arr = PolArray.fan8()
    phi = np.deg2rad(np.array([10.0, 135.0, -60.0]))
    inten = 1000.0 * (1.0 + 0.3 * np.cos(arr.unit_azimuths[None, :] - phi[:, None]))
    counts = counts_from_stokes(inten, np.zeros_like(inten), np.zeros_like(inten), arr)
    ev = evectors_from_counts(counts, arr)
    est = sun_from_sol(ev, np.ones(inten.shape, bool), array=arr, response="i")
    np.testing.assert_allclose(np.degrees(wrap_angle(est.azimuth - phi)), 0.0, atol=1e-9)


@pytest.mark.parametrize("elevation_deg", [15.0, 30.0, 65.0])
def test_four_zeros_finds_the_sun_where_the_ring_has_four_zeros(elevation_deg):
    arr, ev, valid, phi = _simulated(np.arange(-160.0, 180.0, 40.0), elevation_deg)
    est = sun_from_four_zeros(ev, valid, array=arr)
    ok = np.isfinite(est.azimuth)
    assert ok.sum() >= 5  # some headings give fewer than four crossings at every level: not decoded (NaN)
    err = np.degrees(np.abs(wrap_angle(est.azimuth[ok] - phi[ok])))
    assert np.all(err < 8.0), err  # 8 units: the interpolated zeros are approximate


def test_decoder_bench_prints_one_json_line_per_decoder(capsys):
    import json

    from bionav.bench.decoders.__main__ import main

    assert main(["--rotations", "1", "--samples", "16", "--repeat", "1"]) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert [r["decoder"] for r in rows] == ["sky_fit", "two_unit", "sol", "four_zeros", "eigenvector", "mean_vector"]
    assert all(r["n_samples"] == 16 and r["wall_ms_per_session"] > 0 and r["cpu_ms_per_session"] >= 0 for r in rows)
    with pytest.raises(SystemExit) as refused:  # a bad option: one message naming it, status 2 (bench parser)
        main(["--repeat", "0"])
    assert refused.value.code == 2 and "--repeat 0 is out of range" in capsys.readouterr().err
