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


def camera_sheet(name: str, *, camera, pose_error, seed: int = 0, image_size=None, n_cells: int = 3,
                 threads: int | None = 2) -> np.ndarray:
    """Raw mirror frames and unfolded panoramas of a synthetic stand-in (``db.realism=camera``) for people.

    Top: the 8-bit raw frames of ``n_cells`` capture cells (first, middle and
    last existing cell of the grid), cropped to the mirror. Below, per cell:
    the unfolded camera panorama and, for comparison, the ideal panorama
    (``db.realism=ideal`` without noise) at the same nominal pose.

    Parameters
    ----------
    name : str
        A stand-in (``sim_original`` ...).
    camera, pose_error : CameraConfig, PoseErrorConfig
        As in the ``db`` config (:mod:`bionav.db.camera`).
    seed : int
        ``db.seed``.
    image_size : (int, int), optional
        Unfolded ``(W, H)``; default the stand-in's native size.
    n_cells : int
        Number of cells shown (>= 1).
    threads : int or None
        Render threads.

    Returns
    -------
    ndarray, shape (Hs, Ws), uint8
    """
    from bionav.db.camera import camera_images
    from bionav.db.synthetic import get_spec, quantise, render_world_images

    spec = get_spec(name)
    w, h = (int(v) for v in image_size) if image_size is not None else spec.native_size
    geometry = spec.geometry(w, h)
    world = spec.builder(int(seed))
    cells = np.argwhere(world.cells).astype(np.int64)
    pick = np.unique(np.linspace(0, len(cells) - 1, max(1, int(n_cells))).round().astype(int))
    positions = cells[pick]
    images, raws, poses = camera_images(world, positions, geometry, camera=camera, pose_error=pose_error,
                                        seed=int(seed), native_size=spec.native_size, threads=threads,
                                        keep_raw=True)
    ideal = quantise(render_world_images(world, positions, geometry, threads=threads), noise=0.0,
                     rng=np.random.default_rng(0))
    grey = lambda a: np.rint(a.astype(np.float32).mean(axis=-1)).astype(np.uint8)  # noqa: E731
    # raw thumbnails, cropped to the mirror rim
    rh, rw = raws.shape[1:3]
    rim = min(rh, rw) / 2.0 * float(camera.rim_radius_px) / (0.5 * min(camera.raw_size))
    cy, cx = (rh - 1) / 2.0, (rw - 1) / 2.0
    half = int(np.ceil(rim)) + 2
    thumb = 200
    pano_w = max(w, 400)
    pano_h = max(8, int(round(h * pano_w / w)))
    gap, lh = 6, 16
    width = max(len(positions) * (thumb + gap) + gap, pano_w + 2 * gap)
    height = lh + thumb + gap + len(positions) * 2 * (lh + pano_h + gap) + gap
    sheet = np.full((height, width), 255, np.uint8)
    font = cv2.FONT_HERSHEY_SIMPLEX
    for k, (i, j) in enumerate(positions):
        raw = grey(raws[k])
        y0, y1 = max(0, int(cy) - half), min(rh, int(cy) + half + 1)
        x0, x1 = max(0, int(cx) - half), min(rw, int(cx) + half + 1)
        tile = cv2.resize(raw[y0:y1, x0:x1], (thumb, thumb), interpolation=cv2.INTER_AREA)
        left = gap + k * (thumb + gap)
        cv2.putText(sheet, f"raw {i},{j}", (left, lh - 4), font, 0.4, 0, 1, cv2.LINE_AA)
        sheet[lh: lh + thumb, left: left + thumb] = tile
    top = lh + thumb + gap
    for k, (i, j) in enumerate(positions):
        dx, dy = poses["offsets_m"][k] * 100.0
        dh = np.degrees(poses["heading_errors"][k])
        tilt = np.degrees(np.hypot(*poses["tilts"][k])) if "tilts" in poses else 0.0
        for label, img in ((f"camera {i},{j} (pose error {dx:+.1f}, {dy:+.1f} cm, heading {dh:+.1f} deg, "
                            f"tilt {tilt:.1f} deg)", images[k]),
                           (f"ideal {i},{j}", ideal[k])):
            cv2.putText(sheet, label, (gap, top + lh - 4), font, 0.4, 0, 1, cv2.LINE_AA)
            pano = cv2.resize(grey(img), (pano_w, pano_h), interpolation=cv2.INTER_NEAREST if pano_w >= w
                              else cv2.INTER_AREA)
            sheet[top + lh: top + lh + pano_h, gap: gap + pano_w] = pano
            top += lh + pano_h + gap
    return sheet


def write_camera_sheet(name: str, out_dir: Path, **kwargs) -> Path:
    """Write ``<name>_camera.png`` (:func:`camera_sheet`) into ``out_dir``; return its path."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    path = out_dir / f"{name}_camera.png"
    if not cv2.imwrite(str(path), camera_sheet(name, **kwargs)):
        raise OSError(f"OpenCV could not write {path}")
    return path
