"""The virtual homing agent behind the return ratio (thesis 3.2.3).

Documented choices
------------------
* The agent starts at the current-view cell and moves ``step_length`` grid
  units (0.5) along the home vector computed at the *nearest existing* grid
  cell (Euclidean distance in grid units; ties go to the lower image index,
  :func:`nearest_cell_index`; ties are common: an axis-aligned step from a
  cell lands half-way between two cells).
* It succeeds as soon as ``||s - p|| < success_radius`` (1 grid unit).
* It gives up once it has travelled more than half of the grid's
  circumference, ``(nx - 1) + (ny - 1)`` grid units.
* It may leave the grid; outside, the nearest existing cell still supplies
  the home vector (the border cell), as a real robot would keep using its
  nearest memory.
* Where a method gave no direction (NaN) the agent stays put, so it fails
  unless it has already arrived.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from numba import njit


@dataclass(frozen=True)
class AgentResult:
    """Outcome of homing trials towards one snapshot.

    Attributes
    ----------
    success : ndarray of bool, shape (C,)
        Whether each trial reached the snapshot.
    steps : ndarray of int, shape (C,)
        Steps taken (until success or give-up).
    """

    success: np.ndarray
    steps: np.ndarray


def max_travel_length(grid_shape: tuple[int, int]) -> float:
    """Half the circumference of the capture grid in grid units."""
    nx, ny = grid_shape
    return float((nx - 1) + (ny - 1))


def nearest_cell_index(points: np.ndarray, positions: np.ndarray) -> np.ndarray:
    """Index of the nearest existing grid cell of every point; ties go to the lower index.

    The plain reference of the agent's cell look-up (squared distances
    ``dx * dx + dy * dy`` to every cell, first minimum).

    Parameters
    ----------
    points : ndarray, shape (K, 2)
        Positions in grid units.
    positions : ndarray, shape (C, 2)
        Existing grid cells.

    Returns
    -------
    ndarray of int, shape (K,)
    """
    pts = np.asarray(points, dtype=np.float64)
    cells = np.asarray(positions, dtype=np.float64)
    dx = pts[:, None, 0] - cells[None, :, 0]
    dy = pts[:, None, 1] - cells[None, :, 1]
    return np.argmin(dx * dx + dy * dy, axis=1)


def run_agents(
    home_angles: np.ndarray,
    positions: np.ndarray,
    snapshot: np.ndarray,
    starts: np.ndarray,
    *,
    grid_shape: tuple[int, int],
    step_length: float = 0.5,
    success_radius: float = 1.0,
    record_paths: bool = False,
) -> tuple[AgentResult, list[np.ndarray] | None]:
    """Simulate homing trials towards one snapshot from many start positions.

    Parameters
    ----------
    home_angles : ndarray, shape (C,)
        Grid-frame home direction (radians CCW) computed at each existing cell
        ``positions[i]`` for this snapshot; NaN where the method gave none.
    positions : ndarray, shape (C, 2)
        Existing grid cells.
    snapshot : ndarray, shape (2,)
        Snapshot position.
    starts : ndarray, shape (K, 2)
        Start positions of the trials.
    grid_shape : (nx, ny)
        Declared grid size (sets the give-up length).
    step_length, success_radius : float
        In grid units.
    record_paths : bool
        Also return every trial's path, shape ``(steps + 1, 2)`` each.

    Returns
    -------
    AgentResult, list of ndarray or None
    """
    positions = np.asarray(positions, dtype=float)
    snapshot = np.asarray(snapshot, dtype=float)
    p = np.asarray(starts, dtype=float).copy()
    n_steps_max = int(np.ceil(max_travel_length(grid_shape) / step_length))
    direction = np.stack([np.cos(home_angles), np.sin(home_angles)], axis=1)
    direction = np.nan_to_num(direction, nan=0.0)
    done = np.linalg.norm(p - snapshot, axis=1) < success_radius
    success = done.copy()
    steps = np.zeros(len(p), dtype=np.int64)
    paths = [[row.copy()] for row in p] if record_paths else None
    for _ in range(n_steps_max):
        active = np.flatnonzero(~done)
        if active.size == 0:
            break
        nearest = nearest_cell_index(p[active], positions)
        p[active] += step_length * direction[nearest]
        steps[active] += 1
        arrived = np.linalg.norm(p[active] - snapshot, axis=1) < success_radius
        success[active[arrived]] = True
        done[active[arrived]] = True
        if paths is not None:
            for i in active:
                paths[i].append(p[i].copy())
    result = AgentResult(success=success, steps=steps)
    return result, None if paths is None else [np.array(path) for path in paths]


def evaluate_agents(db, hv, *, step_length: float, success_radius: float, record=frozenset(), batch: bool = True):
    """Agent trials from every existing cell towards every evaluated snapshot of an all-pairs run.

    Parameters
    ----------
    db : ImageDatabase
        The database of the current views (positions and grid shape).
    hv : HomeVectorMatrix
        Result of :func:`bionav.evaluation.pairs.home_vector_matrix` (grid-frame angles).
    step_length, success_radius : float
        Grid units (thesis 3.2.3: 0.5 and 1).
    record : set of int
        Rows of ``hv`` whose agent paths are returned.
    batch : bool
        Rows without recorded paths go through the compiled :func:`agent_success`
        (identical outcomes); ``False`` runs :func:`run_agents` row by row.

    Returns
    -------
    success : ndarray of bool, shape (S, C)
    paths : dict
        Row -> agent paths (see :func:`run_agents`) for the recorded rows.
    """
    success = np.zeros(hv.angles.shape, dtype=bool)
    if batch:
        success = agent_success(hv.angles, db.positions, db.positions[hv.snapshot_index], grid_shape=db.grid_shape,
                                step_length=step_length, success_radius=success_radius)
    paths = {}
    for row, si in enumerate(hv.snapshot_index):
        if batch and row not in record:
            continue
        result, p = run_agents(
            hv.angles[row], db.positions, db.positions[si], db.positions,
            grid_shape=db.grid_shape, step_length=step_length, success_radius=success_radius,
            record_paths=row in record,
        )
        success[row] = result.success
        if p is not None:
            paths[row] = p
    return success, paths


#: distance from a half-integer coordinate below which the rounded lattice point is not taken as the nearest cell
_TIE_MARGIN = 1e-9


@njit(cache=True)
def _nearest_cell_search(px, py, qx, qy, lut, cand_start, cand, cx, cy):
    """Nearest cell among the candidates of lattice point ``(qx, qy)`` (table indices), first minimum."""
    best = 0
    best_d = np.inf
    if 0 <= qx < lut.shape[0] and 0 <= qy < lut.shape[1]:
        k = qx * lut.shape[1] + qy
        for j in range(cand_start[k], cand_start[k + 1]):
            i = cand[j]
            dx = px - cx[i]
            dy = py - cy[i]
            d = dx * dx + dy * dy
            if d < best_d:
                best_d = d
                best = i
        return best
    for i in range(cx.size):  # beyond the table: all cells
        dx = px - cx[i]
        dy = py - cy[i]
        d = dx * dx + dy * dy
        if d < best_d:
            best_d = d
            best = i
    return best


@njit(cache=True)
def _agent_success_kernel(dir_x, dir_y, snapshots, starts, lut, origin, cand_start, cand, cx, cy, n_steps_max,
                          step_length, radius, out):
    n_levels, n_snap, _ = dir_x.shape
    margin = 0.5 - _TIE_MARGIN
    # the lattice rectangle of the cells (the table extends ``origin`` beyond it)
    x_lo, x_hi = np.floor(cx.min()), np.floor(cx.max())
    y_lo, y_hi = np.floor(cy.min()), np.floor(cy.max())
    for lv in range(n_levels):
        for s in range(n_snap):
            sx = snapshots[s, 0]
            sy = snapshots[s, 1]
            row_x = dir_x[lv, s]
            row_y = dir_y[lv, s]
            for c in range(starts.shape[0]):
                px = starts[c, 0]
                py = starts[c, 1]
                dx = px - sx
                dy = py - sy
                if np.sqrt(dx * dx + dy * dy) < radius:
                    out[lv, s, c] = True
                    continue
                for _ in range(n_steps_max):
                    # squared distances are separable: the grid's nearest lattice point is the clamped rounded
                    # point, strictly nearest unless a coordinate inside the grid is (nearly) half-integer
                    rx = np.floor(px + 0.5)
                    ry = np.floor(py + 0.5)
                    clear = True
                    if rx < x_lo:
                        rx = x_lo
                    elif rx > x_hi:
                        rx = x_hi
                    else:
                        clear = abs(px - rx) < margin
                    if ry < y_lo:
                        ry = y_lo
                    elif ry > y_hi:
                        ry = y_hi
                    else:
                        clear = clear and abs(py - ry) < margin
                    i = lut[int(rx) + origin, int(ry) + origin] if clear else -1
                    if i < 0:  # next to a missing cell or on a tie: compare the candidate cells
                        i = _nearest_cell_search(px, py, int(np.floor(px + 0.5)) + origin,
                                                 int(np.floor(py + 0.5)) + origin, lut, cand_start, cand, cx, cy)
                    px += step_length * row_x[i]
                    py += step_length * row_y[i]
                    dx = px - sx
                    dy = py - sy
                    if np.sqrt(dx * dx + dy * dy) < radius:
                        out[lv, s, c] = True
                        break


@functools.lru_cache(maxsize=8)
def _cached_cell_tables(key: bytes, n: int, margin: int):
    return _cell_tables(np.frombuffer(key, dtype=np.float64).reshape(n, 2), margin)


def _cell_tables(positions: np.ndarray, margin: int):
    """Look-up tables of the agent's nearest-cell search on the integer lattice around the cells.

    ``lut[x + o, y + o]`` is the lowest index of the cell at ``(x, y)`` (-1:
    none); for every lattice point ``q`` the candidates are the cells within
    ``m + sqrt(2)`` of ``q`` (``m``: distance of ``q``'s nearest cell), which
    hold every nearest cell of any point within ``q``'s unit square (triangle
    inequality). Empty tables when the cells are not on the integer lattice.
    """
    empty = (np.full((0, 0), -1, np.int64), 0, np.zeros(1, np.int64), np.zeros(0, np.int64))
    if positions.size == 0 or np.any(positions != np.round(positions)) or np.any(np.abs(positions) > 10_000):
        return empty
    lo = positions.min(axis=0).astype(np.int64) - margin
    hi = positions.max(axis=0).astype(np.int64) + margin
    origin = int(-min(lo.min(), 0))
    shape = (int(hi[0]) + origin + 1, int(hi[1]) + origin + 1)
    if shape[0] * shape[1] > 4_000_000:
        return empty
    lut = np.full(shape, -1, dtype=np.int64)
    for i in range(len(positions) - 1, -1, -1):
        lut[int(positions[i, 0]) + origin, int(positions[i, 1]) + origin] = i
    qx, qy = np.meshgrid(np.arange(shape[0]) - origin, np.arange(shape[1]) - origin, indexing="ij")
    q = np.stack([qx.ravel(), qy.ravel()], axis=1).astype(np.float64)
    starts = [0]
    cand = []
    for chunk in range(0, len(q), 4096):
        d = np.sqrt(((q[chunk:chunk + 4096, None, :] - positions[None, :, :]) ** 2).sum(axis=2))
        near = d <= d.min(axis=1, keepdims=True) + np.sqrt(2.0) + 1e-6
        for row in near:
            idx = np.flatnonzero(row)
            cand.append(idx)
            starts.append(starts[-1] + len(idx))
    return lut, origin, np.asarray(starts, np.int64), np.concatenate(cand).astype(np.int64)


def agent_success(
    home_angles: np.ndarray,
    positions: np.ndarray,
    snapshots: np.ndarray,
    *,
    grid_shape: tuple[int, int],
    step_length: float = 0.5,
    success_radius: float = 1.0,
) -> np.ndarray:
    """Outcome of the agent trials from every cell towards every snapshot, for many home-vector fields at once.

    The same trials as :func:`run_agents` (start at every cell, nearest-cell
    home vector, give-up after half the grid circumference) with identical
    arithmetic, compiled and looped per trial; the cell look-up rounds to the
    lattice and only near ties, next to missing cells and off the grid
    compares all cells (ties to the lower index, as :func:`nearest_cell_index`).

    Parameters
    ----------
    home_angles : ndarray, shape (..., S, C)
        Grid-frame home directions (radians CCW) at every cell ``positions[c]``
        towards snapshot ``s``; NaN where none (the agent stays). Leading axes
        are independent fields (e.g. the configurations of a parameter sweep).
    positions : ndarray, shape (C, 2)
        Existing grid cells (the start positions).
    snapshots : ndarray, shape (S, 2)
        Snapshot positions.
    grid_shape : (nx, ny)
    step_length, success_radius : float
        Grid units.

    Returns
    -------
    ndarray of bool, shape (..., S, C)
    """
    angles = np.asarray(home_angles, dtype=np.float64)
    lead = angles.shape[:-2]
    n_snap, n_cells = angles.shape[-2:]
    pos = np.ascontiguousarray(positions, dtype=np.float64).reshape(-1, 2)
    snaps = np.ascontiguousarray(snapshots, dtype=np.float64).reshape(-1, 2)
    if pos.shape[0] != n_cells or snaps.shape[0] != n_snap:
        raise ValueError(f"home_angles of shape {angles.shape} do not match {len(pos)} cells and {len(snaps)} snapshots")
    a = angles.reshape((-1, n_snap, n_cells))
    dir_x = np.nan_to_num(np.cos(a), nan=0.0)
    dir_y = np.nan_to_num(np.sin(a), nan=0.0)
    out = np.zeros(a.shape, dtype=np.bool_)
    n_steps_max = int(np.ceil(max_travel_length(grid_shape) / step_length))
    travel = int(np.ceil(n_steps_max * step_length)) + 2
    lut, origin, cand_start, cand = _cached_cell_tables(pos.tobytes(), len(pos), travel)
    if lut.size == 0:  # cells off the integer lattice: the plain trials
        for idx in np.ndindex(a.shape[:2]):
            out[idx] = run_agents(a[idx], pos, snaps[idx[1]], pos, grid_shape=grid_shape, step_length=step_length,
                                  success_radius=success_radius)[0].success
        return out.reshape(lead + (n_snap, n_cells))
    _agent_success_kernel(dir_x, dir_y, snaps, pos, lut, origin, cand_start, cand, np.ascontiguousarray(pos[:, 0]),
                          np.ascontiguousarray(pos[:, 1]), n_steps_max, float(step_length), float(success_radius), out)
    return out.reshape(lead + (n_snap, n_cells))
