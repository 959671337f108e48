"""Dusk (issue 31): the twilight sky's brightness, the count-noise floor of a POL-OP unit, and the
noise-weighted ``sky_fit`` that decodes twilight and says when the light is too weak (``valid``)."""

import numpy as np
import pytest

from bionav.geometry import wrap_angle
from bionav.light import SkyModel, SunPosition
from bionav.light.twilight import (
    plane_parallel_zenith_radiance,
    shadow_height_km,
    twilight_zenith_radiance,
)
from bionav.plugins.decoders.sky_fit import SkyFit, SkyFitConfig
from bionav.polcompass.array import PolArray, counts_from_stokes, evectors_from_counts, stokes_from_sky
from bionav.polcompass.decoders import angle_noise


def test_high_sun_matches_the_plane_parallel_closed_form():
    h = np.deg2rad([20.0, 45.0, 90.0])
    for tau in (0.1, 0.25, 0.6):
        got = twilight_zenith_radiance(h, optical_depth=tau)
        want = plane_parallel_zenith_radiance(h, optical_depth=tau)
        # the Earth's curvature changes the air mass by well under 1 % above 20 degrees
        np.testing.assert_allclose(got, want, rtol=0.01)
    assert plane_parallel_zenith_radiance(np.pi / 2, optical_depth=0.25) == pytest.approx(0.25 * np.exp(-0.25))


def test_below_the_horizon_the_light_falls_with_the_shadow_height():
    h = np.deg2rad([-4.0, -5.0, -6.0, -7.0, -8.0])
    lum = twilight_zenith_radiance(h)
    # the lit column starts above the shadow height z_s = R (1/cos h - 1): L ~ exp(-z_s / H), H = 8 km
    slope = np.diff(np.log(lum)) / np.diff(shadow_height_km(h))
    np.testing.assert_allclose(slope, -1.0 / 8.0, rtol=0.03)
    assert shadow_height_km(np.deg2rad(-6.0)) == pytest.approx(6371.0 * (1.0 / np.cos(np.deg2rad(6.0)) - 1.0))
    assert shadow_height_km(0.1) == 0.0
    # orders of magnitude: from 10 degrees to 6 degrees below the horizon, about three decades
    ratio = twilight_zenith_radiance(np.deg2rad(-6.0)) / twilight_zenith_radiance(np.deg2rad(10.0))
    assert 1e-4 < ratio < 1e-2
    assert np.all(np.diff(twilight_zenith_radiance(np.deg2rad(np.arange(20.0, -9.0, -1.0)))) < 0)


def _unit_counts(n, *, counts, degree, angle, rng, noise):
    """Counts of one fan8 unit (unit 0) seeing light of ``degree`` at e-vector ``angle`` (unit frame)."""
    arr = PolArray.fan8()
    i = np.full((n, 8), 2.0 * counts)
    q = degree * np.cos(2 * angle) * np.ones((n, 8))
    u = degree * np.sin(2 * angle) * np.ones((n, 8))
    c = counts_from_stokes(i, q, u, arr)
    return arr, c + noise * rng.standard_normal(c.shape)


@pytest.mark.parametrize("counts", [20.0, 200.0])
def test_angle_noise_matches_monte_carlo(counts):
    rng = np.random.default_rng(0)
    arr, c = _unit_counts(20000, counts=counts, degree=0.4, angle=0.3, rng=rng, noise=0.5)
    ev = evectors_from_counts(c, arr)
    spread = np.std(wrap_angle(2 * (ev.angle[:, 0] - np.angle(np.mean(np.exp(2j * ev.angle[:, 0]))) / 2)) / 2)
    predicted = np.median(angle_noise(ev, 0.5)[:, 0])
    assert predicted == pytest.approx(spread, rel=0.1)


def _session(sun_elevation_deg, scale, *, n=360, seed=0, noise=0.5):
    rng = np.random.default_rng(seed)
    arr = PolArray.fan8()
    sun = SunPosition(0.3, np.deg2rad(sun_elevation_deg))
    yaw = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    inten, q, u = stokes_from_sky(SkyModel(sun, max_degree=0.5), arr, yaw)
    counts = counts_from_stokes(scale * inten / np.median(inten), q, u, arr)
    counts = np.clip(np.round(counts + noise * rng.standard_normal(counts.shape)), 0, None)
    valid = counts.min(axis=-1) >= 1.0
    with np.errstate(divide="ignore", invalid="ignore"):
        ev = evectors_from_counts(counts, arr)
    return arr, sun, yaw, ev, valid & np.isfinite(ev.angle)


def _errors(est, sun, yaw):
    heading = wrap_angle(sun.azimuth - est.azimuth)
    return np.abs(np.degrees(wrap_angle(heading - yaw)))


def test_sky_fit_reads_twilight_and_refuses_the_dark():
    # sun 2 degrees below the horizon, about 10 counts per photodiode: the pattern of the sun below the horizon
    arr, sun, yaw, ev, valid = _session(-2.0, 10.0)
    dec = SkyFit(SkyFitConfig())
    est = dec.decode(ev, valid, array=arr, sun_elevation=sun.elevation)
    assert est.valid.mean() > 0.99
    assert np.median(_errors(est, sun, yaw)[est.valid]) < 3.0
    # a fraction of a count per photodiode: below the noise floor every sample is flagged, nothing is claimed
    arr, sun, yaw, ev, valid = _session(-6.0, 0.6, seed=1)
    est = dec.decode(ev, valid, array=arr, sun_elevation=sun.elevation)
    assert not est.valid.any() and np.all(np.isnan(est.azimuth)) and not est.resolved.any()
    # without the noise model some of those dark samples get a (worthless) heading
    blind = SkyFit(SkyFitConfig(noise_counts=0.0, min_units=1)).decode(ev, valid, array=arr,
                                                                       sun_elevation=sun.elevation)
    assert blind.valid.any()


def test_noise_weighting_leaves_daylight_alone():
    arr, sun, yaw, ev, valid = _session(30.0, 2000.0)
    with_noise = SkyFit(SkyFitConfig()).decode(ev, valid, array=arr, sun_elevation=sun.elevation)
    without = SkyFit(SkyFitConfig(noise_counts=0.0)).decode(ev, valid, array=arr, sun_elevation=sun.elevation)
    assert with_noise.valid.all()
    assert np.max(np.abs(np.degrees(wrap_angle(with_noise.azimuth - without.azimuth)))) < 0.05
    assert np.median(_errors(with_noise, sun, yaw)) < 1.0


@pytest.mark.slow  # over 5 s on two cores
def test_readable_counts_inverts_the_angle_noise_and_the_limit_sits_where_the_counts_run_out():
    from bionav.light.twilight import twilight_zenith_radiance
    from bionav.polcompass.array import UnitEvectors
    from bionav.polcompass.twilight import lowest_readable_elevation, readable_counts

    need = readable_counts(0.5, degree=0.4, max_angle_noise=np.deg2rad(10.0))
    ev = UnitEvectors(np.zeros((1, 1, 2)), np.zeros((1, 1)), np.full((1, 1), 0.4), np.full((1, 1), need),
                      np.zeros((1, 1, 3)))
    assert angle_noise(ev, 0.5)[0, 0] == pytest.approx(np.deg2rad(10.0))
    ref = np.deg2rad(5.0)
    limit = lowest_readable_elevation(200.0, ref, noise_counts=0.5, degree=0.4, max_angle_noise=np.deg2rad(10.0))
    predicted = 200.0 * twilight_zenith_radiance(limit) / twilight_zenith_radiance(ref)
    assert predicted == pytest.approx(need, rel=0.02)
    assert np.deg2rad(-8.0) < limit < 0.0
    # more light at the reference: a lower limit; too little already: the reference elevation itself
    assert lowest_readable_elevation(2000.0, ref, noise_counts=0.5, degree=0.4,
                                     max_angle_noise=np.deg2rad(10.0)) < limit
    assert lowest_readable_elevation(1.0, ref, noise_counts=0.5, degree=0.4, max_angle_noise=np.deg2rad(10.0)) == ref
