"""The warping methods' Butterworth cutoff relative to the raw camera frame (thesis 5.1.4)."""

import numpy as np
import pytest

from bionav.db.camera import raw_horizon_radius
from bionav.errors import UserError
from bionav.geometry import PanoramaGeometry
from bionav.plugins.homing.warping import MinWarping, Warping1D, Warping2D, panorama_cutoff

R_H = 80.5  # horizon radius of the raw frame, pixels
CUTOFF, ORDER = 0.1, 3


def _cosine(width: int, height: int, k: int) -> np.ndarray:
    cols = np.arange(width)
    return np.broadcast_to(0.5 + 0.2 * np.cos(2 * np.pi * k * cols / width), (height, width)).astype(np.float32)


def _strip_gain(method, width: int, height: int, k: int) -> float:
    strip = np.asarray(method.prepare(_cosine(width, height, k)), dtype=np.float64)
    return float(2 * np.abs(np.fft.rfft(strip))[k] / width / 0.2)


@pytest.mark.parametrize("cls", [MinWarping, Warping2D, Warping1D])
@pytest.mark.parametrize("width", [346, 1122])
def test_raw_relative_cutoff_is_the_closed_form(cls, width):
    """cutoff_panorama = c * 2 pi r_h / W for every width; panorama-relative stays c."""
    geometry = PanoramaGeometry.square_pixels(width, 50)
    raw = cls(cls.Config(image_size=None, butterworth_cutoff=CUTOFF, butterworth_relative_to="raw"),
              geometry=geometry, raw_horizon_radius_px=R_H)
    assert panorama_cutoff(raw, width) == pytest.approx(CUTOFF * 2 * np.pi * R_H / width, rel=1e-12)
    plain = cls(cls.Config(image_size=None, butterworth_cutoff=CUTOFF), geometry=geometry, raw_horizon_radius_px=R_H)
    assert panorama_cutoff(plain, width) == CUTOFF
    off = cls(cls.Config(image_size=None), geometry=geometry)
    assert panorama_cutoff(off, width) is None


@pytest.mark.parametrize("k", [5, 20, 40])
def test_raw_relative_filter_keeps_the_same_angular_detail_at_two_sizes(k):
    """The power response 1 / (1 + (k / (pi r_h c))^(2n)) at k cycles/rev, whatever the db width."""
    expected = 1.0 / (1.0 + (k / (np.pi * R_H * CUTOFF)) ** (2 * ORDER))
    gains, plain_gains = [], []
    for width, height in [(346, 50), (1122, 162)]:
        geometry = PanoramaGeometry.square_pixels(width, height)
        cfg = dict(image_size=None, butterworth_cutoff=CUTOFF, butterworth_order=ORDER, strip_rows=1)
        raw = Warping1D(Warping1D.Config(**cfg, butterworth_relative_to="raw"), geometry=geometry,
                        raw_horizon_radius_px=R_H)
        gains.append(_strip_gain(raw, width, height, k))
        plain = Warping1D(Warping1D.Config(**cfg), geometry=geometry)
        plain_gains.append(_strip_gain(plain, width, height, k))
        # panorama-relative: the cutoff sits at c * W / 2 cycles per revolution
        assert plain_gains[-1] == pytest.approx(1.0 / (1.0 + (k / (CUTOFF * width / 2)) ** (2 * ORDER)), abs=1e-4)
    assert gains[0] == pytest.approx(expected, abs=1e-4)
    assert gains[1] == pytest.approx(expected, abs=1e-4)
    if k >= 20:  # the old behaviour changed with db.image_size
        assert abs(plain_gains[0] - plain_gains[1]) > 0.05


def test_raw_relative_cutoff_needs_the_raw_radius():
    geometry = PanoramaGeometry.square_pixels(346, 50)
    method = Warping1D(Warping1D.Config(image_size=None, butterworth_cutoff=CUTOFF, butterworth_relative_to="raw"),
                       geometry=geometry)
    with pytest.raises(UserError, match="raw"):
        method.prepare(_cosine(346, 50, 3))


def test_thesis_presets_get_the_databases_raw_radius(tmp_path):
    """homing=warping2d_thesis / minwarping_thesis through the experiments' factory: raw-relative cutoff."""
    from bionav.config import compose
    from bionav.experiments.common import make_homing
    from bionav.experiments.context import RunContext

    geometry = PanoramaGeometry.square_pixels(1122, 162)
    for homing in ("warping2d_thesis", "minwarping_thesis"):
        cfg = compose([f"homing={homing}"])
        assert cfg.homing.butterworth_relative_to == "raw"
        ctx = RunContext(dir=tmp_path, log=None, rng=np.random.default_rng(0), cfg=cfg)
        uni = make_homing(cfg, ctx, geometry, raw_horizon_radius_px=raw_horizon_radius("normal-view"))
        assert panorama_cutoff(uni, 1122) == pytest.approx(0.1 * 2 * np.pi * raw_horizon_radius("normal-view") / 1122)
        default = make_homing(cfg, ctx, geometry)  # no radius given: the ultra-wide-view mirror's, as bw1/bw2
        assert default.raw_horizon_radius_px == pytest.approx(raw_horizon_radius("ultra-wide"))
