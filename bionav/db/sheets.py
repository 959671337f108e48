"""Pictures of a database for people: a contact sheet and a grid map (used by ``python -m bionav.db show``)."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from bionav.db.database import ImageDatabase


def contact_sheet(db: ImageDatabase, *, max_width: int = 3000, label: bool = True) -> np.ndarray:
    """Thumbnails of every image laid out like the grid (x to the right, y upwards).

    Each canonical panorama is shown with column 0 (the grid's +x direction)
    at its left edge and azimuth growing counter-clockwise to the right;
    missing cells are dark and crossed out.

    Parameters
    ----------
    db : ImageDatabase
    max_width : int
        Upper bound of the sheet width in pixels.
    label : bool
        Write ``x,y`` above each thumbnail.

    Returns
    -------
    ndarray, shape (Hs, Ws), uint8
    """
    nx, ny = db.grid_shape
    height, width = db.images.shape[1:3]
    gap = 4
    tw = int(max(32, min(width, (max_width - gap) // nx - gap)))
    th = max(4, int(round(height * tw / width)))
    lh = 14 if label else 0
    sheet = np.full((gap + ny * (th + lh + gap), gap + nx * (tw + gap)), 255, np.uint8)
    lut = db.cell_index_map()
    thumbs = np.stack([cv2.resize(img.astype(np.float32), (tw, th), interpolation=cv2.INTER_AREA)
                       for img in db.images]) if len(db) else np.zeros((0, th, tw), np.float32)
    thumbs = np.rint(np.clip(thumbs, 0.0, 1.0) * 255).astype(np.uint8)
    for x in range(nx):
        for y in range(ny):
            top = gap + (ny - 1 - y) * (th + lh + gap)
            left = gap + x * (tw + gap)
            tile = sheet[top + lh: top + lh + th, left: left + tw]
            idx = lut[x, y]
            if idx >= 0:
                tile[:] = thumbs[idx]
            else:
                tile[:] = 60
                cv2.line(tile, (0, 0), (tw - 1, th - 1), 120, 1)
                cv2.line(tile, (0, th - 1), (tw - 1, 0), 120, 1)
            if label:
                cv2.putText(sheet, f"{x},{y}", (left, top + lh - 3), cv2.FONT_HERSHEY_SIMPLEX, 0.4, 0, 1,
                            cv2.LINE_AA)
    return sheet


def grid_map_figure(db: ImageDatabase):
    """A matplotlib Figure showing which grid cells hold an image (x to the right, y upwards).

    Returns
    -------
    matplotlib.figure.Figure
        Not attached to pyplot; save it with ``fig.savefig(path)``.
    """
    from matplotlib.colors import ListedColormap
    from matplotlib.figure import Figure

    nx, ny = db.grid_shape
    exists = (db.cell_index_map() >= 0).T.astype(float)  # (ny, nx)
    scale = 0.45
    fig = Figure(figsize=(max(3.0, 1.6 + nx * scale), max(3.0, 1.2 + ny * scale)), dpi=100)
    ax = fig.add_subplot(1, 1, 1)
    ax.imshow(exists, origin="lower", cmap=ListedColormap(["#d9d9d9", "#2b7bba"]), vmin=0, vmax=1,
              extent=(-0.5, nx - 0.5, -0.5, ny - 0.5))
    ax.set_xticks(range(nx))
    ax.set_yticks(range(ny))
    ax.set_xticks(np.arange(-0.5, nx), minor=True)
    ax.set_yticks(np.arange(-0.5, ny), minor=True)
    ax.grid(which="minor", color="white", linewidth=1.0)
    ax.tick_params(which="minor", length=0)
    ax.tick_params(labelsize=7)
    ax.set_xlabel("x (grid cells)")
    ax.set_ylabel("y (grid cells)")
    ax.set_title(f"{db.name}: {len(db)} of {nx * ny} cells, spacing {db.spacing_m:g} m", fontsize=9)
    fig.tight_layout()
    return fig


def write_show(db: ImageDatabase, out_dir: Path) -> list[Path]:
    """Write ``<name>_contact.png`` and ``<name>_grid.png`` into ``out_dir``; return their paths."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    sheet_path = out_dir / f"{db.name}_contact.png"
    grid_path = out_dir / f"{db.name}_grid.png"
    if not cv2.imwrite(str(sheet_path), contact_sheet(db)):
        raise OSError(f"OpenCV could not write {sheet_path}")
    grid_map_figure(db).savefig(grid_path)
    return [sheet_path, grid_path]
