"""What the thesis tool knows of a database before any run: its preset's grid, spacing and size."""

from __future__ import annotations

from functools import lru_cache


@lru_cache(maxsize=None)
def db_meta(db: str) -> dict:
    """Grid shape, spacing and the other settings of a database preset (composed through Hydra)."""
    from omegaconf import OmegaConf

    from bionav.config import compose

    cfg = compose([f"db={db}"])
    node = OmegaConf.to_container(cfg.db, resolve=False)
    return {k: node.get(k) for k in ("name", "grid_shape", "spacing_m", "horizon_row", "image_size", "source")}
