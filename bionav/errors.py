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


def require_extra(module: str, *, extra: str, what: str):
    """Import an optional dependency, or raise the one message that names its install line.

    Parameters
    ----------
    module : str
        The module to import (``rosbags``, ``foxglove``).
    extra : str
        The bionav extra that installs it (``ros``, ``live``).
    what : str
        What needs it, as the user asked for it (``db=bag``, ``bionav.live=8765``).

    Returns
    -------
    module
        The imported module.

    Raises
    ------
    UserError
        ``<what> needs <module>, which is not installed: pip install "bionav[<extra>]"``.
    """
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise UserError(
            f"{what} needs the Python package {module.split('.')[0]!r}, which is not installed here ({exc}); "
            f"install it with: pip install \"bionav[{extra}]\" (in a clone of bionav: pip install \".[{extra}]\")."
        ) from None
