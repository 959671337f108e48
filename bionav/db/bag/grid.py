"""``db=bag``: a grid database from the views and poses of a ROS bag.

The views (:mod:`bionav.db.bag.views`) are binned to a regular grid of
``db.grid_cell_m`` metres: cell ``(i, j)`` has its centre at ``origin +
(i, j) * grid_cell_m`` in the world frame (``origin``: ``db.origin_m``, else
the lower-left corner of the views' positions), every view belongs to the
cell whose centre is nearest, and each cell keeps the view nearest to its
centre (ties: the earlier stamp). Cells without a view are missing, as in
``db=folder``; the grid is ``db.grid_shape``, else the views' bounding box.
The database's positions are the nominal cells (the real databases' rule).

The kept views are decoded, unfolded (``db.unfold``) and converted to
canonical panoramas with ``db.azimuth`` / ``db.x_axis_column`` exactly as a
folder's images (:func:`bionav.db.conventions.to_canonical`): a folder of
the same images gives the same database bit for bit. With ``db.align=true``
(the default) each view is turned to the world frame by its interpolated
heading psi, i.e. read with ``x_axis_column - s * psi * W / (2 pi)``
(``s = -1`` clockwise, ``+1`` counter-clockwise; cyclic linear interpolation
between columns when that is not a whole column), so column 0 looks along
world +x and every heading is 0, as the grid experiments assume;
``db.align=false`` keeps the robot's frame and records psi in ``headings``.
"""

from __future__ import annotations

import logging

import numpy as np

from bionav.db.bag.reader import open_bag
from bionav.db.bag.views import check_topics, decode_views, index_views
from bionav.db.conventions import azimuth_sign, to_canonical
from bionav.db.database import ImageDatabase
from bionav.errors import UserError
from bionav.geometry import TWO_PI, PanoramaGeometry

log = logging.getLogger(__name__)

#: largest number of grid cells a bag database may span (as a folder's)
MAX_GRID_CELLS = 4_000_000


def bin_views(xy: np.ndarray, stamps: np.ndarray, *, cell_m: float, origin=None, grid_shape=None):
    """Bin positions to grid cells and choose the view nearest to each cell centre.

    Parameters
    ----------
    xy : ndarray, shape (N, 2)
        Metres, world frame.
    stamps : ndarray, shape (N,)
        Tie-breaker (the earlier wins).
    cell_m : float
        Cell size, metres.
    origin : sequence of 2 float, optional
        World position of the centre of cell (0, 0); default the lower-left corner of ``xy``.
    grid_shape : sequence of 2 int, optional
        ``(nx, ny)``; default the bounding box of the cells.

    Returns
    -------
    chosen : ndarray, shape (K,), int
        The view of each occupied cell, cells in (x, y) order.
    cells : ndarray, shape (K, 2), int
    grid_shape : tuple of int
    origin : ndarray, shape (2,)
    offsets : ndarray, shape (K,)
        Distance of each chosen view from its cell centre, metres.
    outside : int
        Views outside the grid (negative cells, or beyond ``grid_shape``).
    """
    xy = np.asarray(xy, np.float64)
    origin = xy.min(axis=0) if origin is None else np.asarray(origin, np.float64)
    cell = np.rint((xy - origin) / cell_m).astype(np.int64)
    nx, ny = (cell.max(axis=0) + 1) if grid_shape is None else grid_shape
    nx, ny = int(nx), int(ny)
    inside = (cell >= 0).all(axis=1) & (cell[:, 0] < nx) & (cell[:, 1] < ny)
    dist = np.linalg.norm(xy - (origin + cell * cell_m), axis=1)
    idx = np.flatnonzero(inside)
    order = idx[np.lexsort((stamps[idx], dist[idx], cell[idx, 1], cell[idx, 0]))]
    first = np.ones(len(order), bool)
    first[1:] = np.any(cell[order[1:]] != cell[order[:-1]], axis=1)
    chosen = order[first]
    return chosen, cell[chosen], (nx, ny), origin, dist[chosen], int((~inside).sum())


def _check_grid(cfg, nx: int, ny: int) -> None:
    from bionav.validation import check_allocation, format_bytes

    fix = ("give a larger db.grid_cell_m, or declare the grid with db.grid_shape=[nx,ny] and db.origin_m=[x,y] "
           "(views outside it are left out)")
    if nx * ny > MAX_GRID_CELLS:
        raise UserError(f"the views of {cfg.path} span a {nx} x {ny} grid of db.grid_cell_m={cfg.grid_cell_m:g} m "
                        f"({nx * ny} cells, {format_bytes(8.0 * nx * ny)} per per-cell array), more than the "
                        f"{MAX_GRID_CELLS} cells bionav handles; {fix}.")
    check_allocation(64.0 * nx * ny, what=f"the per-cell arrays of a {nx} x {ny} grid", fix=fix)


def canonical_views(frames, yaw, cfg, *, align: bool) -> np.ndarray:
    """Decoded (unfolded) frames ``(N, H, W)`` as canonical panoramas, turned to the world frame if ``align``."""
    disk = np.stack(frames).astype(np.float32, copy=False)
    width = disk.shape[-1]
    if not align:
        return to_canonical(disk, azimuth=cfg.azimuth, x_axis_column=cfg.x_axis_column)
    s = azimuth_sign(cfg.azimuth)
    out = np.empty_like(disk)
    for k, psi in enumerate(np.asarray(yaw, np.float64)):
        column = cfg.x_axis_column - s * psi * width / TWO_PI
        whole = round(column)
        column = whole if abs(column - whole) < 1e-9 else column  # a whole column: a pure roll, exact
        out[k] = to_canonical(disk[k], azimuth=cfg.azimuth, x_axis_column=column)
    return out


def view_geometry(cfg, width: int, height: int) -> PanoramaGeometry:
    """Horizon row and vertical angle per row from ``db.horizon_row`` / ``db.rad_per_row`` (defaults as folders')."""
    return PanoramaGeometry(width, height,
                            float(cfg.horizon_row) if cfg.horizon_row is not None else (height - 1) / 2.0,
                            float(cfg.rad_per_row) if cfg.rad_per_row is not None else TWO_PI / width)


#: views decoded at once: the raw frames in memory at a time
DECODE_BATCH = 8


def decode_all(bag, views, which, cfg, *, align: bool, size=None):
    """Decode the views ``which`` in batches into one array of canonical panoramas.

    Each batch of :data:`DECODE_BATCH` messages is decoded, unfolded (``db.unfold``), made canonical
    (:func:`canonical_views`, ``align``) and resized to ``size = [W, H]`` if given before the next is
    read, so memory holds the result and one batch of raw frames.

    Returns
    -------
    kept : list of int
        The positions in ``views`` that were used, in the order of ``which``.
    images : ndarray, shape (len(kept), H, W), float32
    native : (int, int)
        ``(W, H)`` of the panoramas before the resize.
    """
    from bionav.db.unfold import unfold_frames
    from bionav.homing.imageops import resize_images
    from bionav.machine import usable_cpus
    from bionav.validation import check_allocation

    which = np.asarray(which, np.int64)
    skip = cfg.on_bad_image == "skip"
    kept_all, out, shape, native = [], None, None, None
    for start in range(0, len(which), DECODE_BATCH):
        kept, frames = decode_views(bag, views, which[start:start + DECODE_BATCH], skip=skip, shape=shape)
        if not frames:
            continue
        shape = frames[0].shape
        if cfg.unfold is not None and cfg.unfold.enabled:
            frames = unfold_frames(frames, cfg.unfold, first=f"{cfg.path} {views.topic.name}",
                                   threads=min(2, usable_cpus()))
        batch = canonical_views(frames, views.yaw[kept], cfg, align=align)
        native = (batch.shape[-1], batch.shape[-2])
        if size is not None:
            batch = resize_images(batch, size)
        if out is None:
            check_allocation(4.0 * len(which) * batch[0].size, what=f"the {len(which)} views of {views.topic.name}",
                             fix="give a larger db.grid_cell_m or a smaller db.unfold.size / db.image_size")
            out = np.empty((len(which), *batch.shape[1:]), np.float32)
        out[len(kept_all):len(kept_all) + len(kept)] = batch
        kept_all += list(kept)
    if out is None:
        raise UserError(f"no image of {views.topic.name} in {cfg.path} could be used; see the warnings above.")
    return kept_all, out[:len(kept_all)], native


def load_bag_database(cfg) -> ImageDatabase:
    """The grid database of ``db=bag`` (see the module docstring).

    Parameters
    ----------
    cfg : DatabaseConfig
        ``source: bag`` with ``path``, ``image_topic``, ``pose_topic``, ``grid_cell_m`` and the
        optional keys of :mod:`bionav.db.bag`.

    Returns
    -------
    ImageDatabase
        Images ``(N, H, W)`` float32 in ``[0, 1]``, canonical; positions the occupied cells in
        (x, y) order; ``spacing_m = db.grid_cell_m``; headings 0 (``db.align=true``) or the
        robot's; ``meta`` with the bag, topics, counts, origin and each view's stamp and offset.

    Raises
    ------
    UserError
        Everything :func:`~bionav.db.bag.views.index_views` refuses, ``db.grid_cell_m`` unset,
        a grid too large, fewer than 2 views.
    """
    with open_bag(cfg.path, key="db.path") as bag:
        check_topics(bag, cfg)
        if cfg.grid_cell_m is None:
            raise UserError("db=bag as a grid database needs its cell size: set db.grid_cell_m=METRES (e.g. 0.3, the "
                            "Bielefeld grids' spacing); each cell keeps the view nearest to its centre.")
        views = index_views(bag, cfg)
        chosen, cells, (nx, ny), origin, offsets, outside = bin_views(
            views.xy, views.stamp_ns, cell_m=cfg.grid_cell_m, origin=cfg.origin_m, grid_shape=cfg.grid_shape)
        _check_grid(cfg, nx, ny)
        if len(chosen) < 2:
            raise UserError(f"the views of {views.topic.name} fill {len(chosen)} cell(s) of db.grid_cell_m="
                            f"{cfg.grid_cell_m:g} m; homing needs at least 2: use a smaller db.grid_cell_m or a longer "
                            "drive.")
        kept, images, _native = decode_all(bag, views, chosen, cfg, align=cfg.align)
    pick = [int(np.flatnonzero(chosen == w)[0]) for w in kept]
    geometry = view_geometry(cfg, images.shape[-1], images.shape[-2])
    headings = np.zeros(len(kept)) if cfg.align else np.mod(views.yaw[kept], TWO_PI)
    n_cells = nx * ny
    log.log(logging.WARNING if len(kept) < n_cells else logging.INFO,
            "database %r from %s: %d of %d grid cells (%d x %d, %g m) have a view (%d views of %s with poses, "
            "%d left out without a pose, %d outside the grid); views lie %.3f m (mean) / %.3f m (max) from their "
            "cell centres", cfg.name, cfg.path, len(kept), n_cells, nx, ny, cfg.grid_cell_m, len(views.index),
            views.topic.name, views.n_uncovered, outside, float(offsets[pick].mean()), float(offsets[pick].max()))
    meta = {"source": "bag", "path": str(cfg.path), "image_topic": views.topic.name, "pose_topic": views.pose_topic,
            "world_frame": views.world_frame, "n_messages": views.n_messages, "n_with_pose": len(views.index),
            "n_uncovered": views.n_uncovered, "n_odd": views.n_odd, "n_outside_grid": outside, "n_cells": n_cells,
            "n_missing_cells": n_cells - len(kept), "origin_m": origin.tolist(), "grid_cell_m": cfg.grid_cell_m,
            "stamps_ns": views.stamp_ns[kept].tolist(), "messages": views.index[kept].tolist(),
            "offsets_m": offsets[pick].tolist(), "world_xy": views.xy[kept].tolist(),
            "yaw": views.yaw[kept].tolist(), "aligned": bool(cfg.align)}
    return ImageDatabase(name=cfg.name, images=images, positions=cells[pick], grid_shape=(nx, ny), geometry=geometry,
                         spacing_m=float(cfg.grid_cell_m), headings=headings, meta=meta)
