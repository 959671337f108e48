"""2-D scans of the five-channel sensor on a pan-tilt unit, contrast images and their stability (thesis 6.4).

The sensor on the pan-tilt unit samples a grid of pan and tilt angles column by
column (for each pan angle all tilt angles, "tilt-pan" order). Every reading
becomes one pixel of five channel images (row 0 = highest tilt; column index
grows with the pan angle, i.e. counter-clockwise, as in bionav's canonical
panoramas). Contrast images are differences of two channel images (log
signals); separation images classify every pixel as sky or object with a
linear discriminant learned on labelled samples (thesis: ``J_sigma`` lines of
the natural samples), at the learned threshold (``threshold="learned"``, the
thesis' "global" separation) or at a threshold adapted to each image along the
learned direction (``threshold="local"``, beyond the thesis; see
:func:`image_discriminant`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Callable

import numpy as np

from bionav.light.bands import CHANNELS, dual_contrasts, feature_subsets
from bionav.spectral.stability import stability_measures
from bionav.stats.threshold import otsu_threshold

#: How a separation image places the class border on the discriminant's direction.
THRESHOLDS = ("learned", "local")

#: The 14 scan times of the thesis' one-day dataset (Wed 17 June 2009, appendix D.3), local time.
ONE_DAY_TIMES = (
    "2009-06-17T11:27:04+02:00", "2009-06-17T12:06:19+02:00", "2009-06-17T12:46:02+02:00",
    "2009-06-17T13:25:05+02:00", "2009-06-17T14:07:52+02:00", "2009-06-17T14:47:21+02:00",
    "2009-06-17T15:26:36+02:00", "2009-06-17T16:07:15+02:00", "2009-06-17T16:46:10+02:00",
    "2009-06-17T17:26:10+02:00", "2009-06-17T18:44:09+02:00", "2009-06-17T19:24:41+02:00",
    "2009-06-17T20:03:57+02:00", "2009-06-17T20:43:36+02:00",
)


@dataclass(frozen=True)
class ScanGrid:
    """Pan and tilt angles of a scan (radians, ascending).

    Attributes
    ----------
    pans : ndarray, shape (W,)
        Pan angles, radians counter-clockwise; image column ``j`` is ``pans[j]``.
    tilts : ndarray, shape (H,)
        Tilt angles (elevation of the optical axis), radians; image row ``r`` is
        ``tilts[H - 1 - r]`` (row 0 on top).
    """

    pans: np.ndarray
    tilts: np.ndarray

    @classmethod
    def from_steps(cls, *, n_pan: int = 113, pan_step: float = np.deg2rad(2.0), n_tilt: int = 26,
                   tilt_step: float = np.deg2rad(3.0), tilt_start: float = np.deg2rad(-45.0),
                   pan_centre: float = 0.0) -> "ScanGrid":
        """Regular grid: ``n_pan`` pan steps centred on ``pan_centre``, ``n_tilt`` tilt steps upwards
        from ``tilt_start`` (thesis 6.4.1: 113 x 26 steps of 2 and 3 degrees)."""
        pans = pan_centre + (np.arange(n_pan) - (n_pan - 1) / 2) * pan_step
        tilts = tilt_start + np.arange(n_tilt) * tilt_step
        return cls(pans, tilts)

    @property
    def shape(self) -> tuple[int, int]:
        """Image shape ``(H, W)``."""
        return len(self.tilts), len(self.pans)

    def angles(self) -> tuple[np.ndarray, np.ndarray]:
        """Pan and tilt of every pixel, each of shape ``(H, W)``."""
        p, t = np.meshgrid(self.pans, self.tilts[::-1])
        return p, t


class DirectPanTilt:
    """An ideal pan-tilt unit for simulations without ``pantilt=``: moves exactly and instantly
    and aims the attached scene (``scene.set_pose``)."""

    schema_name = "bionav.PanTiltState"

    def __init__(self, scene=None) -> None:
        self.scene = scene

    def attach_simulation(self, scene, rng) -> None:
        self.scene = scene

    def open(self) -> None:
        pass

    def close(self) -> None:
        pass

    def __enter__(self) -> "DirectPanTilt":
        return self

    def __exit__(self, *exc) -> None:
        pass

    def move_to(self, pan: float, tilt: float) -> dict:
        if self.scene is not None:
            self.scene.set_pose(pan, tilt)
        return {"pan_pos": 0, "tilt_pos": 0, "pan": float(pan), "tilt": float(tilt),
                "pan_cmd": float(pan), "tilt_cmd": float(tilt)}


def run_scan(sensor, pantilt, grid: ScanGrid, *, before_column: Callable[[int], None] | None = None,
             on_move: Callable[[dict], None] | None = None, on_reading: Callable[[dict], None] | None = None,
             progress=None) -> np.ndarray:
    """Scan the grid column by column and assemble the channel images.

    Parameters
    ----------
    sensor : object
        ``read() -> {"counts": [[uv, b, g, r, ir, ref], ...]}`` (a spectral5 plugin or a replay).
    pantilt : object
        ``move_to(pan, tilt) -> state dict`` (radians).
    grid : ScanGrid
    before_column : callable, optional
        ``before_column(j)`` before the unit turns to column ``j`` (simulations
        advance their clock here).
    on_move, on_reading : callable, optional
        Receive every pan-tilt state and raw reading as they happen (recording).
    progress : callable, optional
        ``progress(iterable, desc=..., total=...)`` wrapper for the column loop.

    Returns
    -------
    ndarray, shape (H, W, 6), float
        Mean counts (over the readings of one measure command) per pixel:
        ``uv, b, g, r, ir, ref``.
    """
    from bionav.spectral.protocol import reading_counts

    h, w = grid.shape
    out = np.empty((h, w, 6))
    columns = range(w)
    if progress is not None:
        columns = progress(columns, desc="scan columns", total=w)
    for j in columns:
        if before_column is not None:
            before_column(j)
        for i, tilt in enumerate(grid.tilts):
            state = pantilt.move_to(float(grid.pans[j]), float(tilt))
            if on_move is not None:
                on_move(state)
            msg = sensor.read()
            if on_reading is not None:
                on_reading(msg)
            out[h - 1 - i, j] = reading_counts(msg).mean(axis=0)
    return out


def feature_images(counts) -> dict[str, np.ndarray]:
    """Single-channel images and dual-channel contrast images of a scan.

    Parameters
    ----------
    counts : array_like, shape (H, W, >=5)
        Channel counts (log signals) UV, B, G, R, IR.

    Returns
    -------
    dict
        ``"UV"`` .. ``"IR"``: the channel images; ``"UV-B"`` .. ``"R-IR"``: the
        contrasts ``X - Y`` (counts), each of shape ``(H, W)``.
    """
    c = np.asarray(counts, dtype=float)
    out = {name: c[..., i] for i, name in enumerate(CHANNELS)}
    for name, (i, j) in dual_contrasts().items():
        out[name] = c[..., i] - c[..., j]
    return out


def image_discriminant(counts, feature: str, discriminant, *, threshold: str = "learned"):
    """The discriminant that separates one image: the learned one, or its direction with the image's own threshold.

    Parameters
    ----------
    counts : array_like, shape (..., >=5)
        Channel counts UV, B, G, R, IR (log signals) of one image (any pixel shape).
    feature : str
        ``"UV"``, ``"UV-IR"``, ``"all"``, ... (:func:`bionav.light.bands.feature_subsets`).
    discriminant : bionav.stats.LinearDiscriminant
        Fitted on that feature's channels, sky = class 1 (above the threshold).
    threshold : {"learned", "local"}
        ``"learned"``: the discriminant's own threshold, learned on labelled
        samples (the thesis' separation; Differt & Moeller's "global" one).
        ``"local"``: the learned *direction*, with the threshold chosen on this
        image alone by Otsu's criterion (:func:`bionav.stats.otsu_threshold`), so
        that it follows the light of the moment -- at dusk the whole scene,
        sky and objects, moves along the direction, and a day-time threshold
        calls the reddened sky near a low sun an object. Differt & Moeller
        (2016), doi:10.3390/s16101614, found such per-image ("local")
        thresholds more reliable than fixed ("global") ones for skylines
        recorded over whole days. It assumes the image shows both sky and
        objects (a panoramic scan does); an image of one value keeps the
        learned threshold.

    Returns
    -------
    bionav.stats.LinearDiscriminant
        ``discriminant`` itself, or a copy with the image's threshold.
    """
    if _check_threshold(threshold) == "learned":
        return discriminant
    y, _ = _projection(counts, feature, discriminant)
    return replace(discriminant, threshold=_border(y, discriminant, threshold))


def _check_threshold(threshold: str) -> str:
    if threshold not in THRESHOLDS:
        raise ValueError(f"threshold must be one of {', '.join(THRESHOLDS)}, got {threshold!r}")
    return threshold


def _projection(counts, feature: str, discriminant) -> tuple[np.ndarray, tuple[int, ...]]:
    """Every pixel projected on the discriminant's direction, flat, and the pixel shape."""
    c = np.asarray(counts, dtype=float)
    sub = list(feature_subsets()[feature])
    return discriminant.project(c[..., sub].reshape(-1, len(sub))), c.shape[:-1]


def _border(y: np.ndarray, discriminant, threshold: str) -> float:
    """The learned threshold, or Otsu's of the projected pixels ``y`` (the learned one if ``y`` is constant)."""
    if threshold == "local" and y.size > 1 and np.ptp(y) > 0:
        return otsu_threshold(y)
    return float(discriminant.threshold)


def sky_mask(counts, feature: str, discriminant, *, threshold: str = "learned") -> np.ndarray:
    """Sky/object classification of one image by one feature's linear discriminant.

    Parameters
    ----------
    counts : array_like, shape (..., >=5)
        Channel counts of one image (any pixel shape).
    feature : str
        The discriminant's feature (:func:`bionav.light.bands.feature_subsets`).
    discriminant : bionav.stats.LinearDiscriminant
        Sky = class 1.
    threshold : {"learned", "local"}
        The class border on the discriminant's direction (:func:`image_discriminant`).

    Returns
    -------
    ndarray of bool, shape ``counts.shape[:-1]``
        True where classified as sky.
    """
    y, shape = _projection(counts, feature, discriminant)
    return (y > _border(y, discriminant, _check_threshold(threshold))).reshape(shape)


def separation_images(counts, discriminants: dict, *, threshold: str = "learned") -> dict[str, np.ndarray]:
    """Sky/object classification of every pixel per feature.

    Parameters
    ----------
    counts : array_like, shape (H, W, >=5)
    discriminants : dict
        Feature name -> fitted :class:`bionav.stats.LinearDiscriminant` (sky =
        class 1) on that feature's channels (see
        :func:`bionav.light.bands.feature_subsets`).
    threshold : {"learned", "local"}
        The class border on each discriminant's direction (:func:`image_discriminant`).

    Returns
    -------
    dict
        Feature name -> bool image ``(H, W)``, True where classified as sky.
    """
    c = np.asarray(counts, dtype=float)
    return {name: sky_mask(c, name, lda, threshold=threshold) for name, lda in discriminants.items()}


def stability_series(scans, separations=None, *, names=None) -> list[dict]:
    """Stability measures of every feature of every scan against the first scan (thesis 6.4.2/6.4.3).

    Parameters
    ----------
    scans : array_like, shape (T, H, W, >=5)
        Channel counts of T scans of one scene, the first is the reference.
    separations : sequence of dict, optional
        Per scan, feature -> bool sky image ``(H, W)`` (:func:`separation_images`);
        when given, the measures are also computed on the separation images
        (sky 0, object 1) of every feature in ``names``.
    names : sequence of str, optional
        Features to evaluate; default the 5 channels and 10 dual contrasts.

    Returns
    -------
    list of dict
        One row per (scan k >= 1, feature, separated): ``scan``, ``feature``,
        ``separated`` and the seven measures of :func:`~bionav.spectral.stability.stability_measures`.
    """
    scans = np.asarray(scans, dtype=float)
    if separations is not None and len(separations) != len(scans):
        raise ValueError(f"{len(separations)} separations for {len(scans)} scans")
    ref = feature_images(scans[0])
    names = list(names or ref)
    rows = []
    for k in range(1, len(scans)):
        cur = feature_images(scans[k])
        for n in names:
            rows.append({"scan": k, "feature": n, "separated": False, **stability_measures(ref[n], cur[n])})
            if separations is not None:
                a = (~separations[0][n]).astype(float)
                b = (~separations[k][n]).astype(float)
                rows.append({"scan": k, "feature": n, "separated": True, **stability_measures(a, b)})
    return rows
