"""Parameter signatures (thesis 3.5) against hand-computed values on tiny images."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from bionav.errors import PluginError, UserError
from bionav.homing.signatures import cog, fourier, histogram, statistics
from bionav.homing.signatures.rings import ring_edges
from bionav.plugins.signatures import SIGNATURE_NAMES, builtin_signature_class, make_signature

# 4 x 8 image used for the hand-computed statistics
#   ring 0 (rows 0-1): eight 0.5, four 0, four 1  -> mean 0.5, var 0.125
#   ring 1 (rows 2-3): five 1, eleven 0            -> Bernoulli p = 5/16
TINY = np.array(
    [
        [0.5] * 8,
        [0, 1, 0, 1, 0, 1, 0, 1],
        [1, 1, 1, 1, 0, 0, 0, 0],
        [0, 0, 0, 0, 0, 0, 0, 1],
    ],
    dtype=np.float32,
)
P = 5 / 16


def test_ring_edges():
    np.testing.assert_array_equal(ring_edges(4, 2), [0, 2, 4])
    np.testing.assert_array_equal(ring_edges(5, 2), [0, 2, 5])
    np.testing.assert_array_equal(ring_edges(25, 25), np.arange(26))
    with pytest.raises(UserError, match="signature.rings"):
        ring_edges(4, 5)


def test_ring_statistics_hand_computed():
    np.testing.assert_allclose(statistics.ring_mean(TINY, rings=2), [0.5, P])
    np.testing.assert_allclose(statistics.ring_mean(TINY, rings=1), [(8 * 0.5 + 4 + 5) / 32])
    np.testing.assert_allclose(statistics.ring_std(TINY, rings=2), [math.sqrt(0.125), math.sqrt(P * (1 - P))])
    # ring 0 is symmetric about its mean; ring 1 is Bernoulli(p): skew (1-2p)/sqrt(p q)
    np.testing.assert_allclose(
        statistics.ring_skewness(TINY, rings=2), [0.0, (1 - 2 * P) / math.sqrt(P * (1 - P))], atol=1e-12
    )
    # ring 0: mu4 = 8 * 0.5**4 / 16 = 1/32, sigma**4 = 1/64 -> 2 - 3 = -1
    # Bernoulli: (1 - 6 p q) / (p q)
    np.testing.assert_allclose(
        statistics.ring_kurtosis(TINY, rings=2), [-1.0, (1 - 6 * P * (1 - P)) / (P * (1 - P))]
    )


def test_constant_ring_has_zero_skew_and_kurtosis():
    img = np.full((4, 8), 0.3)
    np.testing.assert_array_equal(statistics.ring_skewness(img, rings=2), [0, 0])
    np.testing.assert_array_equal(statistics.ring_kurtosis(img, rings=2), [0, 0])


def test_histogram_and_entropy_hand_computed():
    # bins [0, .5) and [.5, 1]: 0.5 goes to bin 1
    h = histogram.ring_histogram(TINY, rings=2, bins=2)
    np.testing.assert_allclose(h, [[4 / 16, 12 / 16], [11 / 16, 5 / 16]])
    ent = histogram.ring_entropy(TINY, rings=2, bins=2)
    np.testing.assert_allclose(
        ent, [-(0.25 * math.log(0.25) + 0.75 * math.log(0.75)), -(11 / 16 * math.log(11 / 16) + P * math.log(P))]
    )
    # out-of-range values fall into the end bins; one-bin histograms have zero entropy
    np.testing.assert_allclose(histogram.ring_histogram(np.array([[-0.5, 1.0, 2.0, 0.3]]), bins=4), [[0.25, 0.25, 0, 0.5]])
    np.testing.assert_allclose(histogram.ring_entropy(np.full((2, 4), 0.7), bins=8), [0.0])
    # the image's own range: [0.01, 0.03] split into two bins at 0.02
    low = np.array([[0.01, 0.015, 0.02, 0.03]])
    np.testing.assert_allclose(histogram.ring_histogram(low, bins=2, value_range=None), [[0.5, 0.5]])
    np.testing.assert_allclose(histogram.ring_histogram(low, bins=2), [[1.0, 0.0]])
    np.testing.assert_allclose(histogram.ring_histogram(np.full((1, 4), 0.3), bins=3, value_range=None), [[1, 0, 0]])


def test_synthetic_mirror_cog_hand_computed():
    # 2 x 4 panorama, inner radius 0.5: rho_0 = 1 - 0.5 * 0.5 / 2 = 0.875, rho_1 = 0.625
    img = np.zeros((2, 4))
    img[0, 1] = 1.0  # azimuth pi/2 (to the left of the heading)
    np.testing.assert_allclose(cog.ring_center_of_gravity(img, rings=1, inner_radius=0.5), [[0.0, 0.875]], atol=1e-12)
    img = np.zeros((2, 4))
    img[0, 0] = 1.0  # (0.875, 0), weight 0.875 (sector area ~ rho)
    img[1, 2] = 1.0  # (-0.625, 0), weight 0.625
    np.testing.assert_allclose(cog.ring_center_of_gravity(img, rings=1, inner_radius=0.5), [[0.25, 0.0]], atol=1e-12)
    two = cog.ring_center_of_gravity(img, rings=2, inner_radius=0.5)
    np.testing.assert_allclose(two, [[0.875, 0.0], [-0.625, 0.0]], atol=1e-12)
    np.testing.assert_allclose(cog.cog_length(two), [0.875, 0.625])
    np.testing.assert_array_equal(cog.ring_center_of_gravity(np.zeros((2, 4)), rings=2), np.zeros((2, 2)))


def test_raw_cog_hand_computed():
    # 5 x 5 frame: centre (2, 2), outer radius 2.5, inner 0.2 * 2.5 = 0.5 (the centre pixel is outside)
    raw = np.zeros((5, 5))
    raw[2, 2] = 100.0
    raw[2, 4] = 1.0  # x = 2 / 2.5 = 0.8, y = 0
    raw[0, 2] = 3.0  # x = 0, y = 0.8 (row 0 is up)
    np.testing.assert_allclose(cog.raw_ring_center_of_gravity(raw, rings=1), [[0.2, 0.6]])
    # two rings of width 0.4: both pixels (rho = 0.8) in the outer ring 0, ring 1 empty
    np.testing.assert_allclose(cog.raw_ring_center_of_gravity(raw, rings=2), [[0.2, 0.6], [0.0, 0.0]])
    explicit = cog.MirrorImage(raw, center=(2.0, 2.0), inner_radius=0.5, outer_radius=2.5)
    np.testing.assert_allclose(cog.raw_ring_center_of_gravity(explicit, rings=1), [[0.2, 0.6]])


def test_raw_cog_of_rendered_mirror_image_matches_continuum_formula():
    rng = np.random.default_rng(1)
    img = rng.random((10, 36))
    mirror = cog.render_synthetic_mirror_image(img, size=801, inner_radius=0.2)
    got = cog.raw_ring_center_of_gravity(mirror, rings=5)
    want = cog.ring_center_of_gravity(img, rings=5, inner_radius=0.2)
    np.testing.assert_allclose(got, want, atol=4e-3)


def test_column_profiles_and_spectra_hand_computed():
    img = np.array([[1.0, 0, 0, 2], [1, 2, 0, 0]])
    np.testing.assert_allclose(fourier.column_mean(img), [1, 1, 0, 1])
    np.testing.assert_allclose(fourier.column_std(img), [0, 1, 0, 1])
    np.testing.assert_allclose(fourier.column_cog(img), [0.5, 1.0, 0.5, 0.0])  # empty column -> middle row
    # DFT of [1, 1, 0, 1]: F0 = 3, F1 = 1 - i + i = 1, F2 = 1 - 1 - 1 = -1
    np.testing.assert_allclose(fourier.profile_spectrum([1, 1, 0, 1], n_coeffs=3), [3, 1, -1], atol=1e-12)
    # rows [1,0,0,2] and [1,2,0,0]: F1 = 1 + 2i and 1 - 2i
    np.testing.assert_allclose(fourier.row_spectrum(img, n_coeffs=2), [[3, 1 + 2j], [3, 1 - 2j]], atol=1e-12)
    with pytest.raises(UserError, match="n_coeffs"):
        fourier.row_spectrum(img, n_coeffs=5)


def test_fourier_signature_vectors_hand_computed():
    img = np.array([[1.0, 0, 0, 2], [1, 2, 0, 0]])
    k2 = {"n_coeffs": 2}
    np.testing.assert_allclose(make_signature("fc", k2).compute(img), [3, 1, 3, 1, 0, 2, 0, -2], atol=1e-12)
    np.testing.assert_allclose(make_signature("mffc_phase", k2).compute(img), [3, 1, 3, 1, 0, 2, 0, -2], atol=1e-12)
    np.testing.assert_allclose(make_signature("fc_abs", k2).compute(img), [3, math.sqrt(5), 3, math.sqrt(5)])
    np.testing.assert_allclose(make_signature("mffc_abs", k2).compute(img), [3, math.sqrt(5), 3, math.sqrt(5)])
    k3 = {"n_coeffs": 3}
    np.testing.assert_allclose(make_signature("mean_fft", k3).compute(img), [3, 1, -1, 0, 0, 0], atol=1e-12)
    np.testing.assert_allclose(make_signature("mean_fft_abs", k3).compute(img), [3, 1, 1], atol=1e-12)
    # std profile [0, 1, 0, 1]: F = [2, 0, -2]
    np.testing.assert_allclose(make_signature("std_fft", k3).compute(img), [2, 0, -2, 0, 0, 0], atol=1e-12)
    np.testing.assert_allclose(make_signature("std_fft_abs", k3).compute(img), [2, 0, 2], atol=1e-12)
    # cog profile [0.5, 1, 0.5, 0]: F0 = 2, F1 = 0.5 - i - 0.5 = -i, F2 = 0.5 - 1 + 0.5 = 0
    np.testing.assert_allclose(make_signature("cog_fft", k3).compute(img), [2, 0, 0, 0, -1, 0], atol=1e-12)
    np.testing.assert_allclose(make_signature("cog_fft_abs", k3).compute(img), [2, 1, 0], atol=1e-12)


def test_statistics_plugins_match_functions():
    r2 = {"rings": 2, "bins": 2}
    np.testing.assert_allclose(make_signature("mean", r2).compute(TINY), [0.5, P])
    np.testing.assert_allclose(make_signature("std", r2).compute(TINY), [math.sqrt(0.125), math.sqrt(P * (1 - P))])
    np.testing.assert_allclose(make_signature("hist", r2).compute(TINY), [0.25, 0.75, 11 / 16, 5 / 16])
    q = P * (1 - P)
    np.testing.assert_allclose(make_signature("skew", r2).compute(TINY), [0.0, (1 - 2 * P) / math.sqrt(q)], atol=1e-12)
    np.testing.assert_allclose(make_signature("kurt", r2).compute(TINY), [-1.0, (1 - 6 * q) / q])
    np.testing.assert_allclose(
        make_signature("ent", r2).compute(TINY),
        [-(0.25 * math.log(0.25) + 0.75 * math.log(0.75)), -(11 / 16 * math.log(11 / 16) + P * math.log(P))],
    )
    unit = {"rings": 1, "bins": 2, "bin_range": "unit"}
    np.testing.assert_allclose(make_signature("hist", unit).compute(0.1 * TINY), [1.0, 0.0])
    np.testing.assert_allclose(make_signature("hist", {**unit, "bin_range": "image"}).compute(0.1 * TINY),
                               [(4 + 11) / 32, (12 + 5) / 32])  # fmt: skip
    with pytest.raises(UserError, match="bin_range"):
        make_signature("ent", {"bin_range": "bogus"}).compute(TINY)
    np.testing.assert_allclose(make_signature("image").compute(TINY), TINY.ravel())
    img = np.zeros((2, 4))
    img[0, 0] = img[1, 2] = 1.0
    cfg = {"rings": 2, "inner_radius": 0.5}
    np.testing.assert_allclose(make_signature("cog", cfg).compute(img), [0.875, 0, -0.625, 0], atol=1e-12)
    np.testing.assert_allclose(make_signature("cog_l", cfg).compute(img), [0.875, 0.625])


# The thesis' "rot.-invar." column of tables 5.5-5.7
THESIS_ROTATION_INVARIANT = {
    "cog": False, "image": False, "cog_l": True, "mean": True, "std": True, "skew": True, "kurt": True,
    "hist": True, "ent": True, "fc": False, "mean_fft": False, "std_fft": False, "cog_fft": False,
    "fc_abs": True, "mean_fft_abs": True, "std_fft_abs": True, "cog_fft_abs": True,
    "mffc_phase": False, "mffc_abs": True,
}  # fmt: skip


@pytest.mark.parametrize("name", SIGNATURE_NAMES)
def test_rotation_invariance_under_column_roll(name):
    rng = np.random.default_rng(7)
    img = rng.random((12, 40))
    sig = make_signature(name, {"rings": 4, "n_coeffs": 6, "bins": 8})
    assert sig.rotation_invariant is THESIS_ROTATION_INVARIANT[name]
    f = sig.compute(img)
    f_rolled = sig.compute(np.roll(img, 7, axis=1))
    assert f.ndim == 1 and f.dtype == np.float64
    if sig.rotation_invariant:
        np.testing.assert_allclose(f_rolled, f, rtol=1e-10, atol=1e-12)
    else:
        assert np.max(np.abs(f_rolled - f)) > 1e-3


def test_all_nineteen_registered_with_config_and_entry_points():
    assert len(SIGNATURE_NAMES) == 19
    data = tomllib.loads((Path(__file__).resolve().parents[2] / "pyproject.toml").read_text())
    eps = data["project"]["entry-points"]["bionav.signatures"]
    for name in SIGNATURE_NAMES:
        cls = builtin_signature_class(name)
        assert cls.name == name
        module, attr = eps[name].split(":")
        assert f"{cls.__module__}:{cls.__name__}" == eps[name]
        cls.Config()  # defaults exist
    assert data["project"]["entry-points"]["bionav.homing"]["parameter"] == (
        "bionav.plugins.homing.parameter:ParameterHoming"
    )
    with pytest.raises(PluginError, match="mffc_phase"):
        builtin_signature_class("nope")
    with pytest.raises(UserError, match="rings"):
        make_signature("mean", {"rings": 0})
