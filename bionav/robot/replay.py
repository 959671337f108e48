"""``python -m bionav.robot.replay RUN_DIR_OR_MCAP [--run K ...]``: replay logged cleaning runs.

Rebuilds controller, homing method, layout and (for images that were not
logged) the camera from the config attached to ``run.mcap``, feeds every
logged observation back through the controller and checks that it emits the
logged commands exactly. Exit status 0 when every run matches, 2 on the first
mismatch (with a message saying where).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


def main(argv: list[str] | None = None) -> int:
    from bionav.errors import UserError
    from bionav.experiments.cleaning import replay_log

    parser = argparse.ArgumentParser(prog="python -m bionav.robot.replay", description=__doc__.splitlines()[0])
    parser.add_argument("log", help="run.mcap of an experiment=cleaning run, or its run directory")
    parser.add_argument("--run", type=int, action="append", help="only this run (repeatable)")
    args = parser.parse_args(argv)
    path = Path(args.log)
    if path.is_dir():
        path = path / "run.mcap"
    try:
        results = replay_log(path, runs=args.run)
    except UserError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    for k, r in results.items():
        print(f"run {k}: {r.n_ticks} ticks replayed, every command identical")
    return 0


if __name__ == "__main__":
    sys.exit(main())
