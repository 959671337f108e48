"""Every ``python -m bionav...`` command shown in README.md and docs/*.md works.

Commands are collected from fenced code blocks (with ``\\`` continuations, ``&&``
chains, trailing ``&`` and ``#`` comments) and from inline backticks (also
when they span a line break). Each ``python -m bionav`` command is composed by
Hydra in a subprocess with ``--cfg job`` (a multirun ``-m`` command once per
combination of its sweep values); commands of other modules run with
``--help`` (after their sub-command, if any), and the cheap ones
(``bionav.plugins``, ``bionav.logs``, ``bionav.report``) also for real on
tiny inputs. A failure names the file, the line and the command.
"""

from __future__ import annotations

import itertools
import json
import re
import shlex
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import pytest
from helpers import docs_packages, source_copy, write_docs_package

ROOT = Path(__file__).resolve().parents[2]

#: placeholders used in the docs and what a test substitutes (RUN/DIR/<date>/<time> are real dirs)
PLACEHOLDERS = {
    "<partition>": "debug",
    "<any>": "sift",
    "<db>": "sim_original",
    "<directory>": "multirun/2026-01-01/00-00-00",
    "<its directory>": "multirun/2026-01-01/00-00-00",
    "<date>": "2026-01-01",
    "<time>": "00-00-00",
}
#: modules run for real on tiny inputs (all others: --help only)
REAL_RUN_MODULES = ("bionav.plugins", "bionav.logs", "bionav.report")


@dataclass(frozen=True)
class Command:
    file: str
    line: int
    text: str
    requires: str | None = None  # a local package the docs `pip install` earlier in the same block

    def where(self) -> str:
        return f"{self.file}:{self.line}: {self.text}"


def _doc_files() -> list[Path]:
    return [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]


def _split_shell(line: str) -> list[str]:
    """Commands of one shell line: comments dropped, split at ``&&``, ``;``, ``|`` and ``&``."""
    out, buf, quote = [], "", None
    i = 0
    while i < len(line):
        c = line[i]
        if quote:
            buf += c
            if c == quote:
                quote = None
        elif c in "'\"":
            quote = c
            buf += c
        elif c == "#" and (not buf or buf[-1].isspace()):
            break
        elif c in ";|&":
            out.append(buf)
            buf = ""
            while i + 1 < len(line) and line[i + 1] in "&|":
                i += 1
        else:
            buf += c
        i += 1
    out.append(buf)
    return [s.strip() for s in out if s.strip()]


def documented_commands() -> list[Command]:
    """Every ``python -m bionav...`` command in README.md and docs/*.md."""
    found: list[Command] = []
    for path in _doc_files():
        rel = str(path.relative_to(ROOT))
        text = path.read_text()
        lines = text.splitlines()
        in_block = False
        requires = None
        pending, start = "", 0
        outside: list[tuple[int, str]] = []
        for n, line in enumerate(lines, 1):
            if line.lstrip().startswith("```"):
                in_block = not in_block
                requires = None
                outside.append((n, ""))
                continue
            outside.append((n, "" if in_block else line))
            if not in_block:
                continue
            if not pending:
                start = n
            if line.rstrip().endswith("\\"):
                pending += line.rstrip()[:-1] + " "
                continue
            for cmd in _split_shell(pending + line):
                words = cmd.split()
                if words[:2] == ["pip", "install"] or words[:4] == ["python", "-m", "pip", "install"]:
                    local = [w for w in words if w not in (".", "-e") and ((ROOT / w).is_dir()
                                                                         or w.rstrip("/") in docs_packages())]
                    requires = local[-1].rstrip("/") if local else requires
                if cmd.startswith("python -m bionav"):
                    found.append(Command(rel, start, " ".join(words), requires))
            pending = ""
        # inline code outside fenced blocks, possibly across one line break
        prose = "\n".join(l for _, l in outside)
        for m in re.finditer(r"`([^`]+)`", prose):
            cmd = " ".join(m.group(1).split())
            if cmd.startswith("python -m bionav"):
                found.append(Command(rel, prose.count("\n", 0, m.start()) + 1, cmd))
    return found


def _is_syntax_line(cmd: str) -> bool:
    """A usage pattern such as ``python -m bionav [group=option ...]`` or ``info|recover``, not a command."""
    return "..." in cmd or any("|" in word and "=" not in word for word in cmd.split())


@pytest.fixture(scope="module")
def sandbox(tmp_path_factory):
    """A working directory where RUN, DIR and outputs/<date>/<time> exist as tiny real runs."""
    from bionav.logs.writer import McapLog

    root = tmp_path_factory.mktemp("docs")
    for rel in ("RUN", "DIR/0", "outputs/2026-01-01/00-00-00", "multirun/2026-01-01/00-00-00/0"):
        run = root / rel
        run.mkdir(parents=True)
        (run / "metrics.json").write_text(json.dumps({"experiment": "grid_homing", "status": "completed",
                                                      "aae": 0.5, "mae": 0.4, "rr": 0.9}))
        with McapLog(run / "run.mcap") as log:
            log.attach("config.yaml", b"seed: 0\n", media_type="application/yaml")
            log.write("/test", {"x": 1}, schema_name="bionav.Test")
        (run / ".hydra").mkdir()
        (run / ".hydra" / "overrides.yaml").write_text("- homing=sift\n")
    (root / "run.mcap").write_bytes((root / "RUN" / "run.mcap").read_bytes())
    (root / "my_readings.csv").write_text("class,UV,B,G,R,IR\nsky,1,2,3,4,5\n")
    return root


def _substitute(cmd: Command) -> list[str]:
    text = cmd.text
    for key, value in PLACEHOLDERS.items():
        text = text.replace(key, value)
    unknown = re.findall(r"<[A-Za-z _-]+>", text)
    assert not unknown, (f"{cmd.where()}\n  unknown placeholder {unknown}: add it to PLACEHOLDERS in "
                         f"tests/project/test_documented_commands.py")
    args = shlex.split(text)[3:]  # drop python -m bionav...
    out = []
    for a in args:
        if a.startswith("[") and a.endswith("]") and "=" in a and a.index("[") < a.index("="):
            out.append(a[1:-1])  # optional part written as [key=value]
        else:
            out.append(a)
    return out


def _module(cmd: Command) -> str:
    return shlex.split(cmd.text)[2]


def _expand_sweeps(args: list[str]) -> list[list[str]]:
    """One override list per combination of the sweep values (the jobs of ``-m``)."""
    from hydra.core.override_parser.overrides_parser import OverridesParser

    opts = [a for a in args if a.startswith("-")]
    overrides = OverridesParser.create().parse_overrides([a for a in args if not a.startswith("-")])
    choices = []
    for o in overrides:
        if o.is_sweep_override() and o.is_discrete_sweep():
            prefix = o.get_key_element()
            values = list(o.sweep_string_iterator())
            if o.value_type.name == "RANGE_SWEEP":  # range(4,40,step=2): its ends are enough
                values = values[:1] + values[-1:]
            choices.append([f"{prefix}={v}" for v in values])
        elif o.is_sweep_override():  # interval(a,b) of a tuning sweeper: both ends
            prefix, value = o.get_key_element(), o.value()
            choices.append([f"{prefix}={value.start}", f"{prefix}={value.end}"])
        else:
            choices.append([o.input_line])
    return [[*[x for x in opts if x not in ("-m", "--multirun")], *combo] for combo in itertools.product(*choices)]


def _env(cwd: Path, requires: str | None, plugin_site: Path | None) -> dict:
    import os

    env = dict(os.environ, BIONAV_CACHE=str(cwd / "cache"), MPLBACKEND="Agg")
    if requires:
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(plugin_site), env.get("PYTHONPATH", "")]))
    return env


def _run(args: list[str], cwd: Path, env: dict, timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", *args], cwd=cwd, env=env, capture_output=True, text=True,
                          timeout=timeout)


#: composes override lists exactly as ``python -m bionav`` does (name pre-check, then Hydra), in one process
COMPOSE_DRIVER = r"""
import json, sys
from bionav.cli import _precheck
from bionav.config import register_configs
from hydra import compose, initialize
register_configs()
out = []
for args in json.load(sys.stdin):
    try:
        _precheck(args)
        with initialize(version_base="1.3", config_path=None):
            cfg = compose("config", overrides=args)
        out.append(None if cfg.get("experiment") else "no experiment node")
    except Exception as exc:
        out.append(f"{type(exc).__name__}: {exc}")
print(json.dumps(out))
"""


@dataclass(frozen=True)
class Job:
    cmd: Command
    argv: tuple[str, ...]
    compose_only: bool  # composed by the driver, not its own subprocess


def _missing_hydra_plugin(argv) -> str | None:
    """The Hydra plugin (``hydra/sweeper=optuna``, ``hydra/launcher=joblib``) a command needs and lacks."""
    import importlib.util

    for arg in argv:
        key, _, value = arg.partition("=")
        if key in ("hydra/sweeper", "hydra/launcher") and value not in ("basic", ""):
            module = f"hydra_plugins.hydra_{value.split('_')[0]}_{key.split('/')[1]}"
            if importlib.util.find_spec(module) is None:
                return module
    return None


def _jobs() -> list[Job]:
    jobs: list[Job] = []
    seen: set[tuple[str, ...]] = set()
    smoked_files: set[str] = set()

    def add(cmd, argv, compose_only=False):
        if (tuple(argv), compose_only) not in seen:
            seen.add((tuple(argv), compose_only))
            jobs.append(Job(cmd, tuple(argv), compose_only))

    for cmd in documented_commands():
        if _is_syntax_line(cmd.text):
            continue
        module = _module(cmd)
        args = _substitute(cmd)
        if module == "bionav":
            if any(a.startswith("-") and a not in ("-m", "--multirun") for a in args):
                add(cmd, ["bionav", *args])  # --help, --cfg job, -sc install=bash, ...: run as documented
                continue
            for combo in _expand_sweeps(args):
                add(cmd, combo, compose_only=True)
                if cmd.file not in smoked_files:  # one real `--cfg job` subprocess per file
                    smoked_files.add(cmd.file)
                    add(cmd, ["bionav", *combo, "--cfg", "job"])
            continue
        first = args[0] if args and re.fullmatch(r"[a-z_][a-z0-9_-]*", args[0]) else None  # sub-commands: info, export-ros2
        add(cmd, [module, *([first] if first else []), "--help"])
        if module in REAL_RUN_MODULES and args[1 if first else 0:] and "--help" not in args:
            add(cmd, [module, *args])  # a real run (not a mere mention such as `python -m bionav.logs recover`)
    return jobs


@pytest.fixture(scope="module")
def plugin_site(tmp_path_factory):
    """Local packages the docs install before using them (``pip install -e examples/...``)."""
    target = tmp_path_factory.mktemp("site")
    for req in sorted({c.requires for c in documented_commands() if c.requires}):
        if req in docs_packages():  # a package the docs write out file by file (docs/plugins.md, Experiments)
            src = write_docs_package(req, tmp_path_factory.mktemp("src"))
        else:
            src = source_copy(ROOT / req, tmp_path_factory.mktemp("src") / Path(req).name)  # never build in the checkout
        proc = subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "--no-build-isolation", "-q",
                               "--target", str(target), str(src)], capture_output=True, text=True)
        assert proc.returncode == 0, f"pip install {req} (documented before a command) failed:\n{proc.stderr}"
    return target


def test_commands_are_found():
    """The extractor sees the commands of every kind of markup the docs use."""
    cmds = documented_commands()
    texts = {c.text for c in cmds}
    assert len(cmds) >= 40
    assert "python -m bionav experiment=contrast_lda data=sim_natural" in texts  # README table, inline
    assert any(c.text.startswith("python -m bionav -m experiment=param_sweep db=sim_original,sim_hall1,sim_uni "
                                 "hydra/launcher=submitit_slurm") for c in cmds)  # block with continuations
    assert any(c.file == "README.md" and c.text == "python -m bionav" for c in cmds)  # after `pip install . &&`
    assert any(c.file.startswith("docs/") and c.text.startswith("python -m bionav.") for c in cmds)
    assert any(c.requires == "examples/bionav-plugin-example" for c in cmds)
    assert any(c.requires == "bionav-catchment" and "experiment=catchment" in c.text for c in cmds)  # docs package


def test_split_shell():
    assert _split_shell("a && b & # c") == ["a", "b"]
    assert _split_shell("x 'a#b' y  # note") == ["x 'a#b' y"]


def test_sweeps_expand_into_jobs():
    assert _expand_sweeps(["-m", "homing=sift,mfdid", "db=a,b", "seed=1"]) == [
        ["homing=sift", "db=a", "seed=1"], ["homing=sift", "db=b", "seed=1"],
        ["homing=mfdid", "db=a", "seed=1"], ["homing=mfdid", "db=b", "seed=1"]]


@pytest.mark.slow
def test_every_documented_command_composes(sandbox, plugin_site):
    """Every documented command composes (``--cfg job``, or ``--help`` / a tiny real run) without error."""
    all_jobs = _jobs()
    jobs = [j for j in all_jobs if not _missing_hydra_plugin(j.argv)]
    unchecked = sorted({f"{j.cmd.where()} (needs {_missing_hydra_plugin(j.argv)})" for j in all_jobs if j not in jobs})
    failures = []
    # 1. all `python -m bionav` commands (each sweep job) composed by the driver, one process per plugin set
    for requires in sorted({j.cmd.requires or "" for j in jobs if j.compose_only}):
        batch = [j for j in jobs if j.compose_only and (j.cmd.requires or "") == requires]
        proc = subprocess.run([sys.executable, "-c", COMPOSE_DRIVER], input=json.dumps([list(j.argv) for j in batch]),
                              cwd=sandbox, env=_env(sandbox, requires, plugin_site), capture_output=True, text=True,
                              timeout=300)
        assert proc.returncode == 0, proc.stderr
        for job, error in zip(batch, json.loads(proc.stdout.strip().splitlines()[-1])):
            if error:
                failures.append(f"{job.cmd.where()}\n  composing {' '.join(job.argv)}:\n    "
                                + "\n    ".join(error.strip().splitlines()[:12]))

    # 2. real subprocesses: one `--cfg job` per doc file, --help / tiny runs of the other modules
    def check(job):
        proc = _run(list(job.argv), sandbox, _env(sandbox, job.cmd.requires, plugin_site))
        if proc.returncode != 0 or "Traceback" in proc.stderr:
            return (f"{job.cmd.where()}\n  ran: python -m {' '.join(shlex.quote(a) for a in job.argv)}\n"
                    f"  exit {proc.returncode}; stderr:\n    " + "\n    ".join(proc.stderr.strip().splitlines()[-15:]))
        return None

    real = [j for j in jobs if not j.compose_only and j.argv[0] in REAL_RUN_MODULES and "--help" not in j.argv]
    with ThreadPoolExecutor(2) as pool:
        failures += [f for f in pool.map(check, [j for j in jobs if not j.compose_only and j not in real]) if f]
    failures += [f for f in map(check, real) if f]  # in document order: `recover A B` before `info B`
    assert len(jobs) >= 40
    assert not failures, f"{len(failures)} documented commands fail:\n\n" + "\n\n".join(failures)
    if unchecked:  # everything else passed; say what could not be checked here
        pytest.skip("Hydra plugins missing (pip install -e '.[test]'), not checked: " + "; ".join(unchecked))
