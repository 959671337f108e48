"""The bionav runs the thesis items need: specification, deduplication, execution, reuse.

A run is a list of Hydra overrides for ``python -m bionav`` (or a multirun,
``-m``, for experiments that are sweeps themselves). Runs are executed as
subprocesses of the documented command line, so this module depends only on
bionav's public interface: the overrides a user types and the files a run
writes (``metrics.json``, ``.hydra/overrides.yaml``, the experiment's own
files). Identical runs requested by several items are executed once; runs found
completed anywhere under the output directory (``runs/`` or ``sweeps/``) are
reused, so re-running the same command resumes.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import re
import subprocess
import sys
import time
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any, Callable, Iterable, Mapping, Sequence

import yaml

from bionav.machine import usable_cpus

log = logging.getLogger(__name__)

#: override keys that do not change a run's results (ignored when matching runs; the config keys among them
#: are :data:`bionav.runrecord.NEUTRAL_KEYS`)
NEUTRAL_KEYS = ("hydra", "hydra/launcher", "bionav.resume", "workers")
#: file marking a finished multirun (all jobs completed)
SWEEP_DONE = ".thesis_sweep_done"


@dataclass(frozen=True)
class RunSpec:
    """One invocation of ``python -m bionav``.

    Attributes
    ----------
    overrides : tuple of str
        Hydra overrides, e.g. ``("homing=sift", "db=sim_hall1")``.
    multirun : bool
        Run with ``-m`` (the experiment is a sweep, e.g. ``param_sweep``).
    group : str
        Sub-folder of ``OUT/runs`` the run directory goes to (readability only).
    """

    overrides: tuple[str, ...]
    multirun: bool = False
    group: str = "misc"
    blocks: int = 1

    def tasks(self) -> list["RunSpec"]:
        """The independent tasks of this run: ``blocks`` runs by snapshots, or the run itself.

        A grid-homing or cross-database run with ``blocks = n > 1`` splits into
        ``experiment.block=[i,n]`` runs (:mod:`bionav.experiments.tasks`) that
        :meth:`Runner.run_all` executes like any run (each reused on its own when completed)
        and then merges into this run's directory (``python -m bionav.experiments.merge``),
        with identical measures.
        """
        if self.blocks <= 1 or self.multirun:
            return [self]
        return [RunSpec((*self.overrides, f"experiment.block=[{i},{self.blocks}]"), group=f"{self.group}-tasks")
                for i in range(self.blocks)]

    @property
    def key(self) -> str:
        """Canonical identity: equal for runs that compute the same thing."""
        return canonical_key(self.overrides, multirun=self.multirun)

    @property
    def slug(self) -> str:
        """Readable, unique directory name."""
        words = []
        for o in self.overrides:
            k, _, v = o.partition("=")
            if k.split(".")[-1] in ("snapshots",) or len(v) > 24:
                continue
            words.append(re.sub(r"[^A-Za-z0-9.]+", "", v) or k)
        stem = "_".join(w for w in words if w)[:60] or "run"
        return f"{stem}-{hashlib.sha1(self.key.encode()).hexdigest()[:8]}"

    def command(self, run_dir: Path, *, launcher: Sequence[str] = ()) -> list[str]:
        """The command line that executes this run into ``run_dir``."""
        cmd = [sys.executable, "-m", "bionav"]
        if self.multirun:
            cmd += ["-m", *self.overrides, f"hydra.sweep.dir={run_dir}", "bionav.resume=true", *launcher]
        else:
            cmd += [*self.overrides, f"hydra.run.dir={run_dir}"]
        return cmd


def _plain(value: Any) -> Any:
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, float) and value.is_integer():
        return value  # keep 1.0 distinct from 1 only by type, as Hydra does
    return value


@lru_cache(maxsize=1)
def _parser():
    from hydra.core.override_parser.overrides_parser import OverridesParser

    return OverridesParser.create()


@lru_cache(maxsize=4096)
def _canonical_override(text: str) -> tuple[str, str] | None:
    """``(key, canonical value)`` of one override, None for neutral keys."""
    text = text.strip()
    try:
        (ov,) = _parser().parse_overrides([text])
    except Exception:
        key, _, value = text.lstrip("+~").partition("=")
        return (key, re.sub(r"\s+", "", value))
    key = ov.key_or_group
    if key.startswith("hydra.") or key in NEUTRAL_KEYS:
        return None
    if ov.is_sweep_override():
        return (key, re.sub(r"\s+", "", text.partition("=")[2]))
    return (key, json.dumps(_plain(ov.value()), sort_keys=True))


def canonical_key(overrides: Iterable[str], *, multirun: bool = False) -> str:
    """Order- and spelling-independent identity of a list of overrides."""
    pairs = sorted(p for p in (_canonical_override(o) for o in overrides) if p is not None)
    return json.dumps({"m": bool(multirun), "o": pairs})


@dataclass
class RunResult:
    """A run's directory and its metrics (None when it did not complete)."""

    spec: RunSpec
    dir: Path | None
    metrics: dict | None = None
    error: str | None = None
    seconds: float | None = None
    reused: bool = False
    cpu_seconds: float | None = None

    @property
    def ok(self) -> bool:
        return self.metrics is not None and self.metrics.get("status") == "completed"


def read_json(path: Path) -> dict | None:
    """The JSON object in ``path``; ``None`` if missing, not a regular file, unreadable or not an object."""
    from bionav.files import not_a_regular_file

    if not_a_regular_file(path) is not None:
        return None
    try:
        data = json.loads(Path(path).read_text())
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


def index_runs(root: Path) -> dict[str, Path]:
    """Completed single runs (and finished sweeps) under ``root``, by canonical key.

    Single runs are found through ``.hydra/overrides.yaml`` next to a
    ``metrics.json`` saying completed (run directories of ``python -m bionav``
    and job directories of multiruns alike); sweeps through the marker file
    this module writes when every job of a multirun completed.
    """
    found: dict[str, Path] = {}
    root = Path(root)
    if not root.is_dir():
        return found
    for ov_file in root.rglob(".hydra/overrides.yaml"):
        run_dir = ov_file.parent.parent
        metrics = read_json(run_dir / "metrics.json")
        if not metrics or metrics.get("status") != "completed":
            continue
        try:
            overrides = yaml.safe_load(ov_file.read_text()) or []
        except (OSError, ValueError, yaml.YAMLError):
            continue
        if not isinstance(overrides, list):  # not written by Hydra: not a run of ours
            continue
        if not recorded_as_composed(run_dir, tuple(str(o) for o in overrides)):
            continue  # its record is not what these overrides give (changed defaults, a rewritten record)
        found.setdefault(canonical_key([str(o) for o in overrides]), run_dir)
    for marker in root.rglob(SWEEP_DONE):
        info = read_json(marker)
        if info and "key" in info:
            found.setdefault(str(info["key"]), marker.parent)
    return found


@lru_cache(maxsize=4096)
def _composed(overrides: tuple[str, ...]) -> dict | None:
    """The configuration ``python -m bionav <overrides>`` composes today (None: it does not compose)."""
    from bionav.config import compose, register_configs
    from bionav.runrecord import plain_config

    register_configs()
    try:
        return plain_config(compose([o for o in overrides if not o.startswith("hydra")]))
    except Exception:  # an override of an older bionav: nothing to reuse
        return None


def recorded_as_composed(run_dir: Path, overrides: tuple[str, ...]) -> bool:
    """True when ``run_dir`` recorded the configuration its overrides compose to today.

    The reuse of completed runs applies the comparison of ``bionav.resume=true``
    (:func:`bionav.runrecord.config_differences`, neutral keys ignored), so a run is
    reused only for the configuration it was made with.
    """
    from bionav.errors import UserError
    from bionav.runrecord import config_differences, recorded_config

    try:
        recorded = recorded_config(run_dir)
    except UserError:
        return False
    composed = _composed(overrides)
    return recorded is not None and composed is not None and not config_differences(composed, recorded)


def sweep_jobs(sweep_dir: Path) -> list[tuple[Path, dict | None]]:
    """Job directories of a multirun with their metrics."""
    jobs = []
    for ov_file in sorted(Path(sweep_dir).glob("*/.hydra/overrides.yaml")):
        run_dir = ov_file.parent.parent
        jobs.append((run_dir, read_json(run_dir / "metrics.json")))
    return jobs


def _sweep_metrics(sweep_dir: Path) -> dict:
    """A multirun is complete when Hydra finished it (``summary.csv`` written) and every job completed."""
    jobs = sweep_jobs(sweep_dir)
    done = sum(1 for _, m in jobs if m and m.get("status") == "completed")
    finished = (Path(sweep_dir) / "summary.csv").is_file()
    ok = finished and jobs and done == len(jobs)
    out = {"status": "completed" if ok else "failed", "n_jobs": len(jobs), "n_completed": done}
    if not ok:
        out["error"] = (f"{done} of {len(jobs)} jobs completed" if finished else
                        f"the multirun did not finish ({done} jobs completed; see its log)")
    return out


def _move_aside(path: Path) -> None:
    """Keep an unfinished run directory (nothing recorded is lost) and free its name."""
    if path.exists():
        n = 1
        while path.with_name(f"{path.name}.unfinished-{n}").exists():
            n += 1
        path.rename(path.with_name(f"{path.name}.unfinished-{n}"))


def execute_local(spec: RunSpec, out: Path, *, env: Mapping[str, str] | None = None,
                  launcher: Sequence[str] = (), extra: Sequence[str] = ()) -> RunResult:
    """Run one spec as a subprocess of ``python -m bionav`` into ``OUT/runs/<group>/<slug>``.

    ``extra`` overrides are appended to the command without changing the run's identity
    (only :data:`NEUTRAL_KEYS`, e.g. ``workers=1`` when several runs share the cores).
    The CPU time is the child's own (``os.wait4``), so it is exact also when runs overlap.
    """
    run_dir = Path(out) / "runs" / spec.group / spec.slug
    if not spec.multirun:
        _move_aside(run_dir)
    run_dir.parent.mkdir(parents=True, exist_ok=True)
    log_path = run_dir.parent / f"{spec.slug}.log"
    started = time.time()
    with open(log_path, "w") as fh:
        proc = subprocess.Popen([*spec.command(run_dir, launcher=launcher), *extra], stdout=fh,
                                stderr=subprocess.STDOUT, env=dict(env) if env is not None else None)
        returncode, cpu = _wait_with_cpu(proc)
    seconds = time.time() - started
    if spec.multirun:
        metrics = _sweep_metrics(run_dir)
        if metrics["status"] == "completed":
            (run_dir / SWEEP_DONE).write_text(json.dumps({"key": spec.key, "overrides": list(spec.overrides)}))
    else:
        metrics = read_json(run_dir / "metrics.json")
    error = None
    if returncode != 0 or not metrics or metrics.get("status") != "completed":
        error = _last_error(log_path, metrics)
    return RunResult(spec, run_dir, metrics, error, seconds, cpu_seconds=cpu)


def _wait_with_cpu(proc: subprocess.Popen) -> tuple[int, float]:
    """Wait for ``proc``; its exit status and the user + system CPU seconds of it and its children."""
    try:
        _pid, status, usage = os.wait4(proc.pid, 0)
    except ChildProcessError:  # reaped elsewhere: no usage known
        return proc.wait(), 0.0
    except BaseException:  # Ctrl-C: the child got it too; reap it
        proc.wait()
        raise
    proc.returncode = os.waitstatus_to_exitcode(status)
    return proc.returncode, usage.ru_utime + usage.ru_stime


def _last_error(log_path: Path, metrics: dict | None) -> str:
    if metrics and metrics.get("error"):
        return str(metrics["error"])
    try:
        lines = [ln for ln in log_path.read_text(errors="replace").splitlines() if ln.strip()]
    except OSError:
        return "no log"
    errs = [ln for ln in lines if "error" in ln.lower()]
    return (errs or lines or ["the run wrote no metrics.json"])[-1][:400]


# ---------------------------------------------------------------------------
# running many specs: locally one by one, or as multiruns through a launcher
# ---------------------------------------------------------------------------
def product_blocks(specs: Sequence[RunSpec]) -> list[tuple[list[str], list[RunSpec]]]:
    """Group single runs into Cartesian-product sweeps ``key=v1,v2 ...``.

    Returns ``(sweep overrides, specs covered)`` pairs: every spec is covered by
    exactly one block and every job of a block is one of the specs, so each
    block is one ``python -m bionav -m ...`` invocation.
    """
    groups: dict[tuple[str, ...], list[dict[str, str]]] = {}
    by_items: dict[tuple, RunSpec] = {}
    for s in specs:
        d = dict(o.partition("=")[::2] for o in s.overrides)
        groups.setdefault(tuple(sorted(d)), []).append(d)
        by_items[tuple(sorted(d.items()))] = s

    def split(rows: list[dict[str, str]]) -> list[list[dict[str, str]]]:
        uniq = {tuple(sorted(r.items())): r for r in rows}
        rows = list(uniq.values())
        keys = sorted(rows[0])
        values = {k: sorted({r[k] for r in rows}) for k in keys}
        size = 1
        for k in keys:
            size *= len(values[k])
        if size == len(rows):
            return [rows]
        k = min((k for k in keys if len(values[k]) > 1), key=lambda k: len(values[k]))
        out = []
        for v in values[k]:
            out += split([r for r in rows if r[k] == v])
        return out

    blocks = []
    for rows in groups.values():
        for block in split(rows):
            keys = sorted(block[0])
            sweep = []
            for k in keys:
                vals = sorted({r[k] for r in block})
                sweep.append(f"{k}={','.join(vals)}" if len(vals) > 1 else f"{k}={vals[0]}")
            blocks.append((sweep, [by_items[tuple(sorted(r.items()))] for r in block]))
    return blocks


@dataclass
class Runner:
    """Executes the specs items need, once each, reusing completed runs under ``out``.

    Parameters
    ----------
    out : Path
        The report directory; runs go to ``out/runs`` (local) or ``out/sweeps`` (launcher).
    launcher : list of str
        Extra overrides selecting a Hydra launcher (``hydra/launcher=joblib`` ...);
        empty: run locally one after the other.
    dry_run : bool
        Only print the commands.
    jobs : int
        Without a launcher: runs executed at once (1: one after the other). Runs of one
        database wait until its first run has rendered it (the render cache), and each run
        gets ``workers = max(1, cores // jobs)``, so the cores are shared, not oversubscribed.
        With a launcher: multiruns in flight at once (each one a job array on SLURM).
    cost : callable, optional
        ``cost(spec) -> float``: the CPU seconds a spec is expected to need (the plan's estimate,
        ``lambda s: bionav.thesis.plan.task_cpu_s(s).cpu_s``); the longest expected task goes first.
        None: the specs in the order given.
    """

    out: Path
    launcher: list[str] = field(default_factory=list)
    dry_run: bool = False
    echo: Callable[[str], None] = print
    env: dict | None = None
    jobs: int = 1
    cost: Callable[[RunSpec], float] | None = None

    def _expected_cpu_s(self, spec: RunSpec) -> float:
        return 0.0 if self.cost is None else float(self.cost(spec))

    def run_all(self, specs: Sequence[RunSpec]) -> dict[str, RunResult]:
        """Execute every spec not yet completed under :attr:`out`; split runs go as their tasks."""
        unique: dict[str, RunSpec] = {}
        for s in specs:
            unique.setdefault(s.key, s)
        index = index_runs(self.out)
        split = {k: s for k, s in unique.items() if len(s.tasks()) > 1 and k not in index}
        flat = {k: s for k, s in unique.items() if k not in split}
        for s in split.values():
            for t in s.tasks():
                flat.setdefault(t.key, t)
        results = self._run_unique(flat)
        for key, spec in split.items():
            results[key] = self._merge(spec, [results[t.key] for t in spec.tasks()])
        return {k: results[k] for k in unique}

    def _merge(self, spec: RunSpec, parts: list[RunResult]) -> RunResult:
        """Join a split run's task results into its own run directory."""
        run_dir = self.out / "runs" / spec.group / spec.slug
        failed = [p for p in parts if not p.ok]
        cpu = sum(p.cpu_seconds or 0.0 for p in parts)
        seconds = sum(p.seconds or 0.0 for p in parts)
        if self.dry_run:
            return RunResult(spec, None, None, "dry run")
        if failed:
            return RunResult(spec, None, None, f"{len(failed)} of {len(parts)} tasks failed: {failed[0].error}",
                             seconds, cpu_seconds=cpu)
        _move_aside(run_dir)
        run_dir.parent.mkdir(parents=True, exist_ok=True)
        cmd = [sys.executable, "-m", "bionav.experiments.merge", str(run_dir), *(str(p.dir) for p in parts)]
        proc = subprocess.run(cmd, capture_output=True, text=True, errors="replace", env=self.env)
        metrics = read_json(run_dir / "metrics.json")
        if proc.returncode != 0 or not metrics or metrics.get("status") != "completed":
            return RunResult(spec, None, None, f"merging its {len(parts)} tasks failed: "
                             f"{(proc.stderr.strip().splitlines() or ['no message'])[-1]}", seconds, cpu_seconds=cpu)
        self.echo(f"    merged {len(parts)} tasks into {run_dir}")
        return RunResult(spec, run_dir, metrics, None, seconds, cpu_seconds=cpu)

    def _run_unique(self, unique: Mapping[str, RunSpec]) -> dict[str, RunResult]:
        index = index_runs(self.out)
        results: dict[str, RunResult] = {}
        todo = []
        for key, spec in unique.items():
            if key in index:
                d = index[key]
                metrics = _sweep_metrics(d) if spec.multirun else read_json(d / "metrics.json")
                results[key] = RunResult(spec, d, metrics, reused=True)
            else:
                todo.append(spec)
        self.echo(f"bionav.thesis: {len(unique)} runs needed, {len(unique) - len(todo)} found completed in {self.out}, "
                  f"{len(todo)} to run" + (f" through {' '.join(self.launcher)}" if self.launcher else ""))
        if self.launcher:
            results.update(self._run_launcher(todo))
        else:
            results.update(self._run_local(todo))
        return results

    def _run_local(self, todo: Sequence[RunSpec]) -> dict[str, RunResult]:
        if self.jobs > 1 and not self.dry_run and len(todo) > 1:
            return self._run_pool(todo)
        results = {}
        for i, spec in enumerate(todo, 1):
            run_dir = self.out / "runs" / spec.group / spec.slug
            cmd = " ".join(_quote(c) for c in spec.command(run_dir)[1:])
            if self.dry_run:
                self.echo(f"python {cmd}")
                results[spec.key] = RunResult(spec, None, None, "dry run")
                continue
            done = index_runs(self.out / "runs" / spec.group).get(spec.key)  # finished meanwhile by another invocation
            if done is not None:
                metrics = _sweep_metrics(done) if spec.multirun else read_json(done / "metrics.json")
                results[spec.key] = RunResult(spec, done, metrics, reused=True)
                self.echo(f"[{i}/{len(todo)}] completed meanwhile: {done}")
                continue
            self.echo(f"[{i}/{len(todo)}] python {cmd}")
            res = execute_local(spec, self.out, env=self.env)
            self.echo(f"    {'done' if res.ok else 'FAILED: ' + str(res.error)} in {res.seconds:.0f} s "
                      f"(CPU {res.cpu_seconds:.0f} s)")
            results[spec.key] = res
        return results

    def _run_pool(self, todo: Sequence[RunSpec]) -> dict[str, RunResult]:
        """Run ``todo`` on :attr:`jobs` slots; a database's first run goes before its other runs.

        Longest expected task first (:attr:`cost`, the plan's CPU estimate): the largest tasks then
        overlap the many small ones instead of running alone at the end.
        """
        from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait

        cores = usable_cpus()
        extra = [f"workers={max(1, cores // self.jobs)}"]
        waiting = sorted(todo, key=lambda sp: -self._expected_cpu_s(sp))  # stable: equal estimates keep their order
        rendering: set[tuple[str, ...]] = set()  # databases whose first run is running
        rendered: set[tuple[str, ...]] = set()  # databases with a finished run (cached renders)
        results: dict[str, RunResult] = {}
        active: dict = {}
        started = 0
        with ThreadPoolExecutor(max_workers=self.jobs) as pool:
            while waiting or active:
                while len(active) < self.jobs:
                    pick = next((sp for sp in waiting if render_key(sp) in rendered
                                 or render_key(sp) not in rendering), None)
                    if pick is None:
                        break
                    waiting.remove(pick)
                    if render_key(pick) not in rendered:
                        rendering.add(render_key(pick))
                    started += 1
                    run_dir = self.out / "runs" / pick.group / pick.slug
                    shown = " ".join(_quote(c) for c in pick.command(run_dir)[1:])
                    self.echo(f"[{started}/{len(todo)}] python {shown}")
                    active[pool.submit(execute_local, pick, self.out, env=self.env, extra=extra)] = pick
                done, _ = wait(list(active), return_when=FIRST_COMPLETED)
                for future in done:
                    spec = active.pop(future)
                    res = future.result()
                    rendering.discard(render_key(spec))
                    rendered.add(render_key(spec))
                    self.echo(f"    {spec.slug}: {'done' if res.ok else 'FAILED: ' + str(res.error)} in "
                              f"{res.seconds:.0f} s (CPU {res.cpu_seconds:.0f} s)")
                    results[spec.key] = res
        return results

    def _run_launcher(self, todo: Sequence[RunSpec]) -> dict[str, RunResult]:
        results = {}
        singles = [s for s in todo if not s.multirun]
        commands = []
        for sweep, covered in product_blocks(singles):
            digest = hashlib.sha1("\n".join(sweep).encode()).hexdigest()[:10]
            sweep_dir = self.out / "sweeps" / f"{covered[0].group}-{digest}"
            cmd = [sys.executable, "-m", "bionav", "-m", *sweep, f"hydra.sweep.dir={sweep_dir}",
                   "bionav.resume=true", *self.launcher]
            commands.append((cmd, covered, sweep_dir))
        for spec in todo:
            if spec.multirun:
                run_dir = self.out / "runs" / spec.group / spec.slug
                commands.append((spec.command(run_dir, launcher=self.launcher), [spec], run_dir))
        # the multirun holding the longest expected task first (queued first on SLURM), as the pool does
        commands.sort(key=lambda c: -max(self._expected_cpu_s(s) for s in c[1]))

        def launch(i: int, cmd: list[str], covered: list[RunSpec], sweep_dir: Path) -> None:
            self.echo(f"[{i}/{len(commands)}] python " + " ".join(_quote(c) for c in cmd[1:]))
            sweep_dir.parent.mkdir(parents=True, exist_ok=True)
            with open(sweep_dir.parent / f"{sweep_dir.name}.log", "w") as fh:
                subprocess.run(cmd, stdout=fh, stderr=subprocess.STDOUT, env=self.env)
            if len(covered) == 1 and covered[0].multirun:
                metrics = _sweep_metrics(sweep_dir)
                if metrics["status"] == "completed":
                    (sweep_dir / SWEEP_DONE).write_text(json.dumps({"key": covered[0].key}))

        if self.dry_run:
            for cmd, _covered, _dir in commands:
                self.echo("python " + " ".join(_quote(c) for c in cmd[1:]))
        else:  # up to `jobs` multiruns in flight (SLURM: every job array queued at once)
            from concurrent.futures import ThreadPoolExecutor

            with ThreadPoolExecutor(max_workers=max(1, min(self.jobs, len(commands) or 1))) as pool:
                for future in [pool.submit(launch, i, *c) for i, c in enumerate(commands, 1)]:
                    future.result()
        index = index_runs(self.out)
        for spec in todo:
            d = index.get(spec.key)
            if d is None:
                results[spec.key] = RunResult(spec, None, None, "dry run" if self.dry_run else
                                              "the launcher's job did not complete (see the sweep's log and metrics.json)")
            else:
                metrics = _sweep_metrics(d) if spec.multirun else read_json(d / "metrics.json")
                results[spec.key] = RunResult(spec, d, metrics)
        return results


def render_key(spec: RunSpec) -> tuple[str, ...]:
    """What a run renders: its database overrides (``db=...``, ``db.*=...``, ``data=...``).

    Runs with equal keys share the cached renders of their databases, so the pool lets the
    first of them render before the others start.
    """
    return tuple(sorted(o for o in spec.overrides if o.split("=", 1)[0].split(".", 1)[0] in ("db", "data")))


def _quote(arg: str) -> str:
    return f"'{arg}'" if re.search(r"[\s{}\[\]\"*?]", arg) else arg


def tool_env() -> dict[str, str]:
    """Environment for subprocesses (one BLAS thread, as ``python -m bionav`` itself sets)."""
    env = dict(os.environ)
    env.setdefault("OPENBLAS_NUM_THREADS", "1")
    env.setdefault("MKL_NUM_THREADS", "1")
    return env

