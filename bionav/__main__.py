"""``python -m bionav``."""

from bionav.cli import main

if __name__ == "__main__":
    main()
