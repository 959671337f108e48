"""Errors that the command line turns into one clear message (no traceback).

The exception types only; the command-line wrapper that prints them is
:func:`bionav.cli_main.run_main`.
"""

from __future__ import annotations


class UserError(Exception):
    """A problem the user can fix: bad name, missing file, bad value, unreachable device.

    The message must be one paragraph that names the problem and the fix. The
    command line prints it and exits with status 2.
    """


class PluginError(UserError):
    """A plugin could not be found, loaded or instantiated."""


class DeviceError(UserError):
    """A serial device is missing, busy, silent or speaks garbage."""
