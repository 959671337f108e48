"""Image databases: loaders, synthetic stand-ins, preprocessing."""

from bionav.db.database import ImageDatabase

__all__ = ["ImageDatabase"]
