"""Small image operations homing plugins share (resize, low-pass) on canonical panoramas."""

from __future__ import annotations

import numpy as np

from bionav.geometry import PanoramaGeometry


def resize_panorama(
    image: np.ndarray, geometry: PanoramaGeometry, size: tuple[int, int] | list[int] | None
) -> tuple[np.ndarray, PanoramaGeometry]:
    """Resize a canonical panorama to ``size = (W, H)`` (area averaging) and adapt its geometry.

    ``size=None`` returns the inputs unchanged.
    """
    if size is None:
        return image, geometry
    import cv2

    w, h = int(size[0]), int(size[1])
    if (w, h) == (geometry.width, geometry.height):
        return image, geometry
    out = cv2.resize(np.ascontiguousarray(image, dtype=np.float32), (w, h), interpolation=cv2.INTER_AREA)
    return out, geometry.resized(w, h)


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
