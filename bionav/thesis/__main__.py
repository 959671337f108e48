"""``python -m bionav.thesis [--preset quick|full] [--only ITEMS] --out DIR``.

Runs every bionav experiment the thesis' tables and figures need (through
``python -m bionav``, reusing completed runs in DIR and the per-image cache)
and writes ``report.md``, ``report.html``, ``items.csv`` and one figure/table
per item into DIR. ``--launcher joblib`` (or ``submitit_slurm``,
``submitit_local``, any Hydra launcher) runs the needed runs as multiruns
through that launcher; ``--dry-run`` prints the commands only.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

from bionav.errors import UserError


def build_parser() -> argparse.ArgumentParser:
    from bionav.thesis.items import REGISTRY
    from bionav.thesis.presets import PUBLIC_PRESETS

    p = argparse.ArgumentParser(
        prog="python -m bionav.thesis",
        description="Reproduce the thesis' tables and figures with bionav and report them side by side "
                    "(report.md, report.html, items.csv and one figure per item in --out).",
        epilog="items: " + ", ".join(REGISTRY) + ". Thesis numbers work too (--only 5.3,B.1,6.26).",
    )
    p.add_argument("--preset", default="quick", help=f"how much to run: {' | '.join(PUBLIC_PRESETS)} (default quick)")
    p.add_argument("--only", default=None, metavar="ITEMS", help="comma-separated items (ids or thesis numbers)")
    p.add_argument("--out", default=None, metavar="DIR",
                   help="report directory; runs go to DIR/runs (reused when re-run); needed unless --plan")
    p.add_argument("--launcher", default=None, metavar="NAME",
                   help="run through a Hydra launcher (joblib, submitit_slurm, submitit_local, ...) as multiruns")
    p.add_argument("--launcher-arg", action="append", default=[], metavar="KEY=VALUE",
                   help="extra launcher override, e.g. hydra.launcher.partition=cpu (repeatable)")
    p.add_argument("--jobs", type=int, default=None, metavar="N",
                   help="runs at once (default: the usable CPUs; 1: one after the other); with --launcher, "
                        "multiruns in flight (default 1; submitit_slurm: all job arrays at once)")
    p.add_argument("--dry-run", action="store_true", help="print the bionav commands and write nothing")
    p.add_argument("--report-only", action="store_true", help="run nothing; report from the runs already in DIR")
    plan = p.add_argument_group("plan (run nothing)")
    plan.add_argument("--plan", action="store_true",
                      help="print the tasks, the CPU each needs, the critical path and the expected wall time")
    plan.add_argument("--nodes", type=int, default=1, help="machines of the plan (default 1)")
    plan.add_argument("--cores", type=int, default=None, help="cores per machine (default: this machine's)")
    plan.add_argument("--json", action="store_true", help="with --plan or --calibrate: one JSON object")
    plan.add_argument("--cpu-factor", type=float, default=None, metavar="F",
                      help="plan for a machine F times slower (F > 1) or faster (F < 1) than the reference machine "
                           "the figures come from, instead of calibrating this one")
    plan.add_argument("--calibration", default=None, metavar="FILE",
                      help="plan for the machine whose calibration FILE holds (written there with --calibrate --json)")
    plan.add_argument("--calibrate", action="store_true",
                      help="time the calibration workloads on this machine (about 2 s of CPU), cache and print them")
    return p


def _launcher_overrides(name: str | None, extra: list[str]) -> list[str]:
    if not name:
        if extra:
            raise UserError("--launcher-arg needs --launcher NAME (e.g. --launcher joblib).")
        return []
    from bionav.config import hydra_group_options

    available = hydra_group_options("hydra/launcher")
    if name not in available:
        raise UserError(f"unknown --launcher {name!r}; installed Hydra launchers: {', '.join(available)} "
                        "(joblib comes with `pip install \"bionav[parallel]\"`, submitit_* with "
                        "`pip install \"bionav[slurm]\"`).")
    for e in extra:
        if "=" not in e:
            raise UserError(f"--launcher-arg {e!r} must be KEY=VALUE, e.g. hydra.launcher.n_jobs=2.")
    return [f"hydra/launcher={name}", *extra]


def main(argv: list[str] | None = None) -> int:
    from bionav.cli_main import end_on_termination_signals

    args = build_parser().parse_args(argv)
    end_on_termination_signals()  # `kill` and a closed terminal end the command as Ctrl-C does
    try:
        return run(args)
    except UserError as exc:
        print(f"bionav.thesis: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:  # full disk, permissions while writing the report
        print(f"bionav.thesis: error: cannot write {getattr(exc, 'filename', None) or args.out}: "
              f"{exc.strerror or exc}. Free space or choose another --out; completed runs are kept and reused.",
              file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"bionav.thesis: interrupted; completed runs are kept in {args.out}/runs and are reused when you run "
              f"the same command again.", file=sys.stderr)
        return 130


def run(args) -> int:
    from bionav.files import user_path
    from bionav.thesis.items import select_items
    from bionav.thesis.presets import PRESETS, PUBLIC_PRESETS

    started = time.time()
    load_start = _loadavg()
    if args.preset not in PRESETS:
        raise UserError(f"unknown --preset {args.preset!r}; choose one of {', '.join(PUBLIC_PRESETS)}.")
    preset = PRESETS[args.preset]
    if args.jobs is not None and not 1 <= args.jobs <= 4096:
        from bionav.machine import usable_cpus

        raise UserError(f"--jobs {args.jobs} is out of range; give 1 (one run after the other) up to the number "
                        f"of runs to execute at once, e.g. --jobs {usable_cpus()}.")
    if args.calibrate:
        return _calibrate(args)
    items = select_items(args.only)
    if args.plan:
        return _plan(args, items, preset)
    if args.cpu_factor is not None or args.calibration is not None:
        raise UserError("--cpu-factor and --calibration belong to --plan (e.g. --plan --cpu-factor 2).")
    if args.out is None:
        raise UserError("--out DIR is needed: the report directory (runs go to DIR/runs), e.g. --out thesis_report.")
    out = user_path(args.out).resolve()
    if out.exists() and not out.is_dir():
        raise UserError(f"--out {out} is a file; give a directory.")
    if not args.dry_run:
        try:
            out.mkdir(parents=True, exist_ok=True)
            with tempfile.TemporaryFile(dir=out):
                pass
        except OSError as exc:
            raise UserError(f"cannot write the report directory {out}: {exc.strerror}. Choose another with --out.") from None
        from bionav.runlock import RunLock

        # one writer per report directory (the runs below it hold their own locks); a stale lock is taken over
        with RunLock(out, what="report directory (--out)",
                     fix="Wait for that command to finish, or give this one another --out."):
            return _run_in(args, out, items, preset, started, load_start)
    return _run_in(args, out, items, preset, started, load_start)


#: the files of the report itself (the items add their figures and tables, named after the item)
REPORT_FILES = ("report.md", "report.html", "items.csv")
#: where the items' files are made before they are moved into --out (bionav's own files only)
STAGING = ".bionav-staging"


def _run_in(args, out: Path, items, preset, started: float, load_start: str) -> int:
    from bionav.files import OwnedFolder

    owned = OwnedFolder(out)
    if not args.dry_run:  # the user's files in --out are never overwritten: refused before any run
        owned.check([*REPORT_FILES, *(p.name for p in out.iterdir() if any(p.name.startswith(it.id) for it in items))])
        from bionav.runlock import settle_stale_runs

        for sub in ("runs", "sweeps"):  # runs whose process was killed (with this command, alone) say "interrupted"
            settle_stale_runs(out / sub)
    specs = {it.id: it.runs(preset) for it in items}
    results = _results(args, out, specs)
    if args.dry_run:
        return 0
    import shutil

    staging = out / STAGING
    shutil.rmtree(staging, ignore_errors=True)
    staging.mkdir()
    sections = _sections(items, specs, results, staging, preset)
    wall = time.time() - started
    _write_report(args, sections, results, staging, out, preset, wall, load_start)
    _publish(staging, out, owned)
    from bionav.thesis.report import verdict_counts

    counts = verdict_counts(sections)
    print(f"bionav.thesis: {len(sections)} items in {wall:.0f} s: " +
          ", ".join(f"{v} {counts.get(v, 0)}" for v in ("holds", "partly", "does not hold", "not produced")))
    print(f"report: {out / 'report.md'} ({out / 'report.html'}, {out / 'items.csv'})")
    return 0


def _results(args, out: Path, specs: dict) -> dict:
    """Run (or, with --report-only, find) every run the items need; their results by key."""
    from bionav.machine import usable_cpus
    from bionav.thesis.runs import Runner, RunResult, index_runs, read_json, tool_env

    launcher = _launcher_overrides(args.launcher, args.launcher_arg)
    if args.jobs is not None:
        jobs = args.jobs
    elif launcher:  # multiruns in flight: every SLURM job array queued at once; one local launcher at a time
        jobs = 4096 if "slurm" in (args.launcher or "") else 1
    else:
        jobs = usable_cpus()
    all_specs = [s for ss in specs.values() for s in ss]
    if not args.report_only:
        from bionav.thesis.plan import task_cpu_s

        runner = Runner(out=out, launcher=launcher, dry_run=args.dry_run, echo=lambda s: print(s, flush=True),
                        env=tool_env(), jobs=jobs, cost=lambda spec: task_cpu_s(spec).cpu_s)
        return runner.run_all(all_specs)
    index = index_runs(out)
    results = {}
    for s in all_specs:
        d = index.get(s.key)
        results[s.key] = RunResult(s, d, None if d is None else read_json(d / "metrics.json") if not s.multirun
                                   else {"status": "completed"}, None if d else "not run (--report-only)", reused=True)
    return results


def _sections(items, specs: dict, results: dict, staging: Path, preset) -> list:
    """Evaluate every item (its figures and tables go to ``staging``); one report section per item."""
    from bionav.thesis.diagnoses import load_diagnoses
    from bionav.thesis.items import Context
    from bionav.thesis.outcome import Outcome
    from bionav.thesis.reference import load_reference
    from bionav.thesis.report import Section

    ref_all = load_reference()
    sections = []
    diagnoses = load_diagnoses()
    for it in items:
        ref = ref_all.get(it.id, {})
        ctx = Context(preset=preset, out=staging, ref=ref, results=results, ref_id=it.id)
        try:
            outcome = it.evaluate(ctx, specs[it.id])
        except Exception as exc:  # a report section must never take the whole report down
            outcome = Outcome(missing=[f"evaluating this item failed: {type(exc).__name__}: {exc}"])
        item_runs = [results[s.key] for s in specs[it.id]]
        if item_runs and not any(r.ok for r in item_runs):
            for name in (*outcome.figures, *outcome.tables):  # empty figures and all-n/a tables are not left behind
                (staging / name).unlink(missing_ok=True)
            outcome = outcome.without_runs(len({r.spec.key for r in item_runs}))
        claims = list(ref.get("claims", []))
        if it.id.startswith("tableB"):
            claims += list(ref_all.get("appendix_b_claims", []))
        sections.append(Section(it.id, it.label, ref.get("title", it.label), ref.get("source", ""), it.rule,
                                outcome, [results[s.key] for s in {s.key: s for s in specs[it.id]}.values()], claims,
                                diagnoses.get(it.id)))
    return sections


def _write_report(args, sections, results, staging: Path, out: Path, preset, wall: float, load_start: str) -> None:
    """report.md, report.html and items.csv into ``staging`` (run paths relative to ``out``)."""
    from bionav.thesis.report import markdown_to_html, report_markdown, write_csv

    command = "python -m bionav.thesis " + " ".join(argv_for_display(args))
    cpu = sum(r.cpu_seconds or 0.0 for r in results.values())
    machine = f"{os.cpu_count()} CPUs, 1-minute load average {load_start} at the start and {_loadavg()} at the end"
    md = report_markdown(sections, preset=preset, out=out, wall_s=wall, command=command, cpu_s=cpu or None,
                         machine=machine)
    (staging / "report.md").write_text(md)
    (staging / "report.html").write_text(markdown_to_html(md, staging))
    write_csv(staging / "items.csv", sections)


def _publish(staging: Path, out: Path, owned) -> None:
    """Move the staged files into ``out``; a file there that bionav did not write is kept (and named)."""
    import shutil

    names = sorted(p.name for p in staging.iterdir())
    kept = owned.foreign(names)
    for name in names:
        if name not in kept:
            os.replace(staging / name, out / name)
            owned.claim(name)
    owned.save()
    if kept:
        owned.check(kept)  # one message naming them; the new files stay in STAGING
    shutil.rmtree(staging, ignore_errors=True)


def _plan(args, items, preset) -> int:
    """``--plan``: the preset's tasks, their CPU, the critical path and the wall time; runs nothing."""
    import json

    from bionav.machine import usable_cpus
    from bionav.thesis.plan import format_plan, plan_for

    specs = [s for it in items for s in it.runs(preset)]
    plan = plan_for(specs, nodes=args.nodes, cores=args.cores or usable_cpus(), factors=_factors(args))
    if args.json:
        print(json.dumps({"preset": preset.name, **plan}))
    else:
        print(format_plan(plan, preset=preset.name))
    return 0


def _factors(args) -> dict:
    """The plan's CPU factors: ``--cpu-factor``, ``--calibration FILE`` or this machine's (cached) calibration."""
    from bionav.thesis.calibration import factors, load_calibration

    if args.cpu_factor is not None and args.calibration is not None:
        raise UserError("give --cpu-factor or --calibration, not both.")
    if args.cpu_factor is not None:
        if not 0.01 <= args.cpu_factor <= 100.0:
            raise UserError(f"--cpu-factor {args.cpu_factor:g} is out of range; give how many times slower the "
                            "planned machine is than the reference machine, 0.01..100, e.g. --cpu-factor 1.5.")
        return factors(cpu_factor=args.cpu_factor)
    if args.calibration is not None:
        return factors(load_calibration(args.calibration))
    return factors()


def _calibrate(args) -> int:
    """``--calibrate``: time the workloads anew, cache and print them (and the factors)."""
    import json

    from bionav.thesis.calibration import cache_path, factors, machine_calibration

    cal = machine_calibration(refresh=True)
    if args.json:
        print(json.dumps(cal))
        return 0
    f = factors(cal)
    print(f"calibration of {cal['machine']} (numba target {cal['cpu']}), CPU ms (cached in {cache_path()}):")
    for fam in ("minwarping", "warping2d", "sift", "python"):
        print(f"  {fam:10s} {cal[fam]:8.2f} ms   x{f[fam]:.2f} the reference machine's")
    return 0


def _loadavg() -> str:
    try:
        return f"{os.getloadavg()[0]:.1f}"
    except OSError:
        return "unknown"


def argv_for_display(args) -> list[str]:
    words = [f"--preset {args.preset}"]
    if args.only:
        words.append(f"--only {args.only}")
    words.append(f"--out {args.out}")
    if args.jobs is not None:
        words.append(f"--jobs {args.jobs}")
    if args.report_only:
        words.append("--report-only")
    if args.launcher:
        words.append(f"--launcher {args.launcher}")
    words += [f"--launcher-arg {a}" for a in args.launcher_arg]
    return words


if __name__ == "__main__":
    from bionav.cli_main import run_main

    run_main(main, "bionav.thesis")
