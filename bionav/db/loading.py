"""Loading the database a config describes (synthetic stand-ins and folders on disk)."""

from __future__ import annotations

from pathlib import Path

from bionav.db.config import DatabaseConfig
from bionav.db.database import ImageDatabase
from bionav.errors import UserError


def load_database(cfg: DatabaseConfig, *, data_dir: Path, cache_dir: Path) -> ImageDatabase:
    """Load (or render) the database ``cfg`` describes, as canonical panoramas."""
    if cfg.source == "synthetic":
        from bionav.db.synthetic import synthetic_database

        return synthetic_database(
            cfg.name,
            image_size=None if cfg.image_size is None else tuple(cfg.image_size),
            seed=cfg.seed,
            noise=cfg.noise,
            rotate_current=cfg.rotate_current,
            rotation_seed=cfg.rotation_seed,
            cache_dir=cache_dir,
        )
    raise UserError(f"database source {cfg.source!r} is not supported; use 'synthetic' or 'folder'.")
