"""The command-line plumbing of every ``__main__``: user errors to one message, quiet closed pipes.

:func:`run_main` wraps each ``python -m bionav...`` command's ``main()``; it is
the one place outside the Hydra entry point (:mod:`bionav.cli`) where a
:class:`~bionav.errors.UserError` becomes ``<prog>: error: <message>`` on stderr
(exit status 2), and :func:`guard_closed_pipe` the one home of the handling of
output into a closed pipe (exit status 141, no traceback). It lives in a module
of its own so that :mod:`bionav.errors`, the lowest room, holds only the
exception types and never prints.
"""

from __future__ import annotations

from typing import Callable, NoReturn

from bionav.errors import UserError

#: exit status after output went into a closed pipe (128 + SIGPIPE, what a shell reports for `yes | head -1`)
EXIT_CLOSED_PIPE = 141


def closed_pipe_exit() -> NoReturn:
    """End the process quietly because stdout's reader has gone (``... | head -1``).

    Points stdout at ``/dev/null`` so the interpreter's final flush cannot
    raise again, then exits with :data:`EXIT_CLOSED_PIPE` (``SystemExit``,
    which Hydra's error reporting lets through).
    """
    import os
    import sys

    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.__stdout__.fileno())
    except (OSError, ValueError, AttributeError):
        pass
    sys.exit(EXIT_CLOSED_PIPE)


class _ClosedPipeGuard:
    """``sys.stdout`` whose writes end the process quietly when the reader has gone."""

    def __init__(self, stream) -> None:
        self._stream = stream

    def write(self, text: str) -> int:
        try:
            return self._stream.write(text)
        except BrokenPipeError:
            closed_pipe_exit()

    def flush(self) -> None:
        try:
            self._stream.flush()
        except BrokenPipeError:
            closed_pipe_exit()

    def __getattr__(self, name: str):
        return getattr(self._stream, name)


def guard_closed_pipe() -> None:
    """Make output into a closed pipe end the process quietly (the one home of this handling).

    Text that cannot be encoded (a file name holding a byte that is not UTF-8, which Python
    carries as a lone surrogate) is written with backslash escapes instead of raising.

    Called by :func:`run_main` and :func:`bionav.cli.main`: ``python -m bionav --help | head -1``,
    ``python -m bionav.plugins | head -1`` and ``python -m bionav.logs info ... | head -1`` exit
    with status :data:`EXIT_CLOSED_PIPE` and no ``BrokenPipeError`` traceback.
    """
    import sys

    for stream in (sys.stdout, sys.stderr):  # a path with a byte that is not UTF-8 is printed, escaped, never a crash
        try:
            stream.reconfigure(errors="backslashreplace")
        except (AttributeError, ValueError, OSError):  # not a text stream of the interpreter's own
            pass
    if not isinstance(sys.stdout, _ClosedPipeGuard) and sys.stdout is not None:
        sys.stdout = _ClosedPipeGuard(sys.stdout)


def _terminate(signum, frame) -> None:  # noqa: ARG001
    raise KeyboardInterrupt


def end_on_termination_signals() -> None:
    """SIGTERM (``kill``, a cluster's time limit) and SIGHUP (the terminal closed) end a command as Ctrl-C does.

    The one home of this handling: every ``python -m bionav...`` command keeps what it wrote and says so.
    A signal the caller chose to ignore stays ignored (``nohup python -m bionav ...`` survives the hangup).
    """
    import signal

    for name in ("SIGTERM", "SIGHUP"):
        try:
            sig = getattr(signal, name)
            if signal.getsignal(sig) != signal.SIG_IGN:
                signal.signal(sig, _terminate)
        except (ValueError, AttributeError):  # not the main thread; no SIGHUP on this platform
            pass


def run_main(main: Callable[[], "int | None"], prog: str, *,
             interrupted: str = "interrupted; what was written so far is kept.") -> NoReturn:
    """Run a command's ``main()`` and exit with its status: the one wrapper of every ``__main__``.

    * output into a closed pipe ends quietly (:func:`guard_closed_pipe`), also argparse's
      ``--help | head -1``;
    * a :class:`UserError` that escapes ``main`` becomes ``<prog>: error: <message>``
      on stderr and exit status 2;
    * Ctrl-C, SIGTERM and SIGHUP (:func:`end_on_termination_signals`) become ``<prog>: <interrupted>``
      and exit status 130, never a traceback.
    """
    import sys

    guard_closed_pipe()
    end_on_termination_signals()
    try:
        try:
            code = main()
        except SystemExit as exc:  # argparse's --help and errors: their output is flushed below too
            code = exc.code
        except UserError as exc:
            print(f"{prog}: error: {exc}", file=sys.stderr)
            code = 2
        except KeyboardInterrupt:
            print(f"{prog}: {interrupted}", file=sys.stderr)
            code = 130
        sys.stdout.flush()
    except BrokenPipeError:
        closed_pipe_exit()
    if isinstance(code, str):  # sys.exit("message")
        print(code, file=sys.stderr)
        code = 1
    sys.exit(code or 0)
