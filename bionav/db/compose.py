"""Composing a ``db`` config from bionav's ``bionav/conf/`` folder with Hydra's compose API.

Used by ``python -m bionav.db``; the main ``python -m bionav`` entry point
composes its configs through Hydra's own application machinery instead.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from bionav.db.config import DatabaseConfig
from bionav.errors import UserError


def available_databases() -> list[str]:
    """Names selectable as ``db=<name>`` (the ``db`` presets of every config package)."""
    from bionav.config import config_options

    return config_options("db")


@dataclass
class ComposedDatabase:
    """A resolved ``db`` config and the directories it needs."""

    db: DatabaseConfig
    data_dir: Path
    cache_dir: Path


def compose_database(name: str, overrides=()) -> ComposedDatabase:
    """Compose ``db=<name>`` plus Hydra overrides into a validated :class:`DatabaseConfig`.

    Parameters
    ----------
    name : str
        A database preset (``sim_original``, ``hall1``, ``folder`` ...).
    overrides : sequence of str
        Hydra overrides such as ``db.seed=1``, ``db.path=DIR``,
        ``data_dir=DIR``, ``cache_dir=DIR``.

    Returns
    -------
    ComposedDatabase

    Raises
    ------
    UserError
        Unknown database name (the message lists the available ones), a
        malformed override or a value of the wrong type.
    """
    from hydra.errors import HydraException
    from omegaconf import OmegaConf
    from omegaconf.errors import OmegaConfBaseException

    from bionav.config import compose
    from bionav.db.loading import as_database_config

    names = available_databases()
    if name not in names:
        raise UserError(f"unknown database {name!r}; the available databases are: {', '.join(names)}.")
    overrides = list(overrides)
    try:
        cfg = compose([f"db={name}", *overrides])
        data_dir = Path(str(cfg.data_dir)).expanduser()
        cache_dir = Path(str(cfg.cache_dir)).expanduser()
        node = OmegaConf.to_container(cfg.db, resolve=True)
    except (HydraException, OmegaConfBaseException) as exc:
        first = str(exc).strip().splitlines()[0].rstrip(".") if str(exc).strip() else type(exc).__name__
        raise UserError(
            f"cannot compose the configuration for db={name} with {' '.join(overrides) or 'no overrides'}: "
            f"{first}. Check the override syntax (key=value, e.g. db.seed=1) and the key names "
            f"(db.* keys: {', '.join(DatabaseConfig.__dataclass_fields__)})."
        ) from None
    return ComposedDatabase(as_database_config(node), data_dir, cache_dir)
