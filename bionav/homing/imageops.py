"""Image operations on canonical panoramas: the one home of resize, filters and the image-size check.

Every function takes canonical panoramas (:mod:`bionav.geometry`): columns
span 360 degrees counter-clockwise, so filters wrap around horizontally and
mirror at the top and bottom rows. Homing methods (per-image work) and the
database preprocessing chain (:mod:`bionav.db.preprocess`, thesis 5.2.1) both
use them.

* :func:`resize_panorama` (one image, geometry updated), :func:`resize_images` (a stack).
* :func:`butterworth_lowpass`, :func:`butterworth_response`, :func:`gaussian_lowpass`.
* :func:`edge_filter` (Sobel magnitude), :func:`vertical_difference` (the
  scale planes' vertical edge filter), :func:`equalize_histogram`.
* :func:`horizon_strip` -- the rows around the horizon averaged to one row.

scikit-image has each of these jobs; bionav does not use it (measured 2026-11-28 on 170 panoramas of
561 x 81, CPU time, scikit-image 0.26): ``skimage.filters.sobel`` gives the same magnitude (within
1e-7) only after the panorama is padded to wrap around, at 2.1 times the CPU time;
``skimage.exposure.equalize_hist`` maps by another formula than OpenCV's ``equalizeHist`` (up to 0.014
apart) at 4 times the time; ``skimage.filters.butterworth`` pads the image edges, so it does not wrap
the 360-degree azimuth; ``skimage.transform.resize_local_mean`` equals ``cv2.INTER_AREA`` at 6 times
the time.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from bionav.errors import UserError
from bionav.geometry import PanoramaGeometry

__all__ = [
    "butterworth_lowpass",
    "butterworth_response",
    "edge_filter",
    "equalize_histogram",
    "gaussian_lowpass",
    "horizon_strip",
    "resize_images",
    "resize_panorama",
    "vertical_difference",
]


def resize_images(images: np.ndarray, size: Sequence[int]) -> np.ndarray:
    """Resize every image to ``size = [W, H]`` with area averaging (``cv2.INTER_AREA``).

    Parameters
    ----------
    images : ndarray, shape (N, H, W) or (H, W), float
    size : sequence of 2 int
        Target ``(W, H)``, both positive.

    Returns
    -------
    ndarray, shape (N, H', W') or (H', W'), float32
    """
    import cv2

    width, height = (int(v) for v in size)
    if width < 1 or height < 1:
        raise ValueError(f"image size [W, H] must be positive, got {list(size)}")
    images = np.asarray(images, dtype=np.float32)
    if images.ndim == 2:
        return cv2.resize(images, (width, height), interpolation=cv2.INTER_AREA)
    if images.shape[-2:] == (height, width):
        return images.copy()
    out = np.empty((*images.shape[:-2], height, width), dtype=np.float32)
    flat_in = images.reshape(-1, *images.shape[-2:])
    flat_out = out.reshape(-1, height, width)
    for i, image in enumerate(flat_in):  # OpenCV 5 resizes at most 4 channels per call
        flat_out[i] = cv2.resize(image, (width, height), interpolation=cv2.INTER_AREA)
    return out


def resize_panorama(image: np.ndarray, *, geometry: PanoramaGeometry, size: Sequence[int] | None
                    ) -> tuple[np.ndarray, PanoramaGeometry]:
    """Resize one canonical panorama with area averaging and adapt its geometry.

    Parameters
    ----------
    image : ndarray, shape (H, W) or (H, W, C)
        Canonical panorama.
    geometry : PanoramaGeometry
        Geometry of ``image``.
    size : sequence of two ints or None
        Target ``[W, H]`` in pixels; ``None``, or the image's own size, returns
        the inputs unchanged.

    Returns
    -------
    image : ndarray, shape (H', W') or (H', W', C), float32 when resized
        The resized panorama (``cv2.INTER_AREA`` averages the source pixels
        each target pixel covers).
    geometry : PanoramaGeometry
        The geometry of the resized panorama (same field of view).
    """
    if size is None:
        return image, geometry
    import cv2

    width, height = int(size[0]), int(size[1])
    if width < 1 or height < 1:
        raise ValueError(f"image size [W, H] must be positive, got {list(size)}")
    if (width, height) == (geometry.width, geometry.height) and np.shape(image)[:2] == (height, width):
        return image, geometry
    out = cv2.resize(np.ascontiguousarray(image, dtype=np.float32), (width, height), interpolation=cv2.INTER_AREA)
    return out.astype(np.float32, copy=False), geometry.resized(width, height)


def butterworth_response(fx, fy, *, order: int, cutoff: float) -> np.ndarray:
    """Magnitude response of the 2-D Butterworth low-pass filter.

    ``|G| = 1 / sqrt(1 + (rho / cutoff) ** (2 * order))`` with
    ``rho = sqrt(fx**2 + fy**2) / 0.5``: the radial spatial frequency relative
    to the Nyquist frequency (0.5 cycles per pixel). The filter is zero-phase;
    ``|G| = 1/sqrt(2)`` at ``rho = cutoff``.

    Parameters
    ----------
    fx, fy : array_like
        Frequencies in cycles per pixel along columns and rows.
    order : int
        Filter order ``n >= 1``.
    cutoff : float
        Relative cutoff frequency (1.0 = Nyquist).
    """
    rho = np.hypot(np.asarray(fx, dtype=np.float64), np.asarray(fy, dtype=np.float64)) / 0.5
    return 1.0 / np.sqrt(1.0 + (rho / cutoff) ** (2 * order))


def panorama_cutoff_from_raw(cutoff: float, *, width: int, raw_horizon_radius_px: float) -> float:
    """A Butterworth cutoff relative to the raw frame's Nyquist frequency, as one relative to a panorama's.

    ``cutoff_panorama = cutoff * 2 pi r_h / W``: a frequency of ``cutoff / 2``
    cycles per raw pixel on the raw horizon circle (radius ``r_h`` pixels) is
    ``pi r_h cutoff`` cycles per revolution, whatever the panorama width ``W``.

    Parameters
    ----------
    cutoff : float
        Relative to the raw frame's Nyquist frequency (thesis 5.2.1: bw1 0.03, bw2 0.015).
    width : int
        Panorama width ``W`` in pixels (columns per 360 degrees).
    raw_horizon_radius_px : float
        Radius of the horizon circle in the raw frame, pixels.

    Returns
    -------
    float
        Cutoff relative to the panorama's Nyquist frequency (0.5 cycles per pixel).
    """
    return float(cutoff) * 2.0 * np.pi * float(raw_horizon_radius_px) / int(width)


def butterworth_lowpass(images, *, cutoff: float, order: int = 1, passes: int = 1,
                        clip: tuple[float, float] | None = (0.0, 1.0)) -> np.ndarray:
    """Butterworth low-pass filter of panoramas in the frequency domain.

    The image is periodic in x (360 degrees); in y it is extended by its
    mirror image (half-sample symmetric, period ``2H``) so that the top and
    bottom rows do not leak into each other. The 2-D spectrum is multiplied
    by :func:`butterworth_response` to the power ``passes``: ``passes=2`` is
    the filter applied twice (power response ``1 / (1 + (rho / cutoff) **
    (2 n))``, used by the warping methods; Möller 2009,
    doi:10.1016/j.robot.2008.05.005). The thesis' database presets (5.2.1)
    use one pass of order 1 or 2.

    Parameters
    ----------
    images : ndarray, shape (N, H, W) or (H, W)
        Panoramas. The transform runs in float64 for float64 input and in
        float32 otherwise.
    cutoff : float
        Relative cutoff frequency, > 0 (1.0 = Nyquist frequency).
    order : int
        Filter order (1, 2, 3, ...).
    passes : int
        How often the filter is applied (>= 1).
    clip : (float, float) or None
        Range the result is clipped to (default ``[0, 1]``, the range of
        bionav's images); ``None`` keeps over- and undershoots.

    Returns
    -------
    ndarray, same shape, float32
    """
    if int(order) < 1 or not cutoff > 0 or int(passes) < 1:
        raise ValueError(f"butterworth_lowpass needs order >= 1, cutoff > 0 and passes >= 1 "
                         f"(got order={order}, cutoff={cutoff}, passes={passes})")
    work = np.float64 if np.asarray(images).dtype == np.float64 else np.float32
    images = np.asarray(images, dtype=work)
    height, width = images.shape[-2:]
    rho = np.hypot(np.fft.rfftfreq(width)[None, :], np.fft.fftfreq(2 * height)[:, None]) / 0.5
    inverse_power = 1.0 + (rho / float(cutoff)) ** (2 * int(order))  # 1 / |G|^2 (butterworth_response)
    gain = (1.0 / np.sqrt(inverse_power) if int(passes) == 1 else 1.0 / inverse_power ** (int(passes) / 2))
    gain = gain.astype(work)
    stack = images.reshape(-1, height, width)
    out = np.empty_like(stack)
    chunk = 32  # bounds the memory of the complex spectra
    for start in range(0, stack.shape[0], chunk):
        block = stack[start:start + chunk]
        ext = np.concatenate([block, block[:, ::-1, :]], axis=1)
        spec = np.fft.rfft2(ext, axes=(-2, -1))
        out[start:start + chunk] = np.fft.irfft2(spec * gain, s=(2 * height, width), axes=(-2, -1))[:, :height]
    out = out.reshape(images.shape)
    if clip is not None:
        out = np.clip(out, clip[0], clip[1])
    return out.astype(np.float32)


def gaussian_lowpass(image: np.ndarray, *, sigma_azimuth: float, sigma_elevation: float = 0.0) -> np.ndarray:
    """Gaussian low-pass of a panorama ``(H, W)``, sigmas in pixels.

    Cyclic along the azimuth (columns), reflected at the top and bottom rows.
    """
    if sigma_azimuth <= 0 and sigma_elevation <= 0:
        return image
    from scipy.ndimage import gaussian_filter

    return gaussian_filter(
        image.astype(np.float32), sigma=(sigma_elevation, sigma_azimuth), mode=("reflect", "wrap")
    )


def edge_filter(images: np.ndarray, *, method: str = "sobel") -> np.ndarray:
    """Edge filter: Sobel gradient magnitude, cyclic in x, mirrored at the top and bottom rows.

    ``E = sqrt(Gx**2 + Gy**2) / (4 * sqrt(2))`` with the 3 x 3 Sobel kernels,
    so that an input in ``[0, 1]`` gives an output in ``[0, 1]``.

    Parameters
    ----------
    images : ndarray, shape (N, H, W) or (H, W), float
    method : {"sobel"}

    Returns
    -------
    ndarray, same shape, float32
    """
    if method != "sobel":
        raise UserError(f"edges: unknown method {method!r}; the edge filter knows method=sobel.")
    images = np.asarray(images, dtype=np.float32)
    pad = [(0, 0)] * (images.ndim - 2)
    p = np.pad(images, pad + [(1, 1), (0, 0)], mode="reflect" if images.shape[-2] > 1 else "edge")
    p = np.pad(p, pad + [(0, 0), (1, 1)], mode="wrap")
    col = p[..., :-2, :] + 2.0 * p[..., 1:-1, :] + p[..., 2:, :]  # vertical smoothing
    gx = col[..., 2:] - col[..., :-2]
    row = p[..., :-2] + 2.0 * p[..., 1:-1] + p[..., 2:]  # horizontal smoothing
    gy = row[..., 2:, :] - row[..., :-2, :]
    return (np.sqrt(gx * gx + gy * gy) / np.float32(4.0 * np.sqrt(2.0))).astype(np.float32)


def vertical_difference(image) -> np.ndarray:
    """Vertical edge filter of the scale planes: ``out[r] = image[r + 1] - image[r]``.

    Parameters
    ----------
    image : ndarray, shape (H, W)

    Returns
    -------
    ndarray, shape (H - 1, W), float32
    """
    img = np.asarray(image, dtype=np.float32)
    return np.diff(img, axis=0).astype(np.float32)


def equalize_histogram(images: np.ndarray, *, levels: int = 256) -> np.ndarray:
    """Histogram equalisation of every image separately (OpenCV's ``equalizeHist`` formula).

    Each image is quantised to ``levels`` grey levels ``q = round(v * (levels - 1))``;
    with the cumulative histogram ``cdf`` and its value ``cdf_min`` at the
    lowest occupied level, level ``q`` maps to
    ``round((cdf[q] - cdf_min) * (levels - 1) / (n_pixels - cdf_min)) / (levels - 1)``.
    A constant image stays unchanged. For ``levels=256`` this equals
    ``cv2.equalizeHist`` on the 8-bit image.

    Parameters
    ----------
    images : ndarray, shape (N, H, W) or (H, W), float in [0, 1]
    levels : int

    Returns
    -------
    ndarray, same shape, float32 in [0, 1]
    """
    images = np.asarray(images, dtype=np.float32)
    single = images.ndim == 2
    stack = images[None] if single else images.reshape(-1, *images.shape[-2:])
    n, top = stack.shape[0], int(levels) - 1
    q = np.rint(np.clip(stack, 0.0, 1.0) * top).astype(np.int64).reshape(n, -1)
    hist = np.bincount((q + (np.arange(n) * levels)[:, None]).ravel(), minlength=n * levels).reshape(n, levels)
    cdf = np.cumsum(hist, axis=1)
    total = q.shape[1]
    first = np.argmax(hist > 0, axis=1)
    cdf_min = hist[np.arange(n), first]
    denom = np.maximum(total - cdf_min, 1).astype(np.float32)
    scale = np.float32(top) / denom
    lut = np.rint((cdf - cdf_min[:, None]).astype(np.float32) * scale[:, None])
    lut = np.clip(lut, 0, top)
    constant = cdf_min == total
    lut[constant] = np.arange(levels, dtype=np.float32)[None, :]
    out = np.take_along_axis(lut, q, axis=1).reshape(stack.shape) / np.float32(top)
    out = out.astype(np.float32)
    return out[0] if single else out.reshape(images.shape)


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
