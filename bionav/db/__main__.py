"""``python -m bionav.db``: see :mod:`bionav.db.cli`."""

from bionav.db.cli import main
from bionav.errors import run_main

run_main(main, "bionav.db")
