"""The thesis, reproduced by one command: ``python -m bionav.thesis``.

``reference.yaml`` holds the thesis' values (transcribed, with page and table
references); :mod:`bionav.thesis.items` is the registry of items (the runs each
needs, its quantities, figures and verdict rule); :mod:`bionav.thesis.runs`
executes runs through ``python -m bionav`` (deduplicated, resumable, locally or
through any Hydra launcher); :mod:`bionav.thesis.report` writes ``report.md``,
``report.html`` and ``items.csv``. See docs/thesis.md.
"""
