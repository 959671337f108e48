"""``python -m bionav.db``: see :mod:`bionav.db.cli`."""

from bionav.cli_main import run_main
from bionav.db.cli import main

run_main(main, "bionav.db")
