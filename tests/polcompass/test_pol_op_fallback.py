"""A fault mask per photodiode: units with one usable POL-OP still vote (issue 31), on simulated counts."""

import numpy as np
import pytest

from bionav.geometry import wrap_angle
from bionav.light import SkyModel, SunPosition
from bionav.polcompass.array import PolArray, counts_from_stokes, evectors_from_counts, masked_pol_ops, stokes_from_sky
from bionav.polcompass.decoders import sky_table, sun_from_pol_op_fit, sun_from_sky_fit
from bionav.polcompass.recordings import photodiode_validity, pol_op_validity, sample_validity

SAT = 11000.0


def test_pol_op_validity_is_per_photodiode_pair():
    # fan8 file order 135, 45, 90, 0 degrees; POL-OPs (2, 3) and (1, 0)
    counts = np.array([[[32768, 32767, 900, 800],   # pair (1, 0) overflowing: (2, 3) still usable
                        [827, 0, 932, 883],         # one photodiode reads 0 among lit ones: (2, 3) usable
                        [500, 400, 0, 0],           # pair (2, 3) dark: (1, 0) usable
                        [500, 400, 450, 460]]], float)  # healthy
    pd = photodiode_validity(counts, saturation_counts=SAT, dark_counts=1.0)
    np.testing.assert_array_equal(pd[0], [[0, 0, 1, 1], [1, 0, 1, 1], [1, 1, 0, 0], [1, 1, 1, 1]])
    ok = pol_op_validity(counts, [[2, 3], [1, 0]], saturation_counts=SAT, dark_counts=1.0)
    np.testing.assert_array_equal(ok[0], [[1, 0], [1, 0], [0, 1], [1, 1]])
    # the per-unit mask keeps only the healthy unit
    np.testing.assert_array_equal(sample_validity(counts, saturation_counts=SAT, dark_counts=1.0,
                                                  imbalance_decades=0.15)[0], [0, 0, 0, 1])


def test_masked_pol_ops_blanks_unusable_outputs_and_faulty_units():
    arr = PolArray.fan8()
    counts = np.full((2, 8, 4), 500.0)
    counts[0, 1, 0] = 32768.0
    ev = evectors_from_counts(counts, arr)
    ok = pol_op_validity(counts, arr.pairs, saturation_counts=SAT, dark_counts=1.0)
    m = masked_pol_ops(ev, ok, faulty_units=[7])
    assert np.isnan(m.x[0, 1, 1]) and np.isfinite(m.x[0, 1, 0]) and np.isfinite(m.x[1, 1]).all()
    assert np.isnan(m.x[:, 7]).all() and np.isnan(m.intensity[:, 7]).all() and np.isfinite(m.intensity[:, :7]).all()
    np.testing.assert_array_equal(m.pair_total[0, 0], [1000.0, 1000.0])  # s_a + s_b per POL-OP
    np.testing.assert_array_equal(m.pol_op_valid, np.isfinite(m.x))


def test_unchecked_pol_ops_of_dropped_units_are_never_used():
    # without masked_pol_ops an overflowing pair reads x = 0 (32768 vs 32767): the fallback must not take it
    phi, el = np.deg2rad([20.0, -60.0]), np.deg2rad(35.0)
    arr, counts = _sky_counts(phi, el)
    counts[:, 1:, :2] = 32768.0
    ev = evectors_from_counts(counts, arr)
    valid = sample_validity(counts, saturation_counts=SAT, dark_counts=1.0, imbalance_decades=0.15)
    est = sun_from_sky_fit(ev, valid, table=sky_table(arr, el), array=arr, sun_elevation=el, min_units=2,
                           pol_op_fallback=True)
    assert np.isnan(est.azimuth).all()  # one checked unit: nothing claimed
    est = sun_from_sky_fit(masked_pol_ops(ev, pol_op_validity(counts, arr.pairs, saturation_counts=SAT,
                                                                 dark_counts=1.0)),
                           valid, table=sky_table(arr, el), array=arr, sun_elevation=el, min_units=2, pol_op_fallback=True)
    np.testing.assert_allclose(np.degrees(wrap_angle(est.azimuth - phi)), 0.0, atol=0.1)


def _sky_counts(phi, el, max_degree=0.6):
    arr = PolArray.fan8()
    intensity, q, u = stokes_from_sky(SkyModel(SunPosition(0.0, el), max_degree=max_degree), arr, -phi)
    return arr, counts_from_stokes(2000.0 * intensity, q, u, arr)


@pytest.mark.parametrize("elevation_deg", [15.0, 40.0, 65.0])
def test_pol_op_fit_finds_the_sun_with_unknown_degree_scale(elevation_deg):
    # the table is tabulated with maximum degree 0.76, the sky has 0.6: the closed-form scale absorbs it
    phi = np.deg2rad(np.arange(-175.0, 180.0, 29.0))
    el = np.deg2rad(elevation_deg)
    arr, counts = _sky_counts(phi, el)
    ev = evectors_from_counts(counts, arr)
    est = sun_from_pol_op_fit(ev, np.ones(ev.angle.shape, bool), table=sky_table(arr, el), array=arr)
    np.testing.assert_allclose(np.degrees(wrap_angle(est.azimuth - phi)), 0.0, atol=0.1)


@pytest.mark.parametrize("elevation_deg", [15.0, 40.0])
def test_sky_fit_decodes_partially_saturated_units_from_their_other_pol_op(elevation_deg):
    # at every sample only unit 0 reads both POL-OPs: pairs saturate (overflow) on units 1-4, a photodiode
    # reads 0 on unit 6, units 5 and 7 are dropped as faulty; whole units are too few (min_units 2)
    phi = np.deg2rad(np.arange(-170.0, 180.0, 23.0))
    el = np.deg2rad(elevation_deg)
    arr, clean = _sky_counts(phi, el)
    counts = clean.copy()
    counts[:, 1:3, 0:2] = 32768.0   # pair (1, 0) overflowing
    counts[:, 3:5, 2:4] = 32768.0   # pair (2, 3) overflowing
    counts[:, 6, 3] = 0.0           # one photodiode read fault
    faulty = [5, 7]
    valid = sample_validity(counts, saturation_counts=SAT, dark_counts=1.0, imbalance_decades=0.15)
    valid[:, faulty] = False
    assert (valid.sum(axis=1) == 1).all()
    ok = pol_op_validity(counts, arr.pairs, saturation_counts=SAT, dark_counts=1.0)
    ok[:, faulty] = False
    ev = masked_pol_ops(evectors_from_counts(counts, arr), ok, faulty_units=faulty)
    table = sky_table(arr, el)
    kw = dict(table=table, array=arr, sun_elevation=el, min_units=2, noise_counts=0.5)
    assert np.isnan(sun_from_sky_fit(ev, valid, **kw).azimuth).all()  # per unit: undecodable
    est = sun_from_sky_fit(ev, valid, pol_op_fallback=True, **kw)
    # the clean units' heading: the same sky read by every healthy unit without faults
    clean_valid = np.ones(valid.shape, bool)
    clean_valid[:, faulty] = False
    ref = sun_from_sky_fit(evectors_from_counts(clean, arr), clean_valid, **kw)
    np.testing.assert_allclose(np.degrees(wrap_angle(ref.azimuth - phi)), 0.0, atol=0.05)
    np.testing.assert_allclose(np.degrees(wrap_angle(est.azimuth - ref.azimuth)), 0.0, atol=0.1)
    # samples where whole units suffice are not touched by the fallback
    same = sun_from_sky_fit(evectors_from_counts(clean, arr), clean_valid, pol_op_fallback=True, **kw)
    np.testing.assert_array_equal(same.azimuth, ref.azimuth)


def test_fallback_claims_nothing_without_enough_pol_ops():
    arr, counts = _sky_counts(np.deg2rad([10.0, 100.0]), np.deg2rad(30.0))
    counts[:, 1:, :2] = 32768.0  # units 1-7 keep one POL-OP each ...
    counts[:, 2:, 2:] = 32768.0  # ... but units 2-7 lose it too: unit 0 (two POL-OPs) and unit 1 (one)
    counts[:, 0] = 0.0           # and unit 0 is dark: one POL-OP on one unit left
    ok = pol_op_validity(counts, arr.pairs, saturation_counts=SAT, dark_counts=1.0)
    ev = masked_pol_ops(evectors_from_counts(counts, arr), ok)
    valid = np.zeros(ok.shape[:2], bool)
    el = np.deg2rad(30.0)
    est = sun_from_sky_fit(ev, valid, table=sky_table(arr, el), array=arr, sun_elevation=el, min_units=2,
                           pol_op_fallback=True)
    assert np.isnan(est.azimuth).all() and not est.resolved.any()


def test_a_partly_saturated_unit_votes_beside_whole_units():
    # four whole units and three units with one overflowing pair: the sample is fitted on every usable POL-OP
    phi = np.deg2rad(np.arange(-170.0, 180.0, 31.0))
    el = np.deg2rad(50.0)
    arr, counts = _sky_counts(phi, el)
    counts[:, 4:7, 0:2] = 32768.0
    valid = sample_validity(counts, saturation_counts=SAT, dark_counts=1.0, imbalance_decades=0.15)
    ok = pol_op_validity(counts, arr.pairs, saturation_counts=SAT, dark_counts=1.0)
    ev = masked_pol_ops(evectors_from_counts(counts, arr), ok, faulty_units=[7])
    valid[:, 7] = False
    kw = dict(table=sky_table(arr, el), array=arr, sun_elevation=el, min_units=2)
    whole = sun_from_sky_fit(ev, valid, **kw)
    both = sun_from_sky_fit(ev, valid, pol_op_fallback=True, **kw)
    alone = sun_from_pol_op_fit(ev, valid, table=kw["table"], array=arr)
    np.testing.assert_array_equal(both.azimuth, alone.azimuth)  # the POL-OP fit decided
    for est in (whole, both):  # noise-free: both agree with the sun
        np.testing.assert_allclose(np.degrees(wrap_angle(est.azimuth - phi)), 0.0, atol=0.1)
