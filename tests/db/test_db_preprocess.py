"""Preprocessing against closed forms and OpenCV references."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from bionav.db.preprocess import PreprocessConfig, preprocess_images
from bionav.errors import UserError
from bionav.homing.imageops import (
    butterworth_lowpass,
    butterworth_response,
    edge_filter,
    equalize_histogram,
    resize_images,
)


@pytest.mark.parametrize("order,cutoff", [(1, 0.03), (2, 0.015), (3, 0.1), (2, 0.4)])
def test_butterworth_matches_closed_form_response(order, cutoff):
    h, w = 12, 64
    r = np.arange(h)[:, None]
    c = np.arange(w)[None, :]
    out_stack, expected = [], []
    for k, m in ((1, 0), (3, 1), (9, 2), (20, 5)):
        # cos along x (period W) times a DCT-II basis along y (exact under the mirror extension)
        wave = np.cos(2 * np.pi * k * c / w) * np.cos(np.pi * m * (r + 0.5) / h)
        img = (0.5 + 0.25 * wave).astype(np.float32)
        out_stack.append(img)
        gain = 1 / np.sqrt(1 + (np.hypot(k / w, m / (2 * h)) / 0.5 / cutoff) ** (2 * order))
        expected.append(0.5 + 0.25 * gain * wave)
    out = butterworth_lowpass(np.stack(out_stack), order=order, cutoff=cutoff)
    np.testing.assert_allclose(out, np.stack(expected), atol=2e-6)


def test_butterworth_response_at_cutoff_and_dc():
    assert butterworth_response(0.0, 0.0, order=2, cutoff=0.1) == 1.0
    assert butterworth_response(0.05, 0.0, order=2, cutoff=0.1) == pytest.approx(1 / np.sqrt(2))
    assert butterworth_response(0.03, 0.04, order=1, cutoff=0.1) == pytest.approx(1 / np.sqrt(2))


def test_butterworth_is_cyclic_in_x():
    rng = np.random.default_rng(0)
    img = rng.random((10, 40)).astype(np.float32)
    a = butterworth_lowpass(np.roll(img, 7, axis=1), order=2, cutoff=0.2)
    b = np.roll(butterworth_lowpass(img, order=2, cutoff=0.2), 7, axis=1)
    np.testing.assert_allclose(a, b, atol=1e-6)


def test_edges_match_sobel_inside_and_wrap_around():
    rng = np.random.default_rng(1)
    img = rng.random((2, 9, 30)).astype(np.float32)
    out = edge_filter(img)
    for i in range(2):
        gx = cv2.Sobel(img[i], cv2.CV_32F, 1, 0, ksize=3)
        gy = cv2.Sobel(img[i], cv2.CV_32F, 0, 1, ksize=3)
        ref = np.sqrt(gx**2 + gy**2) / (4 * np.sqrt(2))
        # OpenCV's default border (reflect-101) equals ours in y; x differs only at the seam
        np.testing.assert_allclose(out[i][:, 1:-1], ref[:, 1:-1], atol=1e-6)
    np.testing.assert_allclose(edge_filter(np.roll(img, 5, axis=2)), np.roll(out, 5, axis=2), atol=1e-6)
    assert 0.0 <= out.min() and out.max() <= 1.0


def test_edge_of_a_step_has_known_height():
    img = np.zeros((5, 12), np.float32)
    img[:, 6:] = 1.0
    out = edge_filter(img)
    # Sobel x on a unit step: 4 in the two columns next to the step -> 4 / (4 sqrt 2)
    assert out[2, 5] == pytest.approx(1 / np.sqrt(2)) and out[2, 6] == pytest.approx(1 / np.sqrt(2))
    assert out[2, 2] == 0.0


def test_equalize_matches_opencv():
    rng = np.random.default_rng(2)
    imgs = (rng.beta(2, 5, size=(4, 20, 50)) * 255).astype(np.uint8)
    imgs[3] = 77  # constant image stays unchanged
    out = equalize_histogram(imgs.astype(np.float32) / 255)
    for i in range(4):
        np.testing.assert_array_equal(np.rint(out[i] * 255).astype(np.uint8), cv2.equalizeHist(imgs[i]))


def test_resize_matches_opencv_per_image():
    rng = np.random.default_rng(3)
    imgs = rng.random((5, 20, 60)).astype(np.float32)
    out = resize_images(imgs, [30, 10])
    assert out.shape == (5, 10, 30)
    for i in range(5):
        ref = cv2.resize(imgs[i], (30, 10), interpolation=cv2.INTER_AREA)
        np.testing.assert_array_equal(out[i], ref)


def test_chains_and_errors():
    rng = np.random.default_rng(4)
    imgs = rng.random((3, 8, 32)).astype(np.float32)
    np.testing.assert_array_equal(preprocess_images(imgs, []), imgs)
    chain = [{"op": "butterworth", "order": 1, "cutoff": 0.03}, {"op": "edges"}, {"op": "resize", "size": [16, 4]}]
    expected = resize_images(edge_filter(butterworth_lowpass(imgs, order=1, cutoff=0.03)), [16, 4])
    np.testing.assert_array_equal(preprocess_images(imgs, chain), expected)
    with pytest.raises(UserError, match="unknown preprocessing op"):
        preprocess_images(imgs, [{"op": "sharpen"}])
    with pytest.raises(UserError, match="has no key .sigma."):
        preprocess_images(imgs, [{"op": "edges", "sigma": 2}])
    with pytest.raises(UserError, match="cutoff"):
        preprocess_images(imgs, [{"op": "butterworth", "order": 2}])


def test_thesis_presets_compose():
    from omegaconf import OmegaConf

    from bionav.config import compose

    expected = {"none": [], "bw1": [("butterworth", 1, 0.03)], "bw2": [("butterworth", 2, 0.015)],
                "bw1e": [("butterworth", 1, 0.03), ("edges",)], "bw2e": [("butterworth", 2, 0.015), ("edges",)],
                "he": [("equalize",)]}
    for name, steps in expected.items():
        node = compose([f"preprocess={name}"]).preprocess
        cfg = OmegaConf.to_object(OmegaConf.merge(OmegaConf.structured(PreprocessConfig), node))
        assert cfg.name == name
        got = [(s["op"], s["order"], s["cutoff"]) if s["op"] == "butterworth" else (s["op"],) for s in cfg.steps]
        assert got == steps


@pytest.mark.parametrize("size", [(346, 50), (561, 81), (1122, 162)])
def test_raw_relative_butterworth_cutoff_is_the_same_angle_at_every_image_size(size):
    """Thesis cutoffs are relative to the raw frame: gain at k cycles/rev is 1/sqrt(1 + (k / (pi r_h c))^(2n))."""
    width, height = size
    r_h, cutoff, order = 80.0, 0.03, 2
    cols = np.arange(width)
    for k in (3, 8, 20):
        img = np.broadcast_to(0.5 + 0.2 * np.cos(2 * np.pi * k * cols / width), (height, width)).astype(np.float64)
        step = {"op": "butterworth", "order": order, "cutoff": cutoff, "relative_to": "raw"}
        out = preprocess_images(img, [step], raw_horizon_radius_px=r_h)
        gain = 2 * np.abs(np.fft.rfft(out[height // 2]))[k] / width / 0.2
        assert gain == pytest.approx(1 / np.sqrt(1 + (k / (np.pi * r_h * cutoff)) ** (2 * order)), rel=1e-3)
        # relative to the panorama, the same cutoff keeps a size-dependent number of cycles per revolution
        plain = preprocess_images(img, [{"op": "butterworth", "order": order, "cutoff": cutoff}])
        gain_plain = 2 * np.abs(np.fft.rfft(plain[height // 2]))[k] / width / 0.2
        assert gain_plain == pytest.approx(1 / np.sqrt(1 + (k / (cutoff * width / 2)) ** (2 * order)), rel=1e-3)


def test_raw_relative_cutoff_needs_a_known_frame_of_reference():
    with pytest.raises(UserError, match="relative_to"):
        preprocess_images(np.zeros((4, 16)), [{"op": "butterworth", "cutoff": 0.1, "relative_to": "sensor"}])
