"""Time the command line's start-up: ``python -m bionav.bench.startup [--json] [--repeat N]``.

Rows (wall and CPU seconds of a fresh ``python -m bionav`` process, median and minimum over
``--repeat`` rounds, the commands alternated within each round):

* ``help`` -- ``python -m bionav --help`` (every group and its choices, the composed config);
* ``cfg_job`` -- ``python -m bionav --cfg job`` (one composition, the selected plugins imported);
* ``tab_group`` -- one TAB completion after ``homing=`` (``-sc query=bash``, answered without Hydra);
* ``tab_key`` -- one TAB completion of a key (``homing.search_r``: Hydra composes the config).

Targets (issue 28, 2 idle cores): ``help`` and ``cfg_job`` <= 1.5 s wall, a TAB completion
<= 0.5 s wall. The CPU time is the child's own (user + system, ``os.wait4``).

Bytecode is cached as on a user's machine, whatever the environment says: the children write it to
a private ``PYTHONPYCACHEPREFIX`` folder (removed at the end; nothing is written into the checkout),
filled by one warm-up round, with ``PYTHONDONTWRITEBYTECODE`` unset (set, every module of bionav
would be compiled from source at every start, 0.1-0.2 s more).
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import time

#: name -> (arguments of ``python -m bionav``, COMP_LINE of a completion query or None)
COMMANDS = {
    "help": (["--help"], None),
    "cfg_job": (["--cfg", "job"], None),
    "tab_group": (["-sc", "query=bash"], "python -m bionav homing="),
    "tab_key": (["-sc", "query=bash"], "python -m bionav homing.search_r"),
}


def _time_once(args: list[str], comp_line: str | None, *, pycache: str) -> tuple[float, float]:
    env = dict(os.environ, PYTHONPYCACHEPREFIX=pycache)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    if comp_line is not None:
        env.update(COMP_LINE=comp_line, COMP_POINT=str(len(comp_line)))
    start = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-m", "bionav", *args], stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, env=env)
    _pid, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    if os.waitstatus_to_exitcode(status) != 0:
        from bionav.errors import UserError

        raise UserError(f"`python -m bionav {' '.join(args)}` failed (exit {os.waitstatus_to_exitcode(status)}); "
                        f"run it by hand to see why.")
    return wall, usage.ru_utime + usage.ru_stime


def main(argv=None) -> int:
    from bionav.bench._cli import BenchParser, bounded_int

    parser = BenchParser(prog="python -m bionav.bench.startup",
                         description="Time python -m bionav --help, --cfg job and TAB completions (wall and CPU s).")
    parser.add_argument("--json", action="store_true", help="one JSON object per line")
    parser.add_argument("--repeat", type=int, default=5, help="alternated rounds (default: 5; 1..100)")
    args = parser.parse_args(argv)
    bounded_int(parser, "--repeat", args.repeat, 1, 100)
    import tempfile

    samples: dict[str, list[tuple[float, float]]] = {name: [] for name in COMMANDS}
    with tempfile.TemporaryDirectory(prefix="bionav-pycache-") as pycache:
        for args_, comp in COMMANDS.values():  # warm the file-system and bytecode caches once
            _time_once(args_, comp, pycache=pycache)
        for _ in range(args.repeat):
            for name, (args_, comp) in COMMANDS.items():
                samples[name].append(_time_once(args_, comp, pycache=pycache))
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else None
    for name, rows in samples.items():
        walls, cpus = [w for w, _ in rows], [c for _, c in rows]
        row = {"benchmark": name, "command": "python -m bionav " + " ".join(COMMANDS[name][0]),
               "comp_line": COMMANDS[name][1], "wall_s": statistics.median(walls), "wall_s_min": min(walls),
               "cpu_s": statistics.median(cpus), "cpu_s_min": min(cpus), "rounds": args.repeat,
               "loadavg_1min": load}
        if args.json:
            print(json.dumps(row))
        else:
            print(f"{name:<10} wall {row['wall_s']:6.2f} s (min {row['wall_s_min']:.2f})  "
                  f"cpu {row['cpu_s']:6.2f} s (min {row['cpu_s_min']:.2f})  {row['command']}")
    return 0


if __name__ == "__main__":
    from bionav.bench._cli import run

    run(main, "python -m bionav.bench.startup")
