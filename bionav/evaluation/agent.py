"""The virtual homing agent behind the return ratio (thesis 3.2.3).

Documented choices
------------------
* The agent starts at the current-view cell and moves ``step_length`` grid
  units (0.5) along the home vector computed at the *nearest existing* grid
  cell (Euclidean distance in grid units; ties go to the lower image index).
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

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree


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
    tree = cKDTree(positions)
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
        _, nearest = tree.query(p[active])
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


def evaluate_agents(db, hv, *, step_length: float, success_radius: float, record=frozenset()):
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

    Returns
    -------
    success : ndarray of bool, shape (S, C)
    paths : dict
        Row -> agent paths (see :func:`run_agents`) for the recorded rows.
    """
    success = np.zeros(hv.angles.shape, dtype=bool)
    paths = {}
    for row, si in enumerate(hv.snapshot_index):
        result, p = run_agents(
            hv.angles[row], db.positions, db.positions[si], db.positions,
            grid_shape=db.grid_shape, step_length=step_length, success_radius=success_radius,
            record_paths=row in record,
        )
        success[row] = result.success
        if p is not None:
            paths[row] = p
    return success, paths
