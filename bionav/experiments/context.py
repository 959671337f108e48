"""What an experiment gets from the framework: run directory, log, plots, RNG, plugins."""

from __future__ import annotations

import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterable, Iterator

import numpy as np
from omegaconf import DictConfig

from bionav.logs.writer import McapLog


@dataclass
class RunContext:
    """Services an experiment's ``run(cfg, ctx)`` uses.

    Attributes
    ----------
    dir : Path
        The Hydra run directory (metrics.json, run.mcap and plots/ live here).
    log : McapLog
        The run's MCAP log (``ctx.log.write(topic, message, schema_name=...)``).
    rng : numpy.random.Generator
        Seeded from ``cfg.seed``; pass it (or generators spawned from it) on.
    cfg : DictConfig
        The resolved run configuration.
    show_progress : bool
        Whether progress bars are drawn (on stderr).
    nodes : dict
        The other config nodes the experiment reads (its ``group_configs``: ``layout``, ``data``,
        ``recordings``), checked instances of their dataclasses, by key.
    """

    dir: Path
    log: McapLog
    rng: np.random.Generator
    cfg: DictConfig
    show_progress: bool = True
    artifacts: dict[str, Path] = field(default_factory=dict)
    nodes: dict[str, Any] = field(default_factory=dict)

    @property
    def plots(self) -> Path:
        """``plots/`` below the run directory (created on first use)."""
        path = self.dir / "plots"
        path.mkdir(parents=True, exist_ok=True)
        return path

    def progress(self, iterable: Iterable[Any], *, desc: str, total: int | None = None) -> Iterator[Any]:
        """Wrap a long loop in a tqdm progress bar on stderr."""
        from tqdm.auto import tqdm

        return iter(
            tqdm(iterable, desc=desc, total=total, disable=not self.show_progress, file=sys.stderr, leave=False)
        )

    def plugin(self, kind: str, node: Any, **kwargs: Any) -> Any:
        """Instantiate the plugin a config node selects (``node.name``) with its typed config.

        Extra keyword arguments are passed to the plugin's constructor.
        """
        from bionav.config import plugin_config

        cls, config = plugin_config(kind, node)
        return cls(config, **kwargs)
