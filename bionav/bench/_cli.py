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
import os
import sys
from typing import Callable, NoReturn

from bionav.errors import UserError

#: exit status after output went into a closed pipe (128 + SIGPIPE, as a shell reports for ``yes | head -1``)
EXIT_CLOSED_PIPE = 141


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


def _closed_pipe() -> NoReturn:
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):
        pass
    os._exit(EXIT_CLOSED_PIPE)


def run(main: Callable[[], "int | None"], prog: str) -> NoReturn:
    """Run ``main()`` and exit with its status (closed pipe: quiet 141; :class:`UserError`: message, 2)."""
    try:
        try:
            code = main()
        except SystemExit as exc:  # argparse's --help and errors: flush their output here too
            code = exc.code
        except UserError as exc:
            print(f"{prog}: error: {exc}", file=sys.stderr)
            code = 2
        except KeyboardInterrupt:
            print(f"{prog}: interrupted; nothing more was measured.", file=sys.stderr)
            code = 130
        sys.stdout.flush()
    except BrokenPipeError:
        _closed_pipe()
    if isinstance(code, str):
        print(code, file=sys.stderr)
        code = 1
    sys.exit(code or 0)
