"""SIFT features of panoramas: the one feature type and the one detector of SIFT homing and HiSS.

Lowe, D. G. (2004). Distinctive image features from scale-invariant keypoints.
IJCV 60(2), 91-110. doi:10.1023/B:VISI.0000029664.99615.94 (OpenCV's
``cv2.SIFT_create``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["SiftFeatures", "sift_features"]


@dataclass(frozen=True)
class SiftFeatures:
    """Keypoints of one panorama.

    Attributes
    ----------
    xy : ndarray, shape (N, 2), float32
        Pixel coordinates (column, row) of the keypoints; column ``x`` looks
        along azimuth ``2 pi x / W`` counter-clockwise from the heading.
    descriptors : ndarray, shape (N, 128), float32
        SIFT descriptors.
    sq_norms : ndarray, shape (N,), float32
        Squared descriptor norms (for fast distance matrices).
    size : ndarray, shape (N,), float32
        Keypoint diameters in pixels (NaN when not given).
    width : ndarray, 0-d int64
        Width ``W`` of the panorama (-1 when not given).
    """

    xy: np.ndarray
    descriptors: np.ndarray
    sq_norms: np.ndarray
    size: np.ndarray | None = None
    width: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.size is None:
            object.__setattr__(self, "size", np.full(len(self.xy), np.nan, np.float32))
        if self.width is None:
            object.__setattr__(self, "width", np.array(-1, dtype=np.int64))


def sift_features(
    image: np.ndarray,
    *,
    wrap_pad: float | None = None,
    n_features: int = 0,
    contrast_threshold: float = 0.04,
    edge_threshold: float = 10.0,
    sigma: float = 1.6,
    n_octave_layers: int = 3,
) -> SiftFeatures:
    """OpenCV SIFT keypoints and descriptors of a panorama.

    Parameters
    ----------
    image : ndarray, shape (H, W), float in [0, 1] or uint8
        Canonical panorama (float images are scaled by 255 and rounded).
    wrap_pad : float or None
        ``None``: SIFT runs on the image as it is. A fraction in ``[0, 1]``:
        the panorama is padded on both sides with ``wrap_pad * W`` columns
        from the other end, SIFT runs on the padded image and only keypoints
        centred in the original columns are kept (``x`` wrapped to
        ``[0, W)``), so features are seamless across the 0/360 degree border.
    n_features, contrast_threshold, edge_threshold, sigma, n_octave_layers
        Passed to ``cv2.SIFT_create`` (``n_features = 0``: all).

    Returns
    -------
    SiftFeatures
    """
    import cv2

    img = np.asarray(image)
    width = img.shape[1] if img.ndim >= 2 else 0
    pad = 0
    if wrap_pad is not None:
        if img.ndim != 2:
            raise ValueError(f"expected a grey-level panorama of shape (H, W), got shape {img.shape}")
        pad = int(round(wrap_pad * width))
        if pad < 0 or pad > width:
            raise ValueError(f"wrap_pad must lie in [0, 1], got {wrap_pad}")
        if pad:
            img = np.concatenate([img[:, width - pad:], img, img[:, :pad]], axis=1)
    u8 = img if img.dtype == np.uint8 else np.clip(np.rint(img * 255.0), 0, 255).astype(np.uint8)
    sift = cv2.SIFT_create(
        nfeatures=int(n_features),
        nOctaveLayers=int(n_octave_layers),
        contrastThreshold=float(contrast_threshold),
        edgeThreshold=float(edge_threshold),
        sigma=float(sigma),
    )
    keypoints, descriptors = sift.detectAndCompute(u8, None)
    w = np.array(width, dtype=np.int64)
    if descriptors is None or len(keypoints) == 0:
        return SiftFeatures(np.zeros((0, 2), np.float32), np.zeros((0, 128), np.float32), np.zeros(0, np.float32),
                            np.zeros(0, np.float32), w)
    xy = np.array([kp.pt for kp in keypoints], dtype=np.float32).reshape(-1, 2)
    size = np.array([kp.size for kp in keypoints], dtype=np.float32)
    descriptors = descriptors.astype(np.float32)
    if wrap_pad is not None:
        x = xy[:, 0] - pad
        keep = (x >= -0.5) & (x < width - 0.5)
        xy = np.stack([x[keep] % width, xy[keep, 1]], axis=1).astype(np.float32)
        size, descriptors = size[keep], descriptors[keep]
    xy, descriptors, size = (np.ascontiguousarray(a) for a in (xy, descriptors, size))
    return SiftFeatures(xy, descriptors, np.einsum("ij,ij->i", descriptors, descriptors), size, w)
