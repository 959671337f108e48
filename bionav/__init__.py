"""bionav: biologically inspired visual navigation."""

__version__ = "0.1.0"
