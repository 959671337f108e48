"""The one all-pairs runner: per-image work once, then a method's batch path or pairs on all cores."""

from __future__ import annotations

import threading
import time
from concurrent.futures import ThreadPoolExecutor
from concurrent.futures import TimeoutError as FuturesTimeout
from dataclasses import dataclass, field
from typing import Any, Callable, Iterable, Sequence

import numpy as np

from bionav.db.database import ImageDatabase
from bionav.geometry import wrap_angle
from bionav.homing.base import HomingMethod

#: neighbour offsets handed to test-step methods
NEIGHBOUR_OFFSETS = ((1, 0), (-1, 0), (0, 1), (0, -1))

Progress = Callable[..., Iterable[Any]]


def _no_progress(iterable: Iterable[Any], **_: Any) -> Iterable[Any]:
    return iterable


@dataclass
class HomeVectorMatrix:
    """Home vectors of every snapshot/current-view pair.

    Attributes
    ----------
    snapshot_index : ndarray, shape (S,)
        Indices (into the snapshot database) of the evaluated snapshots.
    angles : ndarray, shape (S, C)
        Home directions in the grid frame (radians CCW); NaN on ``s == c`` and
        where the method gave none.
    compass_error : ndarray, shape (S, C) or None
        ``wrap(psi_estimated - psi_true)`` for methods that estimate the
        rotation psi; None otherwise.
    prepare_s, pairs_s : float
        Wall time of the per-image work and of the pair computations.
    n_pairs : int
        Number of home vectors computed.
    prepared_stats : dict
        :meth:`HomingMethod.describe_prepared` averaged over the current views.
    """

    snapshot_index: np.ndarray
    angles: np.ndarray
    compass_error: np.ndarray | None
    prepare_s: float
    pairs_s: float
    n_pairs: int
    prepared_stats: dict = field(default_factory=dict)

    @property
    def ms_per_home_vector(self) -> float:
        """Mean wall time per home vector with per-image work amortised, ms."""
        return 1e3 * (self.prepare_s + self.pairs_s) / max(self.n_pairs, 1)


def neighbour_table(db: ImageDatabase) -> np.ndarray:
    """Index of each cell's grid neighbours at :data:`NEIGHBOUR_OFFSETS`; -1 where missing.

    Returns
    -------
    ndarray of int, shape (N, 4)
        Columns: offsets ``(+1, 0), (-1, 0), (0, +1), (0, -1)`` in the grid frame.
    """
    lut = db.cell_index_map()
    nx, ny = db.grid_shape
    out = np.full((len(db), len(NEIGHBOUR_OFFSETS)), -1, dtype=np.int64)
    for k, (dx, dy) in enumerate(NEIGHBOUR_OFFSETS):
        x = db.positions[:, 0] + dx
        y = db.positions[:, 1] + dy
        ok = (x >= 0) & (x < nx) & (y >= 0) & (y < ny)
        out[ok, k] = lut[x[ok], y[ok]]
    return out


def prepare_images(
    method: HomingMethod,
    images: Sequence[np.ndarray],
    *,
    workers: int = 1,
    progress: Progress = _no_progress,
    desc: str = "per-image work",
    cache: Any = None,
) -> list[Any]:
    """Run ``method.prepare`` once per image, on ``workers`` threads.

    With a :class:`bionav.evaluation.prepcache.PreparedCache`, results are
    read from / written to the on-disk cache.
    """
    fn = method.prepare if cache is None else (lambda image: cache.prepare(method, image))
    with ThreadPoolExecutor(max(1, workers)) as pool:
        return list(progress(pool.map(fn, images), desc=desc, total=len(images)))


def home_vector_matrix(
    method: HomingMethod,
    snapshots: ImageDatabase,
    currents: ImageDatabase | None = None,
    *,
    snapshot_index: Sequence[int] | None = None,
    workers: int = 1,
    progress: Progress = _no_progress,
    prepared: tuple[list[Any], list[Any]] | None = None,
    cache: Any = None,
    on_row: Callable[[int, np.ndarray, np.ndarray], None] | None = None,
    on_partial: Callable[[int, np.ndarray, np.ndarray, np.ndarray], None] | None = None,
    partial_period_s: float = 2.0,
    batch: bool = True,
    device: str = "cpu",
) -> HomeVectorMatrix:
    """Home vectors from every current view to every (selected) snapshot.

    Parameters
    ----------
    method : HomingMethod
        The homing method.
    snapshots : ImageDatabase
        Database the snapshots come from.
    currents : ImageDatabase, optional
        Database the current views come from (cross-database tests); the
        snapshot database by default. Both must share the grid.
    snapshot_index : sequence of int, optional
        Evaluate only these snapshots (indices into ``snapshots``).
    workers : int
        Threads (OpenCV, numpy and numba kernels release the GIL).
    progress : callable
        ``progress(iterable, desc=..., total=...)``, e.g. a tqdm wrapper.
    prepared : (list, list), optional
        Already prepared snapshot and current images (skips the per-image work).
    cache : PreparedCache, optional
        On-disk cache of per-image work.
    on_row : callable, optional
        ``on_row(snapshot, angles, compass)`` is called (in the caller's
        thread, in order) as soon as a snapshot's row is finished:
        ``snapshot`` is its index into ``snapshots``, ``angles`` and
        ``compass`` have shape (C,), radians in the grid frame (NaN: none).
        Experiments log rows here, so a crash loses no finished row.
    on_partial : callable, optional
        ``on_partial(snapshot, currents, angles, compass)`` is called (in the
        caller's thread) about every ``partial_period_s`` seconds with the
        pairs computed since its last call, inside rows not yet finished:
        ``currents`` are indices into the current views (shape (K,)),
        ``angles`` and ``compass`` shape (K,), radians in the grid frame. With
        it, a crash loses at most about ``partial_period_s`` of computed home
        vectors however long a row takes (per-pair path; a method's batch path
        reports whole rows only).
    partial_period_s : float
        Period of ``on_partial``, seconds (> 0).
    batch : bool
        Use the method's batch path (:meth:`HomingMethod.all_pairs_angles`)
        when it has one and snapshots and current views are one database;
        ``False`` forces the per-pair calls.
    device : str
        ``"cpu"``, or ``"cuda"``: the pairs on an NVIDIA GPU (:mod:`bionav.gpu`; min-warping,
        2D-warping and SIFT), the per-image work on the CPU.

    Returns
    -------
    HomeVectorMatrix
        Angles converted to the grid frame with the current views' headings.
    """
    same = currents is None or currents is snapshots
    currents = snapshots if currents is None else currents
    s_idx = np.arange(len(snapshots)) if snapshot_index is None else np.asarray(snapshot_index, dtype=np.int64)
    if device == "cuda":  # before the per-image work: a method the GPU does not compute is refused at once
        from bionav.gpu import check_method

        check_method(getattr(method, "name", type(method).__name__))
    t0 = time.perf_counter()
    snap_prep, cur_prep = prepared if prepared is not None else _prepare_both(method, snapshots, currents, same,
                                                                              workers, progress, cache)
    timing = _Timing(t0, time.perf_counter(), _n_pairs(snapshots, currents, s_idx), _prepared_stats(method, cur_prep))
    if device == "cuda":
        from bionav.gpu.pairs import gpu_matrix

        angles, compass = gpu_matrix(method, snapshots, currents, s_idx, snap_prep, cur_prep, on_row=on_row)
        has_compass = bool(np.any(np.isfinite(compass)))
        return HomeVectorMatrix(snapshot_index=s_idx, angles=angles, compass_error=compass if has_compass else None,
                                prepare_s=timing.t1 - timing.t0, pairs_s=time.perf_counter() - timing.t1,
                                n_pairs=timing.n_pairs, prepared_stats=timing.prepared_stats)
    if batch and same:
        matrix = _batch_matrix(method, snapshots, currents, s_idx, cur_prep, timing, workers, progress, on_row)
        if matrix is not None:
            return matrix
    rows = _PairRows(method, snapshots, currents, s_idx, snap_prep, cur_prep, on_partial, partial_period_s)
    return rows.matrix(timing, workers=workers, progress=progress, on_row=on_row)


@dataclass
class _Timing:
    """Start and end (``time.perf_counter``, s) of the per-image work, pairs counted, per-image statistics."""

    t0: float
    t1: float
    n_pairs: int
    prepared_stats: dict[str, float]


def _prepare_both(method, snapshots, currents, same, workers, progress, cache) -> tuple[list[Any], list[Any]]:
    """Per-image work of the snapshots and the current views (once when they are one database)."""
    cur_prep = prepare_images(method, list(currents.images), workers=workers, progress=progress, cache=cache)
    snap_prep = cur_prep if same else prepare_images(
        method, list(snapshots.images), workers=workers, progress=progress, cache=cache,
        desc="per-image work (snapshots)",
    )
    return snap_prep, cur_prep


def _n_pairs(snapshots: ImageDatabase, currents: ImageDatabase, s_idx: np.ndarray) -> int:
    """Pairs of the selected snapshots and the current views at another position."""
    return int(np.sum(~np.all(snapshots.positions[s_idx][:, None, :] == currents.positions[None, :, :], axis=2)))


def _batch_matrix(method, snapshots, currents, s_idx, cur_prep, timing: _Timing, workers, progress,
                  on_row) -> HomeVectorMatrix | None:
    """The method's batch path (:meth:`HomingMethod.all_pairs_angles`); None when it has none."""
    options = _batch_options(method, snapshot_index=s_idx, workers=workers, progress=progress, on_row=on_row)
    all_pairs = method.all_pairs_angles(
        cur_prep, headings=currents.headings, neighbours=neighbour_table(currents), **options,
    )
    if all_pairs is None:
        return None
    angles = np.array(all_pairs, dtype=np.float64)[s_idx]
    angles[np.all(snapshots.positions[s_idx][:, None, :] == currents.positions[None, :, :], axis=2)] = np.nan
    t2 = time.perf_counter()
    if on_row is not None and "on_row" not in options:  # a method that streams rows has called it already
        no_compass = np.full(len(currents), np.nan)
        for row_angles, si in zip(angles, s_idx):
            on_row(int(si), row_angles, no_compass)
    return HomeVectorMatrix(snapshot_index=s_idx, angles=angles, compass_error=None, prepare_s=timing.t1 - timing.t0,
                            pairs_s=t2 - timing.t1, n_pairs=timing.n_pairs, prepared_stats=timing.prepared_stats)


class _PairRows:
    """The per-pair path of :func:`home_vector_matrix`: one row of home vectors per snapshot, rows on worker
    threads, finished rows handed to ``on_row`` in order and pairs of unfinished rows to ``on_partial``.

    Angles and compass errors in radians, grid frame (the current view's heading added).
    """

    def __init__(self, method, snapshots, currents, s_idx, snap_prep, cur_prep, on_partial, partial_period_s):
        self.method, self.snapshots, self.currents, self.s_idx = method, snapshots, currents, s_idx
        self.snap_prep, self.cur_prep = snap_prep, cur_prep
        self.on_partial, self.partial_period_s = on_partial, partial_period_s
        self.lut = currents.cell_index_map()
        self.nx, self.ny = currents.grid_shape
        #: rows being computed: position in s_idx -> (angles, compass, computed mask, reported mask); the worker
        #: writes a pair's values before setting its computed flag, the caller's thread only reads flagged pairs
        self.live: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = {}
        #: set when the caller stops early (Ctrl-C, SIGTERM, an error): rows in progress end after their current pair
        self.stop = threading.Event()

    def neighbours_of(self, ci: int) -> dict[tuple[float, float], Any]:
        """Prepared grid neighbours keyed by their offset in the current view's frame."""
        currents, lut, nx, ny = self.currents, self.lut, self.nx, self.ny
        x, y = currents.positions[ci]
        c, s = np.cos(currents.headings[ci]), np.sin(currents.headings[ci])
        out = {}
        for dx, dy in NEIGHBOUR_OFFSETS:
            if 0 <= x + dx < nx and 0 <= y + dy < ny and lut[x + dx, y + dy] >= 0:
                key = (dx, dy) if s == 0 and c == 1 else (round(c * dx + s * dy, 12), round(-s * dx + c * dy, 12))
                out[key] = self.cur_prep[lut[x + dx, y + dy]]
        return out

    def row(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """Home vectors of every current view to snapshot ``s_idx[k]`` (a worker thread)."""
        method, snapshots, currents = self.method, self.snapshots, self.currents
        si = self.s_idx[k]
        angles = np.full(len(currents), np.nan)
        compass = np.full(len(currents), np.nan)
        computed = np.zeros(len(currents), dtype=bool)
        self.live[k] = (angles, compass, computed, np.zeros(len(currents), dtype=bool))
        s_pos = snapshots.positions[si]
        for ci in range(len(currents)):
            if self.stop.is_set():
                break
            if np.array_equal(currents.positions[ci], s_pos):
                continue
            kwargs = {"neighbours": self.neighbours_of(ci)} if method.uses_test_steps else {}
            hv = method.home_vector(self.snap_prep[si], self.cur_prep[ci], **kwargs)
            angles[ci] = hv.angle + currents.headings[ci]
            if hv.compass is not None:
                compass[ci] = hv.compass - (currents.headings[ci] - snapshots.headings[si])
            computed[ci] = True
        return wrap_angle(angles), wrap_angle(compass)

    def report_partial(self, first_open: int) -> None:
        """Hand the pairs computed since the last report, of rows not reported whole, to ``on_partial``."""
        for k in sorted(self.live.copy()):  # a worker may add a row meanwhile
            if k < first_open:
                continue
            angles, compass, computed, reported = self.live[k]
            new = np.flatnonzero(computed & ~reported)
            if new.size:
                self.on_partial(int(self.s_idx[k]), new, wrap_angle(angles[new]), wrap_angle(compass[new]))
                reported[new] = True

    def finished_rows(self, pool: ThreadPoolExecutor):
        """Rows in order; while waiting for one, report partial rows every ``partial_period_s``."""
        futures = [pool.submit(self.row, k) for k in range(len(self.s_idx))]
        last = time.monotonic()
        try:
            for k, future in enumerate(futures):
                while True:
                    wait = max(0.0, last + self.partial_period_s - time.monotonic())
                    try:
                        result = future.result(timeout=wait if self.on_partial is not None else None)
                        break
                    except FuturesTimeout:
                        self.report_partial(k)
                        last = time.monotonic()
                self.live.pop(k, None)
                yield result
        finally:  # normal end, or the caller stopped early: nothing more to compute
            self.stop.set()
            for future in futures:
                future.cancel()

    def matrix(self, timing: _Timing, *, workers: int, progress: Progress, on_row) -> HomeVectorMatrix:
        """Compute every row on ``workers`` threads; ``on_row`` gets each finished row in order."""
        s_idx, n_cur = self.s_idx, len(self.currents)
        with ThreadPoolExecutor(max(1, workers)) as pool:
            rows = []
            try:
                for si, r in zip(s_idx, progress(self.finished_rows(pool), desc="home vectors", total=len(s_idx))):
                    rows.append(r)
                    if on_row is not None:
                        on_row(int(si), r[0], r[1])
            finally:  # also when on_row or the progress bar raised: the pool must not wait for whole rows
                self.stop.set()
        t2 = time.perf_counter()
        angles = np.array([r[0] for r in rows]).reshape(len(s_idx), n_cur)
        compass = np.array([r[1] for r in rows]).reshape(len(s_idx), n_cur)
        has_compass = bool(np.any(np.isfinite(compass)))
        return HomeVectorMatrix(
            snapshot_index=s_idx,
            angles=angles,
            compass_error=compass if has_compass else None,
            prepare_s=timing.t1 - timing.t0,
            pairs_s=t2 - timing.t1,
            n_pairs=timing.n_pairs,
            prepared_stats=timing.prepared_stats,
        )


def _batch_options(method: HomingMethod, **options: Any) -> dict[str, Any]:
    """The ``options`` that ``method.all_pairs_angles`` accepts as keywords (``snapshot_index``, ``workers``, ...)."""
    import inspect

    accepted = inspect.signature(method.all_pairs_angles).parameters
    return {k: v for k, v in options.items() if k in accepted}


def _prepared_stats(method: HomingMethod, prepared: Sequence[Any]) -> dict[str, float]:
    """Means over the images of :meth:`HomingMethod.describe_prepared` (e.g. keypoints per image)."""
    described = [method.describe_prepared(p) for p in prepared]
    return {k: float(np.mean([d[k] for d in described])) for k in (described[0] if described else {})}
