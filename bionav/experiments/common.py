"""Pieces several experiments share: loading the configured database and homing method."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from omegaconf import DictConfig, OmegaConf

from bionav.db.database import ImageDatabase
from bionav.errors import UserError


def database_config(node: Any):
    """Validate a ``db`` config node against :class:`bionav.db.config.DatabaseConfig`."""
    from bionav.db.config import DatabaseConfig

    plain = OmegaConf.to_container(node, resolve=True) if isinstance(node, DictConfig) else dict(node)
    try:
        return OmegaConf.to_object(OmegaConf.merge(OmegaConf.structured(DatabaseConfig), plain))
    except Exception as exc:
        raise UserError(f"bad database settings: {exc}") from None


def load_configured_database(cfg: DictConfig, node: Any | None = None) -> ImageDatabase:
    """The database the config selects (``cfg.db`` unless ``node`` given), preprocessed per ``cfg.preprocess``."""
    from bionav.db.loading import load_database

    db_cfg = database_config(cfg.db if node is None else node)
    db = load_database(db_cfg, data_dir=Path(str(cfg.data_dir)), cache_dir=Path(str(cfg.cache_dir)))
    steps = OmegaConf.select(cfg, "preprocess.steps", default=None)
    if steps:
        from bionav.db.preprocess import preprocess_database

        db = preprocess_database(db, OmegaConf.to_container(steps, resolve=True))
    return db


def make_homing(cfg: DictConfig, ctx, geometry):
    """Instantiate ``cfg.homing`` (and ``cfg.signature`` for methods that take one)."""
    import inspect

    from bionav import registry

    cls = registry.load_plugin("homing", str(cfg.homing.name))
    kwargs: dict[str, Any] = {"geometry": geometry}
    if "signature" in inspect.signature(cls.__init__).parameters and cfg.get("signature"):
        kwargs["signature"] = ctx.plugin("signature", cfg.signature)
    return ctx.plugin("homing", cfg.homing, **kwargs)
