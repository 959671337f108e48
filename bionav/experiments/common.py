"""Pieces several experiments share: loading the configured database and homing method."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from omegaconf import DictConfig, OmegaConf

from bionav.db.database import ImageDatabase


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
        cache_dir=Path(str(cfg.cache_dir)),
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


def make_homing(cfg: DictConfig, ctx, geometry):
    """Instantiate ``cfg.homing`` (and ``cfg.signature`` for methods that take one)."""
    import inspect

    from bionav import registry

    cls = registry.load_plugin("homing", str(cfg.homing.name))
    kwargs: dict[str, Any] = {"geometry": geometry}
    if "signature" in inspect.signature(cls.__init__).parameters and cfg.get("signature"):
        kwargs["signature"] = ctx.plugin("signature", cfg.signature)
    return ctx.plugin("homing", cfg.homing, **kwargs)


def prepared_cache(cfg: DictConfig):
    """The on-disk cache of per-image work for ``cfg.homing`` (None when ``bionav.cache_prepared=false``)."""
    if not OmegaConf.select(cfg, "bionav.cache_prepared", default=True):
        return None
    from bionav.evaluation.prepcache import PreparedCache

    name = str(cfg.homing.name)
    if cfg.get("signature") and cfg.signature.get("name"):
        name = f"{name}-{cfg.signature.name}"
    return PreparedCache(Path(str(cfg.cache_dir)), name)
