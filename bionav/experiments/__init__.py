"""Experiments: one folder per experiment, each a plugin of the entry-point group ``bionav.experiments``.

``bionav/experiments/<name>/`` holds the plugin class (``__init__.py``, a subclass of
:class:`~bionav.experiments.base.Experiment`), its typed config (``config.py``), its
``run.py`` and ``plots.py`` and the modules of its own; the shared machinery is here:
the runner (``runner.py``: metrics.json and run.mcap whatever happens), the run context
(``context.py``), the run settings and the typed ``experiment`` node (``settings.py``),
pieces several experiments use (``common.py``, ``ranges.py``), split runs (``tasks.py``,
``merge/``) and the sweep objective (``objective.py``). No experiment imports another.
"""

from bionav.experiments.base import Experiment

__all__ = ["Experiment"]
