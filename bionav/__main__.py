"""``python -m bionav``."""

from bionav.cli import main

if __name__ == "__main__":
    from bionav.cli_main import run_main

    run_main(main, "bionav")
