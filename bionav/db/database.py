"""The in-memory image database every homing experiment works on."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from bionav.geometry import PanoramaGeometry


@dataclass
class ImageDatabase:
    """A grid of canonical panoramic images (see :mod:`bionav.geometry`).

    Parameters
    ----------
    name : str
        Database name (``sim_original``, ``hall1``, a folder name ...).
    images : ndarray, shape (N, H, W) or (N, H, W, C), float32 in [0, 1]
        Canonical panoramas: column 0 looks along the robot's heading, azimuth
        grows counter-clockwise with the column index.
    positions : ndarray, shape (N, 2), int
        Grid cell ``(x, y)`` of every image. Missing cells are simply absent.
    grid_shape : tuple of int
        ``(nx, ny)``: number of grid cells along x and y (the declared grid,
        which may hold fewer than ``nx * ny`` images).
    geometry : PanoramaGeometry
        Pixel geometry of the images.
    spacing_m : float
        Distance between neighbouring grid cells in metres.
    headings : ndarray, shape (N,), optional
        Heading of the robot (radians CCW from grid +x) when each image was
        taken. Zero for aligned databases; non-zero after a random rotation of
        current views.
    raw : callable, optional
        ``raw(i) -> ndarray`` returning the raw (mirror) camera image of image
        ``i`` for signatures that the thesis computes on the raw image.
    meta : dict
        Free-form provenance (world parameters, source folder, preprocessing).
    """

    name: str
    images: np.ndarray
    positions: np.ndarray
    grid_shape: tuple[int, int]
    geometry: PanoramaGeometry
    spacing_m: float = 1.0
    headings: np.ndarray | None = None
    raw: Callable[[int], np.ndarray] | None = None
    meta: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.positions = np.asarray(self.positions, dtype=np.int64).reshape(-1, 2)
        if self.headings is None:
            self.headings = np.zeros(len(self.positions))
        if len(self.images) != len(self.positions):
            raise ValueError(
                f"database {self.name!r}: {len(self.images)} images but {len(self.positions)} positions"
            )

    def __len__(self) -> int:
        return len(self.positions)

    def index_of(self, x: int, y: int) -> int | None:
        """Index of the image at grid cell ``(x, y)``, or ``None`` if the cell is missing."""
        hit = np.flatnonzero((self.positions[:, 0] == x) & (self.positions[:, 1] == y))
        return int(hit[0]) if hit.size else None

    def cell_index_map(self) -> np.ndarray:
        """Array of shape ``(nx, ny)`` holding the image index per cell, -1 where missing."""
        lut = np.full(self.grid_shape, -1, dtype=np.int64)
        lut[self.positions[:, 0], self.positions[:, 1]] = np.arange(len(self.positions))
        return lut

    def subset(self, indices) -> "ImageDatabase":
        """A database holding only the given image indices (same grid and geometry)."""
        idx = np.asarray(indices, dtype=np.int64)
        return ImageDatabase(
            name=self.name,
            images=self.images[idx],
            positions=self.positions[idx],
            grid_shape=self.grid_shape,
            geometry=self.geometry,
            spacing_m=self.spacing_m,
            headings=self.headings[idx],
            raw=None if self.raw is None else (lambda i, _r=self.raw, _m=idx: _r(int(_m[i]))),
            meta=dict(self.meta),
        )
