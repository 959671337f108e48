"""The warping family as homing plugins: ``minwarping``, ``warping2d``, ``warping1d``.

Each plugin resizes the canonical panorama itself (``image_size``, area
averaging), optionally low-pass filters it first (Butterworth, thesis 5.1.4),
does the per-image work in :meth:`prepare` (scale-plane stack or horizon strip)
and the per-pair search in :meth:`home_vector`. All three estimate the rotation
between the views (visual compass, ``HomeVector.compass = psi``), so they need
no aligned images. The algorithms live in :mod:`bionav.homing.warping`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from bionav.errors import UserError
from bionav.homing.base import HomeVector, HomingMethod
from bionav.homing.warping.scaleplanes import THRESHOLD_RULES
from bionav.validation import Range, bounded


def _grey(image) -> np.ndarray:
    img = np.asarray(image, dtype=np.float32)
    if img.ndim == 3:
        img = img.mean(axis=2, dtype=np.float32)
    if img.ndim != 2:
        raise UserError(
            f"the warping methods need panoramas of shape (H, W) or (H, W, C), got shape {img.shape}; "
            "check the database's images"
        )
    return img


#: what ``homing.butterworth_cutoff`` is relative to: the loaded panorama's Nyquist frequency, or the raw
#: camera frame's (thesis 5.1.4: the raw frames were filtered with cutoff 0.1 before unfolding)
BUTTERWORTH_RELATIVE_TO = ("panorama", "raw")


def panorama_cutoff(method: HomingMethod, width: int) -> float | None:
    """The warping method's Butterworth cutoff relative to a ``width``-pixel panorama's Nyquist frequency.

    With ``butterworth_relative_to=raw`` the configured cutoff is relative to
    the raw camera frame's Nyquist frequency and is converted by
    :func:`bionav.homing.imageops.panorama_cutoff_from_raw` (the conversion of
    the preprocessing presets bw1/bw2) with the database's raw horizon radius
    (``raw_horizon_radius_px``, passed by the experiment; the ultra-wide-view
    mirror's when the database names none), so the filter keeps the same
    angular detail at every panorama width. None when the filter is off. The result may exceed 1 (nothing is
    removed below the panorama's Nyquist frequency).
    """
    cfg = method.config
    if cfg.butterworth_cutoff is None:
        return None
    if getattr(cfg, "butterworth_relative_to", "panorama") != "raw":
        return cfg.butterworth_cutoff
    from bionav.homing.imageops import panorama_cutoff_from_raw

    radius = getattr(method, "raw_horizon_radius_px", None)
    if radius is None:
        raise UserError(
            f"homing.butterworth_relative_to=raw needs the raw frame's horizon radius, which {method.name} was "
            "not given; run it through an experiment (python -m bionav experiment=grid_homing ...), which "
            "passes the database's, or set homing.butterworth_relative_to=panorama"
        )
    return panorama_cutoff_from_raw(cfg.butterworth_cutoff, width=int(width), raw_horizon_radius_px=radius)


def _prepare_image(method: HomingMethod, image):
    from bionav.homing.imageops import butterworth_lowpass, resize_panorama

    cfg = method.config
    img = _grey(image)
    cutoff = panorama_cutoff(method, img.shape[1])
    if cutoff is not None:
        # the warping methods' filter: applied twice (power response), float64 transform, no clipping
        img = butterworth_lowpass(img.astype(np.float64), cutoff=cutoff, order=cfg.butterworth_order,
                                  passes=2, clip=None)
    geometry = method.geometry
    if img.shape != (geometry.height, geometry.width):
        geometry = geometry.resized(img.shape[1], img.shape[0])
    return resize_panorama(img, geometry=geometry, size=cfg.image_size)


class _PlaneWarping(HomingMethod):
    """Shared parts of min-warping and 2D-warping (scale-plane stack per image)."""

    requires_alignment = False

    def __init__(self, config: Any, *, geometry, raw_horizon_radius_px: float | None = None) -> None:
        super().__init__(config, geometry=geometry)
        self.raw_horizon_radius_px = None if raw_horizon_radius_px is None else float(raw_horizon_radius_px)
        self._check()
        self._template = None
        self._template_width = None

    def _scales(self):
        """Checked ``(scales, thresholds)`` of the configuration (computed once per setting)."""
        cfg = self.config
        key = (None if cfg.scales is None else tuple(cfg.scales),
               None if cfg.thresholds is None else tuple(cfg.thresholds),
               getattr(cfg, "threshold_rule", "geometric"), getattr(cfg, "max_scale_ratio", None))
        cached = getattr(self, "_scales_cache", None)
        if cached is None or cached[0] != key:
            cached = (key, self._compute_scales())
            self._scales_cache = cached
        return cached[1]

    def _compute_scales(self):
        from bionav.homing.warping.scaleplanes import check_scales, default_scales, reference_thresholds

        cfg = self.config
        scales = default_scales() if cfg.scales is None else [float(x) for x in cfg.scales]
        thresholds = None if cfg.thresholds is None else [float(x) for x in cfg.thresholds]
        if thresholds is None and getattr(cfg, "threshold_rule", "geometric") == "reference":
            thresholds = reference_thresholds(scales, max_ratio=cfg.max_scale_ratio)
        return check_scales(scales, thresholds)

    def _check(self) -> None:
        cfg = self.config
        name = self.name
        try:
            self._scales()
        except ValueError as exc:
            raise UserError(
                f"bad homing.scales / homing.thresholds for {name}: {exc}. Give increasing scale "
                "factors and one threshold per factor with sigma_k < tau_k <= sigma_(k+1), or null "
                "for the defaults"
            ) from None
        width = cfg.image_size[0] if cfg.image_size is not None else self.geometry.width
        for key in ("n_alpha", "n_psi"):
            n = getattr(cfg, key)
            if not (1 <= n <= width):
                raise UserError(
                    f"homing.{key}={n} must lie between 1 and the image width {width} (the search "
                    f"shifts whole columns); e.g. homing.{key}={max(1, width // 3)}"
                )

    def prepare(self, image):
        """Resize (and low-pass) the panorama and build its scale-plane stack.

        Returns the dict of :func:`~bionav.homing.warping.scaleplanes.scale_plane_stack`.
        """
        from bionav.homing.warping import scale_plane_stack

        img, geometry = _prepare_image(self, image)
        scales, _ = self._scales()
        return scale_plane_stack(img, geometry=geometry, scales=scales)

    def _compass_fraction(self):
        cfg = self.config
        return cfg.compass_fraction if cfg.compass_acceleration else None

    def _cached_template(self, width: int, build):
        if self._template is None or self._template_width != width:
            self._template = build()
            self._template_width = width
        return self._template

    @staticmethod
    def _to_home_vector(result) -> HomeVector:
        extras = {"alpha": result.alpha, "score": result.score}
        if np.isfinite(result.rho):
            extras["rho"] = result.rho
        extras.update(result.extras)
        return HomeVector(angle=result.home_angle, compass=result.psi, extras=extras)


class MinWarping(_PlaneWarping):
    """Min-warping (Möller, Krzykawski & Gerstmayr 2010, doi:10.1007/s10514-010-9195-y).

    The holistic 2D-warping method without the equal-distance assumption, with
    visual compass. Defaults are the fast settings (288 x 50 pixels, 96 x 96
    search steps, 9 scale planes ``2 ** ((k - 4) / 4)``); the preset
    ``homing=minwarping_thesis`` holds the thesis' tables 5.1 and 5.2.
    """

    name = "minwarping"

    @dataclass
    class Config:
        """Parameters of min-warping.

        image_size: [W, H] the panorama is resized to (area averaging); null keeps it.
        butterworth_cutoff: relative cutoff of a Butterworth low-pass applied before
            resizing; null switches it off (thesis: 0.1, order 3).
        butterworth_order: order of that filter.
        butterworth_relative_to: panorama (the cutoff is relative to the loaded panorama's Nyquist
            frequency) or raw (relative to the raw camera frame's, as the thesis' 0.1: the same
            angular detail at every db.image_size; see bionav.homing.imageops.panorama_cutoff_from_raw).
        n_alpha, n_psi: search steps over 360 degrees for movement direction and rotation.
        scales: scale factors of the planes; null = 2 ** ((k - 4) / 4), k = 0..8.
        thresholds: upper scale thresholds per plane; null = by threshold_rule.
        threshold_rule: thresholds when none are given: reference (default: arithmetic means
            of neighbouring scales and a largest scale ratio max_scale_ratio, as WarpingSIMD and
            the thesis' table 5.2) or geometric (geometric means, no largest ratio).
        max_scale_ratio: largest allowed scale ratio of the reference rule.
        compass_acceleration: search only compass_fraction of the rotations, those the
            visual compass measure ranks best.
        compass_fraction: fraction of rotations searched with compass acceleration.
        fine_search: refine alpha and psi at one-column resolution.
        double_search: also search with snapshot and current view exchanged.
        quantised: 8-bit column distances summed in 16 bits, as the SIMD reference
            implementation (fast); false searches float32 distances (about 3x slower,
            home directions agree within one search step).
        """

        image_size: list[int] | None = bounded([288, 50], length=2, item=Range(ge=8, le=8192))
        butterworth_cutoff: float | None = bounded(None, gt=0.0, le=1.0)
        butterworth_order: int = bounded(3, ge=1, le=10)
        butterworth_relative_to: str = bounded("panorama", choices=BUTTERWORTH_RELATIVE_TO)
        n_alpha: int = bounded(96, ge=4, le=4096)
        n_psi: int = bounded(96, ge=4, le=4096)
        scales: list[float] | None = bounded(None, gt=0.0, le=100.0)
        thresholds: list[float] | None = bounded(None, gt=0.0, le=100.0)
        threshold_rule: str = bounded("reference", choices=THRESHOLD_RULES)
        max_scale_ratio: float = bounded(2.5, gt=1.0, le=100.0)
        compass_acceleration: bool = False
        compass_fraction: float = bounded(0.25, gt=0.0, le=1.0)
        fine_search: bool = False
        double_search: bool = False
        quantised: bool = True

    def _check(self) -> None:
        super()._check()
        cfg = self.config
        width = cfg.image_size[0] if cfg.image_size is not None else self.geometry.width
        if cfg.double_search and width % 2:
            raise UserError(
                f"homing.double_search needs an even image width, got {width}; "
                "change homing.image_size"
            )

    def home_vector(self, snapshot, current, *, neighbours=None) -> HomeVector:
        """Min-warping search; ``angle`` in the current view's frame, ``compass = psi``."""
        from bionav.homing.warping import minwarping
        from bionav.homing.warping.search import WINDOW_LEVEL
        from bionav.homing.warping.templates import minwarp_template, minwarp_windows

        cfg = self.config
        width = int(np.shape(snapshot["snap"])[-1])

        def build():
            scales, tau = self._scales()
            template = minwarp_template(width, scales, tau)
            return template, minwarp_windows(template, max_level=WINDOW_LEVEL)

        template, windows = self._cached_template(width, build)
        result = minwarping(
            snapshot,
            current,
            n_alpha=cfg.n_alpha,
            n_psi=cfg.n_psi,
            thresholds=self._scales()[1],
            compass_fraction=self._compass_fraction(),
            fine_search=cfg.fine_search,
            double_search=cfg.double_search,
            template=template,
            windows=windows,
            quantised=cfg.quantised,
        )
        return self._to_home_vector(result)


class Warping2D(_PlaneWarping):
    """2D-warping with the equal-distance assumption (Möller 2009, doi:10.1016/j.robot.2008.05.005).

    Searches movement direction, rotation and distance ratio ``rho``; visual
    compass included. Defaults as :class:`MinWarping` plus ``rho`` in
    ``0 .. 0.95`` in 20 steps (table 5.1).
    """

    name = "warping2d"

    @dataclass
    class Config:
        """Parameters of 2D-warping (see :class:`MinWarping.Config`; plus ``n_rho``, ``rho_max``)."""

        image_size: list[int] | None = bounded([288, 50], length=2, item=Range(ge=8, le=8192))
        butterworth_cutoff: float | None = bounded(None, gt=0.0, le=1.0)
        butterworth_order: int = bounded(3, ge=1, le=10)
        butterworth_relative_to: str = bounded("panorama", choices=BUTTERWORTH_RELATIVE_TO)
        n_alpha: int = bounded(96, ge=4, le=4096)
        n_psi: int = bounded(96, ge=4, le=4096)
        n_rho: int = bounded(20, ge=1, le=1000)
        rho_max: float = bounded(0.95, ge=0.0, lt=1.0)
        scales: list[float] | None = bounded(None, gt=0.0, le=100.0)
        thresholds: list[float] | None = bounded(None, gt=0.0, le=100.0)
        compass_acceleration: bool = False
        compass_fraction: float = bounded(0.25, gt=0.0, le=1.0)
        fine_search: bool = False

    def home_vector(self, snapshot, current, *, neighbours=None) -> HomeVector:
        """2D-warping search; ``angle`` in the current view's frame, ``compass = psi``."""
        from bionav.homing.warping import warping2d
        from bionav.homing.warping.search import rho_grid
        from bionav.homing.warping.templates import warp2d_template

        cfg = self.config
        width = int(np.shape(snapshot["snap"])[-1])

        def build():
            return warp2d_template(width, rho_grid(cfg.n_rho, cfg.rho_max), self._scales()[1])

        result = warping2d(
            snapshot,
            current,
            n_alpha=cfg.n_alpha,
            n_psi=cfg.n_psi,
            n_rho=cfg.n_rho,
            rho_max=cfg.rho_max,
            thresholds=self._scales()[1],
            compass_fraction=self._compass_fraction(),
            fine_search=cfg.fine_search,
            template=self._cached_template(width, build),
        )
        return self._to_home_vector(result)


class Warping1D(HomingMethod):
    """1D warping of the horizon strip (Franz et al. 1998), with visual compass.

    Defaults are Vardy's settings: 36 steps each for alpha, psi and rho, rho up to 0.95.
    """

    name = "warping1d"
    requires_alignment = False

    @dataclass
    class Config:
        """Parameters of 1D warping.

        image_size: [W, H] the panorama is resized to before the strip is taken.
        butterworth_cutoff, butterworth_order, butterworth_relative_to: optional low-pass before
            resizing (see :class:`MinWarping.Config`).
        strip_rows: rows around the horizon averaged into the strip.
        n_alpha, n_psi, n_rho: search steps; rho_max: largest distance ratio.
        """

        image_size: list[int] | None = bounded([288, 50], length=2, item=Range(ge=8, le=8192))
        butterworth_cutoff: float | None = bounded(None, gt=0.0, le=1.0)
        butterworth_order: int = bounded(3, ge=1, le=10)
        butterworth_relative_to: str = bounded("panorama", choices=BUTTERWORTH_RELATIVE_TO)
        strip_rows: int = bounded(5, ge=1, le=8192)
        n_alpha: int = bounded(36, ge=4, le=4096)
        n_psi: int = bounded(36, ge=4, le=4096)
        n_rho: int = bounded(36, ge=1, le=1000)
        rho_max: float = bounded(0.95, ge=0.0, lt=1.0)

    def __init__(self, config: Any, *, geometry, raw_horizon_radius_px: float | None = None) -> None:
        super().__init__(config, geometry=geometry)
        self.raw_horizon_radius_px = None if raw_horizon_radius_px is None else float(raw_horizon_radius_px)

    def prepare(self, image):
        """Resize (and low-pass) the panorama and average its horizon rows; shape (W,)."""
        from bionav.homing.imageops import horizon_strip

        img, geometry = _prepare_image(self, image)
        rows = min(self.config.strip_rows, img.shape[0])
        return horizon_strip(img, geometry=geometry, rows=rows)

    def home_vector(self, snapshot, current, *, neighbours=None) -> HomeVector:
        """1D-warping search; ``angle`` in the current view's frame, ``compass = psi``."""
        from bionav.homing.warping import warping1d

        cfg = self.config
        r = warping1d(
            snapshot, current, n_alpha=cfg.n_alpha, n_psi=cfg.n_psi, n_rho=cfg.n_rho, rho_max=cfg.rho_max
        )
        return HomeVector(
            angle=r.home_angle, compass=r.psi, extras={"alpha": r.alpha, "rho": r.rho, "score": r.score}
        )
