"""Shell completion for ``python -m bionav`` (and the ``bionav`` script), on top of Hydra's.

Hydra's own bash completion (``-sc install=bash``) recognises ``python script.py`` and
console scripts, not ``python -m package``. bionav prints its own small bash function
instead, which asks ``python -m bionav -sc query=bash`` for the choices, and rewrites the
command line of such a query to the script form Hydra parses::

    eval "$(python -m bionav -sc install=bash)"     # in ~/.bashrc; zsh: autoload bashcompinit first
"""

from __future__ import annotations

import os
import re
from typing import Sequence

_PYTHON_M = re.compile(r"^\s*\S*python[0-9.]*\s+-m\s+bionav(?=\s|$)")

BASH_SCRIPT = r"""_bionav_completion()
{
    local words=($COMP_LINE) helper
    if [ "${words[0]##*/}" = bionav ]; then
        helper=("${words[0]}")
    elif [ "${words[1]}" = -m ] && [ "${words[2]}" = bionav ]; then
        helper=("${words[0]}" -m bionav)
    else
        return 0
    fi
    local choices
    choices=$(COMP_POINT=$COMP_POINT COMP_LINE=$COMP_LINE "${helper[@]}" -sc query=bash 2>/dev/null)
    COMPREPLY=($(compgen -o nospace -o default -W "$choices" -- "${words[$COMP_CWORD]}"))
}
COMP_WORDBREAKS=${COMP_WORDBREAKS//=}
complete -o nospace -o default -F _bionav_completion python python3 bionav
"""


def wants_bash_install(argv: Sequence[str]) -> bool:
    """True for ``-sc install=bash`` / ``--shell-completion install=bash``."""
    for flag, value in zip(argv, list(argv[1:]) + [""]):
        if flag in ("-sc", "--shell-completion") and value == "install=bash":
            return True
    return False


def rewrite_query_line(environ: dict | None = None) -> None:
    """Turn ``COMP_LINE='python -m bionav ...'`` into ``'bionav ...'`` (and move ``COMP_POINT``) for Hydra."""
    env = os.environ if environ is None else environ
    line = env.get("COMP_LINE")
    if not line:
        return
    match = _PYTHON_M.match(line)
    if match is None:
        return
    env["COMP_LINE"] = "bionav" + line[match.end():]
    point = env.get("COMP_POINT")
    if point is not None and point.isdigit():
        env["COMP_POINT"] = str(max(len("bionav"), int(point) - (match.end() - len("bionav"))))


#: config groups that exist for bionav's own wiring (typed schemas), never typed by users
INTERNAL_GROUPS = ("experiment_schema", "experiment_nodes", "db_schema")
_GROUP_WORD = re.compile(r"([+~]?)([A-Za-z_]\w*)=([^=,]*)")


def quick_choices(environ: dict | None = None) -> list[str] | None:
    """Choices for a ``group=prefix`` word, answered without Hydra (None: ask Hydra).

    The options are bionav's YAML presets and the plugins' entry points
    (:func:`bionav.clihelp.groups_and_options`); nothing is composed and no plugin is imported
    (but the sensors), so a TAB after ``homing=`` answers in a fraction of a second.
    """
    env = os.environ if environ is None else environ
    line = env.get("COMP_LINE", "")
    point = env.get("COMP_POINT")
    if point is not None and point.isdigit():
        line = line[: int(point)]
    if not line or line[-1].isspace():
        return None
    match = _GROUP_WORD.fullmatch(line.split()[-1])
    if match is None:
        return None
    from bionav.clihelp import groups_and_options

    sign, group, prefix = match.groups()
    options = groups_and_options(only=group).get(group)
    if options is None:
        return None
    return [f"{sign}{group}={o}" for o in options if o.startswith(prefix)]


def without_internal(choices: str) -> str:
    """Hydra's completion output less bionav's internal groups (:data:`INTERNAL_GROUPS`)."""
    words = [w for w in choices.split() if not w.lstrip("+~").startswith(INTERNAL_GROUPS)]
    return " ".join(words)
