"""Per-image preprocessing shared by the warping methods: resize, low-pass, horizon strip.

All functions take canonical panoramas (see :mod:`bionav.geometry`): columns
span 360 degrees counter-clockwise, so filters wrap around horizontally.
"""

from __future__ import annotations

import numpy as np

from bionav.geometry import PanoramaGeometry


def resize_panorama(image, *, geometry: PanoramaGeometry, size):
    """Resize a canonical panorama with area averaging and update its geometry.

    Parameters
    ----------
    image : ndarray, shape (H, W)
        Canonical panorama.
    geometry : PanoramaGeometry
        Geometry of ``image``.
    size : sequence of two ints or None
        Target ``[W, H]`` in pixels; ``None`` keeps the image as it is.

    Returns
    -------
    image : ndarray, shape (H', W'), float32
        The resized panorama (``cv2.INTER_AREA``, which averages the source
        pixels each target pixel covers).
    geometry : PanoramaGeometry
        The geometry of the resized panorama (same field of view).
    """
    import cv2

    img = np.asarray(image, dtype=np.float32)
    if img.ndim != 2:
        raise ValueError(f"expected a grey-level panorama of shape (H, W), got shape {img.shape}")
    if size is None:
        return img, geometry
    width, height = int(size[0]), int(size[1])
    if width < 4 or height < 3:
        raise ValueError(f"image size [W, H] = {list(size)} is too small (need W >= 4, H >= 3)")
    if (width, height) == (img.shape[1], img.shape[0]):
        return img, geometry
    out = cv2.resize(img, (width, height), interpolation=cv2.INTER_AREA)
    return out.astype(np.float32, copy=False), geometry.resized(width, height)


def butterworth_lowpass(image, *, cutoff: float, order: int = 3):
    """Butterworth low-pass filter of a panorama, periodic around the azimuth.

    The gain is ``1 / (1 + (f / cutoff) ** (2 * order))`` where ``f`` is the
    radial spatial frequency relative to the Nyquist frequency (``f = 1`` at
    half a cycle per pixel), so ``cutoff = 1`` keeps nearly everything and
    ``cutoff = 0.1`` keeps a tenth of the band (the thesis' setting for
    min-warping, order 3; Möller 2009, doi:10.1016/j.robot.2008.05.005).
    Columns wrap around (the panorama is periodic in azimuth); rows are
    mirrored at the top and bottom to avoid wrap-around between them.

    Parameters
    ----------
    image : ndarray, shape (H, W)
        Canonical panorama.
    cutoff : float
        Relative cutoff frequency in ``(0, 1]``.
    order : int
        Filter order (>= 1).

    Returns
    -------
    ndarray, shape (H, W), float32
    """
    if not (0.0 < cutoff <= 1.0):
        raise ValueError(f"Butterworth cutoff must lie in (0, 1], got {cutoff}")
    if order < 1:
        raise ValueError(f"Butterworth order must be >= 1, got {order}")
    img = np.asarray(image, dtype=np.float64)
    h, _ = img.shape
    padded = np.concatenate([img, img[::-1]], axis=0)  # mirror rows: periodic and smooth
    fy = np.fft.fftfreq(padded.shape[0])[:, None] / 0.5
    fx = np.fft.rfftfreq(padded.shape[1])[None, :] / 0.5
    gain = 1.0 / (1.0 + (np.hypot(fx, fy) / cutoff) ** (2 * order))
    out = np.fft.irfft2(np.fft.rfft2(padded) * gain, s=padded.shape)[:h]
    return out.astype(np.float32)


def horizon_strip(image, *, geometry: PanoramaGeometry, rows: int = 5):
    """Average the rows around the horizon into a one-dimensional panorama.

    Parameters
    ----------
    image : ndarray, shape (H, W)
        Canonical panorama.
    geometry : PanoramaGeometry
        Its geometry (``horizon_row`` is used).
    rows : int
        Number of rows averaged, centred on the horizon row.

    Returns
    -------
    ndarray, shape (W,), float32
        Column ``j`` looks along azimuth ``2 pi j / W`` (CCW from the heading).
    """
    img = np.asarray(image, dtype=np.float32)
    h = img.shape[0]
    if rows < 1:
        raise ValueError(f"the horizon strip needs at least one row, got rows={rows}")
    lo = int(round(geometry.horizon_row - (rows - 1) / 2.0))
    lo = min(max(lo, 0), max(h - rows, 0))
    hi = min(lo + rows, h)
    return img[lo:hi].mean(axis=0).astype(np.float32)
