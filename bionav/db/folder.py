"""Loading a real image database from a folder (``source: folder``).

The loader reads the files of one naming scheme (:mod:`bionav.db.naming`),
validates them, optionally unfolds raw mirror frames
(:mod:`bionav.db.unfold`), and converts the on-disk convention into canonical
panoramas (:mod:`bionav.db.conventions`).

Validation (each a :class:`~bionav.errors.UserError` naming the file and the
fix): an unreadable, truncated or undecodable file that matches the naming
scheme; images of different sizes (the most common size wins); a cell outside
the declared grid; two files for one cell; an empty folder. With
``db.on_bad_image=skip`` undecodable files, odd-sized images and cells outside
the grid are skipped with a logged warning instead. Files that do not match the
naming scheme are ignored with one warning.
"""

from __future__ import annotations

import logging
from collections import Counter
from pathlib import Path

import numpy as np

from bionav.db.config import DatabaseConfig
from bionav.db.conventions import to_canonical
from bionav.db.database import ImageDatabase
from bionav.db.imageio import ImageReadError, read_image
from bionav.db.naming import Entry, not_a_file_reason, scan_folder
from bionav.db.unfold import unfold_frames
from bionav.errors import UserError
from bionav.geometry import TWO_PI, PanoramaGeometry

log = logging.getLogger(__name__)

_SKIP_HINT = "or pass db.on_bad_image=skip to skip such files with a warning"


class RawFrames:
    """Lazy access to the raw camera frames of a folder database: ``raw(i)`` reads file ``i`` again.

    Returns the raw frame as float32 grey in ``[0, 1]``, shape ``(h, w)``,
    before unfolding (and before any resizing or preprocessing).
    """

    def __init__(self, paths) -> None:
        self.paths = tuple(Path(p) for p in paths)

    def __call__(self, i: int) -> np.ndarray:
        try:
            return read_image(self.paths[int(i)])
        except ImageReadError as exc:
            raise UserError(f"cannot re-read the raw image {self.paths[int(i)]}: {exc}.") from None

    def __len__(self) -> int:
        return len(self.paths)


def _grid_shape(cfg: DatabaseConfig, scan, entries: list[Entry]) -> tuple[int, int]:
    if cfg.grid_shape is not None:
        return tuple(cfg.grid_shape)
    if scan.grid_shape is not None:
        return tuple(int(v) for v in scan.grid_shape)
    return (max(e.x for e in entries) + 1, max(e.y for e in entries) + 1)


def load_folder(cfg: DatabaseConfig, folder: Path) -> ImageDatabase:
    """Load a database folder into canonical panoramas.

    Parameters
    ----------
    cfg : DatabaseConfig
        ``naming``, ``azimuth``, ``x_axis_column``, ``horizon_row``,
        ``rad_per_row``, ``spacing_m``, ``grid_shape``, ``on_bad_image``,
        ``unfold`` and ``extra.bw_cutoff`` are used; the conventions describe
        the images as they lie on disk (after unfolding, for raw frames) and
        the grid frame after the naming scheme's index conversion.
    folder : Path
        Existing directory holding the images.

    Returns
    -------
    ImageDatabase
        Images ``(N, H, W)`` float32 in ``[0, 1]``, canonical (column 0 along
        grid +x, azimuth counter-clockwise); positions of the cells that exist;
        geometry with the on-disk horizon row and vertical angle per row (rows
        are not changed by the conversion); ``raw`` set when unfolding.
    """
    folder = Path(folder)
    skip = cfg.on_bad_image == "skip"
    extra = dict(cfg.extra or {})
    scan = scan_folder(folder, naming=cfg.naming, grid_shape=cfg.grid_shape, bw_cutoff=extra.get("bw_cutoff"))
    if scan.ignored:
        shown = ", ".join(scan.ignored[:5]) + (" ..." if len(scan.ignored) > 5 else "")
        log.warning("%s: ignoring %d file(s) that do not follow the %s naming scheme: %s",
                    folder, len(scan.ignored), scan.scheme, shown)

    entries = sorted(scan.entries, key=lambda e: (e.x, e.y, e.path.name))
    nx, ny = _grid_shape(cfg, scan, entries)
    _check_grid_extent(cfg, folder, entries, nx, ny)
    skipped: list[str] = []

    def bad(entry: Entry, problem: str, fix: str) -> None:
        if not skip:
            raise UserError(f"cannot load database {cfg.name!r}: {entry.path} {problem}; {fix}, {_SKIP_HINT}.")
        log.warning("skipping %s: it %s", entry.path, problem)
        skipped.append(entry.path.name)

    _check_one_file_per_cell(cfg, folder, entries)
    frames, kept = _read_frames(_inside_grid(entries, nx, ny, bad), bad)
    if not frames:
        raise UserError(
            f"cannot load database {cfg.name!r}: none of the {len(entries)} image file(s) in {folder} "
            f"could be used (skipped: {', '.join(skipped[:5])}); fix the files or db.grid_shape."
        )

    unfold = cfg.unfold
    raw = None
    if unfold is not None and unfold.enabled:
        frames = unfold_frames(frames, unfold, first=str(kept[0].path))
        raw = RawFrames(e.path for e in kept)
    disk = np.stack(frames).astype(np.float32, copy=False)
    height, width = disk.shape[1:]
    images = to_canonical(disk, azimuth=cfg.azimuth, x_axis_column=cfg.x_axis_column)
    geometry = _folder_geometry(cfg, scan, width, height)
    if scan.meta.get("w") not in (None, width) and not (unfold is not None and unfold.enabled):
        log.warning("%s: the .db file says w=%s but the images are %d pixels wide",
                    folder, scan.meta.get("w"), width)
    meta = _folder_meta(cfg, folder, scan, kept, skipped, nx, ny, geometry, raw)
    return ImageDatabase(
        name=cfg.name,
        images=images,
        positions=np.array([(e.x, e.y) for e in kept], dtype=np.int64).reshape(-1, 2),
        grid_shape=(nx, ny),
        geometry=geometry,
        spacing_m=cfg.spacing_m,
        raw=raw,
        meta=meta,
    )


def _check_one_file_per_cell(cfg: DatabaseConfig, folder: Path, entries: list[Entry]) -> None:
    """Refuse two files for one grid cell (naming both)."""
    seen: dict[tuple[int, int], Entry] = {}
    for entry in entries:
        cell = (entry.x, entry.y)
        if cell in seen:
            raise UserError(
                f"cannot load database {cfg.name!r}: grid cell {cell} is given by two files, "
                f"{seen[cell].path.name} and {entry.path.name} in {folder}; remove or rename one of them."
            )
        seen[cell] = entry


def _inside_grid(entries: list[Entry], nx: int, ny: int, bad) -> list[Entry]:
    """The entries inside the ``nx`` x ``ny`` grid; ``bad(entry, problem, fix)`` for the others."""
    inside = []
    for entry in entries:
        if 0 <= entry.x < nx and 0 <= entry.y < ny:
            inside.append(entry)
        else:
            bad(entry, f"is at grid cell ({entry.x}, {entry.y}), outside the declared {nx} x {ny} grid",
                "fix db.grid_shape=[nx,ny] (or set it to null to use the bounding box of the files) "
                "or remove the file")
    return inside


def _read_frames(entries: list[Entry], bad) -> tuple[list[np.ndarray], list[Entry]]:
    """The images of ``entries`` that are readable files of the most common size, and their entries.

    ``bad(entry, problem, fix)`` is called for each file that is not a regular file, not a readable image,
    or of another size than most.
    """
    frames, kept = [], []
    for entry in entries:
        not_file = not_a_file_reason(entry.path)
        if not_file:
            bad(entry, not_file, "replace it by the image file or remove it")
            continue
        try:
            frames.append(read_image(entry.path))
            kept.append(entry)
        except ImageReadError as exc:
            bad(entry, f"is not a readable image ({exc})", "replace or remove the file")
    if not frames:
        return frames, kept
    sizes = Counter(f.shape for f in frames)
    common = sizes.most_common(1)[0][0]
    example = next(e for e, f in zip(kept, frames) if f.shape == common)
    ok_frames, ok_entries = [], []
    for entry, frame in zip(kept, frames):
        if frame.shape == common:
            ok_frames.append(frame)
            ok_entries.append(entry)
        else:
            bad(entry, f"is {frame.shape[1]} x {frame.shape[0]} pixels while the other images "
                f"(e.g. {example.path.name}) are {common[1]} x {common[0]}",
                "a database needs one image size: resize or remove the odd file")
    return ok_frames, ok_entries


def _folder_geometry(cfg: DatabaseConfig, scan, width: int, height: int) -> PanoramaGeometry:
    """Horizon row and vertical angle per row from the config, else the scheme's files, else the defaults
    (the middle row; square pixels, ``2 pi / width`` radians per row)."""
    horizon_row = cfg.horizon_row if cfg.horizon_row is not None else scan.horizon_row
    rad_per_row = cfg.rad_per_row if cfg.rad_per_row is not None else scan.rad_per_row
    return PanoramaGeometry(
        width, height,
        float(horizon_row) if horizon_row is not None else (height - 1) / 2.0,
        float(rad_per_row) if rad_per_row is not None else TWO_PI / width,
    )


def _folder_meta(cfg: DatabaseConfig, folder: Path, scan, kept: list[Entry], skipped: list[str], nx: int, ny: int,
                 geometry: PanoramaGeometry, raw) -> dict:
    """Log how many grid cells have an image (a warning when some are missing or skipped); the ``meta``."""
    n_cells = nx * ny
    n_present = len({(e.x, e.y) for e in kept})
    missing_text = (f", {n_cells - n_present} missing (the agent uses the nearest existing cell)"
                    if n_present < n_cells else ", none missing")
    (log.warning if n_present < n_cells or skipped else log.info)(
        "database %r from %s: %d of %d grid cells (%d x %d) have an image%s%s",
        cfg.name, folder, n_present, n_cells, nx, ny, missing_text,
        f"; {len(skipped)} file(s) skipped: {', '.join(skipped[:5])}" if skipped else "",
    )
    meta = {
        "source": "folder",
        "n_cells": n_cells,
        "n_missing_cells": n_cells - n_present,
        "path": str(folder),
        "naming": scan.scheme,
        "files": [e.path.name for e in kept],
        "skipped": skipped,
        "conventions": {"azimuth": cfg.azimuth, "x_axis_column": cfg.x_axis_column,
                        "horizon_row": geometry.horizon_row, "rad_per_row": geometry.rad_per_row},
        "unfolded": bool(raw is not None),
    }
    meta.update({f"scheme_{k}": v for k, v in scan.meta.items()})
    return meta


#: largest number of grid cells a database may span (arrays of one value per cell are allocated)
MAX_GRID_CELLS = 4_000_000


def _check_grid_extent(cfg: DatabaseConfig, folder: Path, entries: list[Entry], nx: int, ny: int) -> None:
    """Refuse a grid so large that per-cell arrays would exhaust memory (a stray ``99999_99999.png``)."""
    from bionav.validation import check_allocation, format_bytes

    cells = nx * ny
    far = max(entries, key=lambda e: max(e.x, e.y), default=None) if entries else None
    culprit = (f" The largest index comes from {far.path.name} (cell ({far.x}, {far.y}))"
               if far is not None and cfg.grid_shape is None else "")
    fix = ("remove or rename the stray file, or declare the grid with db.grid_shape=[nx,ny] "
           "(files outside it are then an error, or skipped with db.on_bad_image=skip)")
    if cells > MAX_GRID_CELLS:
        raise UserError(
            f"database {cfg.name!r} in {folder} would span a {nx} x {ny} grid ({cells} cells, "
            f"{format_bytes(8.0 * cells)} per per-cell array), more than the {MAX_GRID_CELLS} cells bionav "
            f"handles.{culprit}; {fix}."
        )
    check_allocation(64.0 * cells, what=f"the per-cell arrays of a {nx} x {ny} grid", fix=fix)
