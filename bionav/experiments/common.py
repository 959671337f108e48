"""Pieces several experiments share: the configured database, homing method, worker pool and sample set."""

from __future__ import annotations

import contextlib
from pathlib import Path
from typing import Any

from omegaconf import DictConfig, OmegaConf

from bionav.db.database import ImageDatabase
from bionav.errors import UserError
from bionav.files import user_path
from bionav.machine import usable_cpus


def load_configured_database(cfg: DictConfig, node: Any | None = None) -> ImageDatabase:
    """The database the config selects (``cfg.db`` unless ``node`` given), preprocessed per ``cfg.preprocess``."""
    from bionav.db.loading import load_database

    preprocess = OmegaConf.select(cfg, "preprocess", default=None)
    node = cfg.db if node is None else node
    if isinstance(node, DictConfig):
        node = OmegaConf.to_container(node, resolve=True)  # resolve ${data_dir} against the whole config
    db = load_database(
        node,
        data_dir=Path(str(cfg.data_dir)),
        cache_dir=user_path(str(cfg.cache_dir)),
        preprocess=preprocess,
    )
    if len(db) < 2:
        from bionav.errors import UserError

        where = db.meta.get("path") or db.name
        raise UserError(
            f"database {db.name!r} ({where}) has {len(db)} usable image(s); homing needs at least 2 "
            "(a snapshot and a current view), so there are no image pairs to evaluate. Add images "
            "(and check db.grid_shape and the warnings about skipped files)."
        )
    return db


def _init_pool_worker(numba_threads: int, initializer, initargs: tuple) -> None:
    """First thing in a pool worker: its numba thread pool sized to its share of the CPUs, then ``initializer``."""
    import os
    import sys

    os.environ["NUMBA_NUM_THREADS"] = str(numba_threads)  # read when numba is first imported in this worker
    if "numba" in sys.modules:  # imported while unpickling the initializer: no parallel region has run yet
        from numba.core import config

        config.reload_config()
    if initializer is not None:
        initializer(*initargs)


@contextlib.contextmanager
def worker_pool(workers: int, *, initializer=None, initargs: tuple = ()):
    """A pool of ``workers`` spawned processes that is torn down at once when the run stops.

    On leaving the ``with`` block normally the pool finishes its tasks; on
    an exception (a failed task, Ctrl-C) the workers are terminated, so an
    interrupted run does not wait for the tasks still queued.

    The pool has at most :func:`usable_cpus` processes (more processes than
    CPUs only add memory and start-up time to CPU-bound tasks), and each
    worker's numba thread pool gets its share of the CPUs
    (``NUMBA_NUM_THREADS = max(1, CPUs // processes)``): without it every
    worker starts one numba thread per CPU (the renderer's parallel loops),
    ``workers x CPUs`` threads in all (256 with 16 workers on 16 cores).

    Yields
    ------
    multiprocessing.pool.Pool
    """
    from multiprocessing import get_context

    cpus = usable_cpus()
    n = max(1, min(int(workers), cpus))
    pool = get_context("spawn").Pool(n, initializer=_init_pool_worker,
                                     initargs=(max(1, cpus // n), initializer, tuple(initargs)))
    try:
        yield pool
    except BaseException:
        pool.terminate()
        pool.join()
        raise
    pool.close()
    pool.join()


def make_homing(cfg: DictConfig, ctx, geometry, *, raw_horizon_radius_px: float | None = None):
    """Instantiate ``cfg.homing`` (and ``cfg.signature`` for methods that take one).

    Methods that take ``raw_horizon_radius_px`` (filters defined on the raw
    camera frame, e.g. the warping methods' ``butterworth_relative_to=raw``)
    get the database's (``db.meta["raw_horizon_radius_px"]``), else the
    ultra-wide-view mirror's, as the preprocessing chain (:mod:`bionav.db.preprocess`).
    """
    import inspect

    from bionav import registry

    cls = registry.load_plugin("homing", str(cfg.homing.name))
    kwargs: dict[str, Any] = {"geometry": geometry}
    params = inspect.signature(cls.__init__).parameters
    if "signature" in params and cfg.get("signature"):
        kwargs["signature"] = ctx.plugin("signature", cfg.signature)
    if "raw_horizon_radius_px" in params:
        if raw_horizon_radius_px is None:
            from bionav.db.camera import raw_horizon_radius

            raw_horizon_radius_px = raw_horizon_radius("ultra-wide")
        kwargs["raw_horizon_radius_px"] = float(raw_horizon_radius_px)
    return ctx.plugin("homing", cfg.homing, **kwargs)


def prepared_cache(cfg: DictConfig):
    """The on-disk cache of per-image work for ``cfg.homing`` (None when ``bionav.cache_prepared=false``)."""
    if not OmegaConf.select(cfg, "bionav.cache_prepared", default=True):
        return None
    from bionav.evaluation.prepcache import PreparedCache

    name = str(cfg.homing.name)
    if cfg.get("signature") and cfg.signature.get("name"):
        name = f"{name}-{cfg.signature.name}"
    return PreparedCache(user_path(str(cfg.cache_dir)), name)


def load_samples(data):
    """The sample set a checked ``data`` config names.

    Parameters
    ----------
    data : DataConfig or LearnSamplesConfig
        (:mod:`bionav.spectral.sample_config`) ``name`` (``sim_natural``, ``sim_artificial`` or ``csv``)
        and its options: ``seed``, ``n_objects``, ``n_sky``, ``n_average``, ``noise_counts`` for the
        simulated sets (defaults where the config has no such field, or ``None``); ``path`` for ``csv``.

    Returns
    -------
    SampleSet
    """
    from bionav.spectral.sensor_model import LogSensorModel

    def _get(key, default=None):
        value = getattr(data, key, None)
        return default if value is None else value

    name = str(_get("name", ""))
    if name == "csv":
        path = _get("path")
        if not path or str(path) == "???":
            raise UserError("data=csv needs the file: add data.path=/path/to/samples.csv (columns class,UV,B,G,R,IR, "
                            "optional kind,time).")
        from bionav.spectral.csv_io import read_samples_csv

        try:
            from hydra.utils import to_absolute_path

            path = to_absolute_path(str(path))
        except Exception:
            pass
        return read_samples_csv(path)
    if name in ("sim_natural", "sim_artificial"):
        from bionav.spectral import samples as sim

        sensor = LogSensorModel(noise_counts=float(_get("noise_counts", 4.0)))
        default_objects = 239 if name == "sim_natural" else 124
        fn = sim.sim_natural if name == "sim_natural" else sim.sim_artificial
        return fn(seed=int(_get("seed", 0)), n_objects=int(_get("n_objects", default_objects)),
                  n_sky=int(_get("n_sky", 233)), sensor=sensor, n_average=int(_get("n_average", 10)))
    raise UserError(f"Unknown data set {name!r} for experiment=contrast_lda. Choose data=sim_natural, "
                    f"data=sim_artificial, or data=csv data.path=FILE.")


def db_preset(name: str, *, key: str = "the cross_db family") -> dict:
    """The ``bionav/conf/db/<name>.yaml`` preset from any config folder (``key``: where the name was given, for the
    message naming a missing preset)."""
    import yaml

    from bionav.config import config_dirs

    for _n, folder in config_dirs():
        path = folder / "db" / f"{name}.yaml"
        if path.is_file():
            return yaml.safe_load(path.read_text()) or {}
    raise UserError(f"{key} names the database {name!r}, which has no preset (bionav/conf/db/{name}.yaml).")
