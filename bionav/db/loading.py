"""The one public entry for getting a database: :func:`load_database`."""

from __future__ import annotations

import logging
from pathlib import Path

from bionav.db.config import DatabaseConfig
from bionav.db.database import ImageDatabase
from bionav.db.preprocess import preprocess_database, resize_database
from bionav.db.rotation import rotate_views
from bionav.errors import UserError

log = logging.getLogger(__name__)

#: The real databases of thesis table 3.1 (plus hall2 of appendix B); each has a
#: synthetic stand-in ``sim_<name>``.
REAL_DATABASES = ("original", "arboreal", "chairs", "day", "doorlit", "screen", "twilight", "winlit",
                  "hall1", "hall2", "moeller1", "roeben1", "uni")


def as_database_config(cfg) -> DatabaseConfig:
    """The ``db`` node as a checked :class:`DatabaseConfig` (:func:`bionav.validation.typed_config`).

    Parameters
    ----------
    cfg : DatabaseConfig, DictConfig or Mapping
        The ``db`` node (``${data_dir}`` resolved against the whole config).

    Raises
    ------
    UserError
        Unknown keys, values of the wrong type or out of range, keys this
        database does not use (the keys it uses listed), a mesh database
        without its mesh or grid (message names the key).
    """
    from bionav.validation import typed_config

    return typed_config(cfg, DatabaseConfig, key="db", what=f"db={_name_of(cfg)}")


def _name_of(cfg) -> str:
    name = cfg.get("name") if hasattr(cfg, "get") else getattr(cfg, "name", None)
    return str(name) if name is not None else DatabaseConfig.name


def _missing_folder_message(cfg: DatabaseConfig, folder: Path, data_dir: Path) -> str:
    name = cfg.name
    if cfg.source == "folder" and name == "folder" and cfg.path is None:
        return ("db=folder needs the folder that holds the images: pass db.path=DIR "
                "(images named <x>_<y>.png, see python -m bionav.db --help).")
    base = name[4:] if name.startswith("sim_") else name
    stand_in = (f" db=sim_{base} is its synthetic stand-in, rendered on first use."
                if base in REAL_DATABASES else "")
    if cfg.path is not None and Path(cfg.path).resolve() != (Path(data_dir) / name).resolve():
        where = f"set by db.path={cfg.path}"
    else:
        where = f"data_dir={data_dir}, set by data_dir=... or the BIONAV_DATA environment variable"
    return (f"database {name!r} not found: looked for the folder {folder.resolve()} ({where}). "
            f"bionav does not ship the real databases; put them under one directory as <dir>/{name}/ and "
            f"point data_dir=<dir> or the BIONAV_DATA environment variable at it, or give the folder "
            f"directly with db.path=DIR.{stand_in}")


def _render_progress(name: str):
    """A tqdm wrapper for render loops (stderr, cleared when done)."""
    import sys

    def wrap(iterable):
        from tqdm.auto import tqdm

        return tqdm(iterable, desc=f"rendering {name}", file=sys.stderr, leave=False)

    return wrap


def load_database(cfg, *, data_dir: Path, cache_dir: Path, preprocess=None) -> ImageDatabase:
    """Load the database a ``db`` config describes, as canonical panoramas.

    Parameters
    ----------
    cfg : DatabaseConfig or DictConfig
        The ``db`` config node. ``source: synthetic`` renders (or reads from
        the cache) the stand-in ``cfg.name`` through
        :func:`bionav.db.synthetic.synthetic_database`; ``source: folder``
        reads ``cfg.path``, or ``data_dir / cfg.name`` when no path is given
        (:func:`bionav.db.folder.load_folder`); ``source: bag`` reads a ROS bag's
        views and poses into a grid (:func:`bionav.db.bag.grid.load_bag_database`).
    data_dir : Path
        Where real databases live (``data_dir=`` / ``BIONAV_DATA``).
    cache_dir : Path
        Cache directory for rendered synthetic databases.
    preprocess : PreprocessConfig or list of steps, optional
        Applied at the database's native resolution, before the resize to
        ``db.image_size`` (the thesis filters before unfolding to the final
        size; see :mod:`bionav.db.preprocess`).

    Returns
    -------
    ImageDatabase
        Resized to ``db.image_size = [W, H]`` (``cv2.INTER_AREA``) if given;
        folder databases with ``db.rotate_current`` get a random rotation of
        every view (:func:`rotate_views`, seed ``db.rotation_seed``).

    Raises
    ------
    UserError
        Unknown source, missing folder (the message says where it looked, how
        to point ``data_dir``/``BIONAV_DATA`` at it and names the ``sim_``
        stand-in), or any invalid file (see :mod:`bionav.db.folder`).
    """
    cfg = as_database_config(cfg)
    source = cfg.source
    size = cfg.image_size
    if source == "synthetic":
        from bionav.db.synthetic import synthetic_database

        camera = {} if cfg.realism == "ideal" else dict(realism=cfg.realism, camera=cfg.camera,
                                                        pose_error=cfg.pose_error,
                                                        progress=_render_progress(cfg.name), threads=2)
        db = synthetic_database(cfg.name, image_size=size, seed=cfg.seed, noise=cfg.noise,
                                rotate_current=cfg.rotate_current, rotation_seed=cfg.rotation_seed,
                                cache_dir=Path(cache_dir), **camera)
    elif source == "folder":
        from bionav.db.folder import load_folder

        if cfg.path is None and cfg.name == "folder":
            raise UserError(_missing_folder_message(cfg, Path(data_dir), Path(data_dir)))
        folder = Path(cfg.path).expanduser() if cfg.path is not None else Path(data_dir) / cfg.name
        if not folder.is_dir():
            if folder.exists():
                raise UserError(f"database path {folder} is a file, not a folder; point db.path at the "
                                "directory that holds the images.")
            raise UserError(_missing_folder_message(cfg, folder, Path(data_dir)))
        db = load_folder(cfg, folder)
    elif source == "mesh":
        from bionav.db.mesh import mesh_grid_database

        db = mesh_grid_database(cfg, cache_dir=Path(cache_dir), progress=_render_progress(cfg.name))
        size = None  # rendered directly at db.image_size
    elif source == "bag":
        from bionav.db.bag.grid import load_bag_database

        db = load_bag_database(cfg)
    else:  # route (db.source is one of its declared choices)
        raise UserError(f"db={cfg.name} holds views along a route, not a grid; evaluate it with "
                        "experiment=route_homing (grid experiments need a grid database such as db=sim_seville).")
    _check_image_memory(db, size)
    db = preprocess_database(db, preprocess)
    if size is not None:
        db = resize_database(db, size)
    if source in ("folder", "bag") and cfg.rotate_current:
        db = rotate_views(db, seed=cfg.rotation_seed)
    return db


def _check_image_memory(db: ImageDatabase, size) -> None:
    """Refuse a ``db.image_size`` whose images would not fit in memory (before resizing)."""
    if size is None:
        return
    from bionav.validation import check_allocation

    w, h = size
    # the resized stack, the native stack and one working copy (float32)
    nbytes = 4.0 * len(db) * (w * h + 2 * db.geometry.width * db.geometry.height)
    check_allocation(
        nbytes,
        what=f"resizing the {len(db)} images of database {db.name!r} to db.image_size=[{w},{h}]",
        fix="choose a smaller db.image_size=[W,H] (the thesis uses up to [600,100])",
    )
