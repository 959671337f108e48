"""``python -m bionav.db``: see :mod:`bionav.db.cli`."""

import sys

from bionav.db.cli import main

sys.exit(main())
