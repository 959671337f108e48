"""Shared command-line plumbing of the ``python -m bionav.bench*`` commands.

* :class:`BenchParser` reports a bad argument as one line,
  ``<prog>: error: <problem and fix> (see <prog> --help)``, exit status 2,
  without argparse's usage block;
* :func:`run` runs a ``main`` and exits with its status: output into a closed
  pipe (``... | head -1``) ends quietly with status 141 (128 + SIGPIPE), a
  :class:`~bionav.errors.UserError` becomes ``<prog>: error: <message>`` with
  status 2, never a traceback.
"""

from __future__ import annotations

import argparse
import sys
from typing import Callable, NoReturn

from bionav.cli_main import run_main


class BenchParser(argparse.ArgumentParser):
    """``argparse.ArgumentParser`` whose errors are one line naming the option (no usage block)."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")

    def _print_message(self, message, file=None) -> None:
        # argparse swallows a closed pipe here (--help | head -0 would exit 0 having printed nothing)
        if message:
            (file or sys.stderr).write(message)


def bounded_int(parser: argparse.ArgumentParser, name: str, value: int, lo: int, hi: int, why: str = "") -> None:
    """Exit through ``parser.error`` unless ``lo <= value <= hi`` (one message naming ``name`` and the range)."""
    if not (lo <= value <= hi):
        parser.error(f"{name} {value} is out of range: it must lie in {lo}..{hi}{why}; "
                     f"e.g. {name} {min(max(value, lo), hi)}")


def run(main: Callable[[], "int | None"], prog: str) -> NoReturn:
    """Run ``main()`` and exit with its status: :func:`bionav.cli_main.run_main` (closed pipe: quiet 141;
    :class:`UserError`: message, 2; Ctrl-C: message, 130)."""
    run_main(main, prog, interrupted="interrupted; nothing more was measured.")
