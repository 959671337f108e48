"""The registry of thesis items: the runs each needs, its quantities, figures and verdict rule.

Every item declares (per preset) the ``python -m bionav`` runs it needs, and
turns the files those runs write (``metrics.json``, ``per_snapshot.csv``,
``cross_db.csv``, ``ranking_<db>.csv``, ``significance_<criterion>.csv``,
``stability.csv``, plots) into rows (thesis value, bionav value, difference,
tolerance), claim checks stated in words, and figures named after the item.
Nothing here imports an experiment: items depend only on the command line and
the files runs write.
"""

import importlib

from bionav.thesis.items.base import (
    REGISTRY,
    THESIS_DBS,
    TOL_ANGLE,
    TOL_RR,
    Context,
    Item,
    compare_bars,
    db_meta,
    grid_spec,
    item,
    markdown,
    rho_check,
    select_items,
    snapshot_list,
    spearman,
)

# the chapters register their items on import, in the report's order
for _chapter in ("ch3", "ch5", "ch5_params", "appendix_b", "ch4", "ch6", "ch7", "standins"):
    importlib.import_module(f"bionav.thesis.items.{_chapter}")

from bionav.thesis.items.ch6 import FEATURES  # noqa: E402

__all__ = ["FEATURES", "REGISTRY", "THESIS_DBS", "TOL_ANGLE", "TOL_RR", "Context", "Item", "compare_bars", "db_meta",
           "grid_spec", "item", "markdown", "rho_check", "select_items", "snapshot_list", "spearman"]
