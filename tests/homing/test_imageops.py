"""bionav.homing.imageops: the one home of resize, filters and the image-size check."""

import numpy as np
import pytest

from bionav.geometry import PanoramaGeometry
from bionav.homing.imageops import (
    butterworth_lowpass,
    resize_images,
    resize_panorama,
    vertical_difference,
)


def test_two_passes_equal_the_filter_applied_twice():
    rng = np.random.default_rng(0)
    img = rng.random((12, 48))
    once = butterworth_lowpass(img, cutoff=0.2, order=2, clip=None)
    twice = butterworth_lowpass(once.astype(np.float64), cutoff=0.2, order=2, clip=None)
    both = butterworth_lowpass(img, cutoff=0.2, order=2, passes=2, clip=None)
    np.testing.assert_allclose(both, twice, atol=1e-6)


def test_power_response_at_the_cutoff_halves_a_wave():
    # a wave along x at the cutoff frequency: |G|^2 = 1/2 with two passes
    w, k = 64, 8  # rho = (k / w) / 0.5 = 0.25
    wave = np.tile(np.cos(2 * np.pi * k * np.arange(w) / w), (6, 1))
    out = butterworth_lowpass(wave, cutoff=0.25, order=3, passes=2, clip=None)
    np.testing.assert_allclose(out, 0.5 * wave, atol=1e-6)
    clipped = butterworth_lowpass(wave, cutoff=0.25, order=3, passes=2)
    assert clipped.min() == 0.0


def test_resize_panorama_keeps_the_field_of_view_and_matches_the_stack_resize():
    g = PanoramaGeometry.square_pixels(60, 20)
    img = np.random.default_rng(1).random((20, 60)).astype(np.float32)
    out, g2 = resize_panorama(img, geometry=g, size=[30, 10])
    assert out.shape == (10, 30) and out.dtype == np.float32
    assert (g2.width, g2.height) == (30, 10) and g2.rad_per_row == pytest.approx(2 * g.rad_per_row)
    np.testing.assert_array_equal(out, resize_images(img[None], [30, 10])[0])
    same, g3 = resize_panorama(img, geometry=g, size=None)
    assert same is img and g3 is g


def test_vertical_difference():
    np.testing.assert_array_equal(vertical_difference([[1.0, 2.0], [4.0, 2.0], [4.0, 5.0]]), [[3.0, 0.0], [0.0, 3.0]])
