"""The explicit-vector kernels (bionav/homing/warping/vkernels.py) against the previous kernels, bit for bit.

The previous kernels (``kernels.minwarp_scores``, ``distance._diagonal_distances_q``) are kept as the
plain reference; these tests run both on random inputs of many sizes (alpha steps 1, 2, 3, 6; widths
below, at and above the 96 lanes the search keeps in registers; widths not a multiple of 32 or 4).
"""

from __future__ import annotations

import numpy as np
import pytest

from bionav.homing.warping.distance import _diagonal_distances_q, _image_quantum, _quantise, distance_quantum
from bionav.homing.warping.kernels import fill_window_minima, minwarp_scores
from bionav.homing.warping.scaleplanes import check_scales, default_scales, reference_thresholds
from bionav.homing.warping.templates import minwarp_template, minwarp_windows
from bionav.homing.warping.vkernels import (
    TABLE_PAD,
    diagonal_distances_u8,
    minwarp_search_u8,
    padded_lanes,
    search_scratch_size,
)

#: (width, alpha steps): step 3 at 288 (the default), steps 1, 2, 6, alpha lanes 22 .. 130
SIZES = ((288, 96), (144, 48), (96, 96), (66, 22), (130, 130), (120, 60), (102, 17), (200, 100))


def _windows(width):
    scales = default_scales()
    scales, tau = check_scales(scales, reference_thresholds(scales, max_ratio=2.5))
    return minwarp_windows(minwarp_template(width, scales, tau), max_level=4)


@pytest.mark.parametrize("width,n_alpha", SIZES)
def test_vector_search_equals_the_previous_kernel(width, n_alpha):
    rng = np.random.default_rng(width * 1000 + n_alpha)
    windows = _windows(width)
    step, n, k = width // n_alpha, n_alpha, 9
    n_levels = int(windows[2].max()) + 1
    size = n_levels * k * width * step * n
    for trial in range(3):
        flat = rng.integers(0, 256, size + TABLE_PAD).astype(np.uint8)  # garbage in the padding too
        levels = flat[:size].reshape(n_levels, k, width, step, n)
        levels[0] = rng.integers(0, distance_quantum(width)[0] + 1, levels[0].shape)
        fill_window_minima(levels)
        p_cols = np.sort(rng.choice(np.arange(0, width, step), size=max(1, n // (trial + 1)), replace=False))
        expected = np.zeros((p_cols.size, n), np.uint16)
        minwarp_scores(levels, n, p_cols.astype(np.int64), *windows, np.uint8(255), expected)
        acc = np.full((p_cols.size, padded_lanes(n)), 7, np.uint16)  # overwritten, not added to
        scratch = rng.integers(0, 256, search_scratch_size(n)).astype(np.uint8)
        minwarp_search_u8(flat, k, width, step, n, p_cols.astype(np.int64), *windows, acc, scratch)
        np.testing.assert_array_equal(acc[:, :n], expected)


@pytest.mark.parametrize("width,n_alpha", SIZES + ((33, 11), (35, 35)))
@pytest.mark.parametrize("rows", [5, 8, 17, 49])
def test_vector_distances_equal_the_previous_kernel(width, n_alpha, rows):
    rng = np.random.default_rng(width * 100 + rows)
    k, step = 3, width // n_alpha
    snap = rng.normal(size=(k, rows, width)).astype(np.float32)
    cur = rng.normal(size=(k, rows, width)).astype(np.float32)
    snap[1, :, 3] = 0.0  # zero columns: the 0 / 0 case
    cur[1, :, 5] = 0.0
    top = max(np.abs(snap).max(), np.abs(cur).max())
    scale = np.float32(_image_quantum(rows) / top)  # the largest values the 16-bit sums allow
    sq = np.empty((k, rows, width), np.int16)
    sn = np.empty((k, width), np.int32)
    cq2 = np.empty((k, rows, 2 * width + 4), np.int16)
    cn2 = np.empty((k, 2 * width + 4), np.int32)
    _quantise(snap, scale, sq, sn)
    _quantise(cur, scale, cq2, cn2)
    q = distance_quantum(width)[0]
    expected = np.empty((k, width, step, n_alpha), np.uint8)
    _diagonal_distances_q(sq, cq2, sn, cn2, step, q, expected)
    got = np.empty_like(expected)
    acc = np.empty((width + 4, width), np.uint16)
    diagonal_distances_u8(sq, cq2, sn, cn2, step, q, got, acc)
    np.testing.assert_array_equal(got, expected)


@pytest.mark.parametrize("width,rows", [(64, 5), (96, 49), (130, 17)])
def test_vector_distances_exact_at_the_largest_sums(width, rows):
    """Values at +-the image quantum (|a - b| up to twice it, sums up to 65,535): the kernel's
    ``2 sum max(a, b) - sum a - sum b`` wraps in 16 bits and must still equal ``sum |a - b|``."""
    rng = np.random.default_rng(width + rows)
    k, q = 2, distance_quantum(width)[0]
    top = _image_quantum(rows)
    sq = (top * rng.choice([-1, 1], size=(k, rows, width))).astype(np.int16)
    c = (top * rng.choice([-1, 1], size=(k, rows, width))).astype(np.int16)
    c[0] = -sq[0]  # a diagonal whose every term is 2 * top: the largest sum the quantum allows
    cq2 = np.zeros((k, rows, 2 * width + 4), np.int16)
    cq2[:, :, :2 * width] = np.concatenate([c, c], axis=2)
    cq2[:, :, 2 * width:] = c[:, :, :4]
    sn = np.abs(sq.astype(np.int32)).sum(axis=1)
    cn2 = np.abs(cq2.astype(np.int32)).sum(axis=1)
    expected = np.empty((k, width, 1, width), np.uint8)
    _diagonal_distances_q(sq, cq2, sn, cn2, 1, q, expected)
    got = np.empty_like(expected)
    diagonal_distances_u8(sq, cq2, sn, cn2, 1, q, got, np.empty((width + 4, width), np.uint16))
    np.testing.assert_array_equal(got, expected)
    assert (expected[0, 0] == q).all()  # the opposite columns: NSAD 1 on diagonal 0


#: (width, height, n_alpha, n_psi): the default, steps 2 and 1 (96 is no multiple of 40), an odd step (130 / 65)
PAIR_SIZES = ((288, 50, 96, 96), (64, 12, 32, 16), (96, 20, 40, 30), (130, 17, 65, 26))
VARIANTS = {"single": {}, "compass": {"compass_fraction": 0.3}, "fine": {"fine_search": True},
            "double_fine": {"double_search": True, "fine_search": True},
            "compass_double_fine": {"compass_fraction": 0.25, "double_search": True, "fine_search": True}}


@pytest.mark.parametrize("symmetric", [True, False])
@pytest.mark.parametrize("width,height,n_alpha,n_psi", PAIR_SIZES)
def test_compiled_pair_equals_the_kernel_by_kernel_path(width, height, n_alpha, n_psi, symmetric):
    """minwarping's one compiled call per pair (``pair.minwarp_pair_u8``) against the same kernels called
    one by one from Python (``search._minwarping_steps``): the same hypothesis, score and count, exactly."""
    from bionav.geometry import PanoramaGeometry
    from bionav.homing.warping import minwarping, scale_plane_stack
    from bionav.homing.warping import search as S

    rng = np.random.default_rng(width + height)
    geometry = PanoramaGeometry.square_pixels(width, height)
    scales = default_scales() if symmetric else np.array([0.5, 0.75, 1.0, 1.4, 2.0])  # asymmetric: recomputed
    for trial in range(2):
        base = rng.random((height, width)).astype(np.float32)
        other = np.roll(base, 5 * trial + 3, axis=1) + 0.3 * rng.random((height, width)).astype(np.float32)
        snap, cur = (scale_plane_stack(img, geometry=geometry, scales=scales) for img in (base, other))
        scl, tau, sym = S._scale_setup(snap["scales"], None)
        assert sym == symmetric
        windows = minwarp_windows(minwarp_template(width, scl, tau), max_level=S.WINDOW_LEVEL)
        for name, opts in VARIANTS.items():
            got = minwarping(snap, cur, n_alpha=n_alpha, n_psi=n_psi, **opts)
            p_all = S._column_grid(n_psi, width)
            double = opts.get("double_search", False)
            grid = (S._column_grid(n_alpha, width), p_all, S._layout_step(width, n_alpha, p_all, double),
                    n_alpha, n_psi)
            want = S._minwarping_steps(snap, cur, grid, windows, opts.get("compass_fraction"),
                                       opts.get("fine_search", False), double, sym, True)
            assert (got.alpha, got.psi, got.score, got.home_angle) == (want.alpha, want.psi, want.score,
                                                                      want.home_angle), (name, trial)
            assert got.extras == want.extras
