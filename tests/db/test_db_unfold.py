"""Unfolding raw mirror frames against images with known geometry."""

from __future__ import annotations

import numpy as np
import pytest

from bionav.db.unfold import unfold_panorama


def test_linear_frame_is_sampled_exactly():
    # bilinear interpolation reproduces a linear function exactly
    h, w = 60, 80
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float64)
    a, b, c = 0.004, -0.003, 0.5
    raw = (a * xx + b * yy + c).astype(np.float32)
    cx, cy, r_in, r_out, width, height = 41.3, 29.6, 5.0, 25.0, 48, 9
    out = unfold_panorama(raw, center=(cx, cy), inner_radius=r_in, outer_radius=r_out, size=(width, height))
    assert out.shape == (height, width) and out.dtype == np.float32
    phi = 2 * np.pi * np.arange(width) / width
    radius = r_out + (r_in - r_out) * np.arange(height) / (height - 1)
    expected = a * (cx + radius[:, None] * np.cos(phi)) + b * (cy + radius[:, None] * np.sin(phi)) + c
    np.testing.assert_allclose(out, expected, atol=2e-5)


def test_ring_image_rows_and_ray_columns():
    # concentric rings of known radius and one bright ray at a known polar angle
    size, cx, cy = 101, 50.0, 50.0
    yy, xx = np.mgrid[0:size, 0:size].astype(np.float64)
    r = np.hypot(xx - cx, yy - cy)
    ang = np.arctan2(yy - cy, xx - cx)
    raw = np.clip(r / 45.0, 0, 1)  # intensity encodes the radius
    ray_angle = np.deg2rad(225.0)
    ray = (np.abs(np.angle(np.exp(1j * (ang - ray_angle)))) * r < 1.0) & (r > 3)
    raw = np.where(ray, 1.0, raw * 0.8).astype(np.float32)
    width, height = 72, 11
    out = unfold_panorama(raw, center=(cx, cy), inner_radius=10.0, outer_radius=40.0, size=(width, height))
    # column 72 * 225/360 = 45 holds the ray, every other column the radius ramp
    assert int(np.argmax(out.mean(axis=0))) == 45
    others = np.delete(out, [44, 45, 46], axis=1)
    radius = 40.0 + (10.0 - 40.0) * np.arange(height) / (height - 1)
    np.testing.assert_allclose(others, np.repeat((0.8 * radius / 45.0)[:, None], others.shape[1], 1), atol=0.01)


def test_outside_the_frame_reads_zero():
    raw = np.ones((20, 20), np.float32)
    out = unfold_panorama(raw, center=(10, 10), inner_radius=2, outer_radius=30, size=(16, 4))
    assert out[0].max() == 0.0 and out[-1].min() == pytest.approx(1.0)
