"""``python -m bionav [hydra overrides]``: the one entry point.

This is the one place where user errors become clean messages: one
paragraph naming the problem and the fix, a non-zero exit status, no
traceback (the traceback of an unexpected error goes to ``error.log`` in the
run directory).
"""

from __future__ import annotations

import logging
import os
import sys
import tempfile
from pathlib import Path

from bionav.clihelp import composition_message
from bionav.errors import UserError
from bionav.files import user_path
from bionav.registry import names_by_group

EXIT_USER_ERROR = 2
EXIT_INTERNAL_ERROR = 1
#: a run directory with less free space is refused before Hydra writes its files there
MIN_FREE_BYTES = 2**20

log = logging.getLogger("bionav")

#: config groups that hold YAML options only (plugin groups come from the registry)
YAML_GROUPS = ("experiment", "db", "preprocess", "layout", "data", "mode")


def _fail(message: str, code: int = EXIT_USER_ERROR) -> None:
    try:
        print(f"bionav: error: {message}", file=sys.stderr)
    except OSError:  # the terminal is gone (SIGHUP): the exit status and metrics.json still say it
        pass
    sys.exit(code)


def _precheck(argv: list[str]) -> list[tuple[Path, bool]]:
    """Catch unknown plugin names before Hydra starts; return the output dirs given (path, is_sweep)."""
    from hydra.core.override_parser.overrides_parser import OverridesParser

    words = _override_words(argv)
    parser = OverridesParser.create()
    for word in words:
        try:
            parser.parse_overrides([word])
        except Exception as exc:
            detail = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            key = word.split("=", 1)[0]
            raise UserError(
                f"cannot read the override {word!r} ({detail}). Values with characters such as ~ * ? : [ ] "
                f"or spaces must be quoted for Hydra, inside the shell's quotes, e.g. '{key}=\"...\"' "
                f"(see https://hydra.cc/docs/advanced/override_grammar/basic)."
            ) from None
    try:
        overrides = parser.parse_overrides(words)
    except Exception:
        return []  # Hydra reports syntax errors itself
    dirs: list[tuple[Path, bool]] = []
    groups = {g: list(v) for g, v in names_by_group().items()}
    for group in YAML_GROUPS:
        if _yaml_options(group):  # only groups that exist; otherwise `key=value` is a plain value
            groups.setdefault(group, [])
    for override in overrides:
        key = override.key_or_group
        if key.startswith("hydra/") and isinstance(override.value(), str):
            from bionav.clihelp import check_hydra_option

            check_hydra_option(key, override.value())
        if key in groups and not override.is_delete():
            values = override.value()
            candidates = values if isinstance(values, list) else [values]
            if override.is_sweep_override() and not isinstance(values, list):
                continue
            for value in candidates:
                if isinstance(value, str) and value not in groups[key] and not _has_yaml(key, value):
                    choices = sorted(set(groups[key]) | set(_yaml_options(key)))
                    raise UserError(
                        f"unknown {key} {value!r}. Available: {', '.join(choices) or '(none installed)'}. "
                        f"Run `python -m bionav.plugins` to see every installed plugin."
                    )
        if key in ("hydra.run.dir", "hydra.sweep.dir"):
            value = override.value()
            if not isinstance(value, str) or not value.strip():
                raise UserError(
                    f"{key}={value!r} names no directory (an empty one would be the current directory, whose "
                    f"files a run would mix with its own); give a directory, e.g. {key}=outputs/my_run."
                )
            dirs.append((user_path(value), key == "hydra.sweep.dir"))
    return dirs


#: options of Hydra's command line that take the next word as their value
_FLAGS_WITH_VALUE = ("--cfg", "-c", "--package", "-p", "--config-path", "-cp", "--config-name", "-cn",
                     "--config-dir", "-cd", "--experimental-rerun", "--shell-completion", "-sc")


def _override_words(argv: list[str]) -> list[str]:
    """The words of the command line that are overrides (not options, not an option's value)."""
    out, skip = [], False
    for a in argv:
        if skip:
            skip = False
            continue
        if a.startswith("-"):
            skip = a in _FLAGS_WITH_VALUE
            continue
        out.append(a)
    return out


def _concrete_overrides(argv: list[str]) -> list[str] | None:
    """The command line's overrides with each sweep replaced by its first value (None: unparsable)."""
    from hydra.core.override_parser.overrides_parser import OverridesParser

    try:  # the words after --cfg, --info, -cn, ... are not overrides
        overrides = OverridesParser.create().parse_overrides(_override_words(argv))
    except Exception:
        return None  # Hydra reports syntax errors itself
    out = []
    for override in overrides:
        key = override.key_or_group
        if key == "hydra" or key.startswith(("hydra.", "hydra/")):
            continue
        if override.is_sweep_override():
            try:
                values = list(override.sweep_string_iterator())
            except Exception:  # interval sweeps (optimisers): each job checks its own value
                continue
            if not values:
                continue
            out.append(f"{override.get_key_element()}={values[0]}")
        else:
            out.append(override.input_line)
    return out


def _check_composition(argv: list[str], *, validate: bool = True):
    """Compose the configuration once before Hydra runs; turn its errors into one paragraph.

    With ``validate``, also check every value against its declared range
    (:func:`bionav.experiments.runner.validate_run_config`), so a bad value is
    reported before a run directory is created. A sweep is checked with the
    first value of each swept key (each job checks its own values again).
    """
    from bionav.config import compose

    overrides = _concrete_overrides(argv)
    if overrides is None:
        return None
    try:
        cfg = compose(overrides, return_hydra_config=True)
    except Exception as exc:
        raise UserError(composition_message(exc, overrides)) from None
    from omegaconf import OmegaConf, open_dict

    params = OmegaConf.select(cfg, "hydra.sweeper.params", default=None)
    _STATE["sweeper_params"] = OmegaConf.to_container(params) if params is not None else None
    with open_dict(cfg):
        del cfg["hydra"]
    if validate:
        from bionav.experiments.runner import validate_run_config

        validate_run_config(cfg)
    return cfg


def _yaml_options(group: str) -> list[str]:
    from bionav.config import config_options

    return config_options(group)


def _has_yaml(group: str, value: str) -> bool:
    return value in _yaml_options(group)


def _check_writable(path: Path, *, sweep: bool = False) -> None:
    """The output directory can be created and written, and no live run holds it."""
    from bionav.runlock import check_free

    fix = "Choose another one with hydra.run.dir=... (or hydra.sweep.dir=... for -m)."
    probe = path
    while not probe.exists() and probe != probe.parent:
        probe = probe.parent
    if not probe.is_dir() or not os.access(probe, os.W_OK):
        what = "is not a directory" if not probe.is_dir() else "is not writable"
        raise UserError(f"cannot write the output directory {path}: {probe} {what}. {fix}")
    if "${" in str(path):
        return  # resolved by Hydra (e.g. ${now:...}); the probe above is all we can check
    try:
        path.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=path):
            pass
    except OSError as exc:
        raise UserError(f"cannot write the output directory {path}: {exc.strerror or exc}. {fix}") from None
    free = os.statvfs(path)
    if free.f_bavail * free.f_frsize < MIN_FREE_BYTES:
        from bionav.experiments.runner import mount_point

        raise UserError(
            f"no space left on {mount_point(path)} (only {free.f_bavail * free.f_frsize // 1024} kB free, a run "
            f"needs at least {MIN_FREE_BYTES // 2**20} MB for its config, log and metrics); free space or choose "
            f"hydra.run.dir=... on another disk."
        )
    check_free(path)
    if sweep:
        for job in sorted(p.parent for p in path.glob("*/.bionav.lock")):
            check_free(job)


def _check_sweep_overrides(argv: list[str]) -> None:
    """Search spaces and sweeper settings that a sweeper would reject with a traceback (or never finish)."""
    from hydra.core.override_parser.overrides_parser import OverridesParser
    from hydra.core.override_parser.types import IntervalSweep, RangeSweep

    try:
        overrides = OverridesParser.create().parse_overrides(_override_words(argv))
    except Exception:
        return
    for o in overrides:
        key, value = o.key_or_group, o.value()
        if isinstance(value, IntervalSweep) and not value.start < value.end:
            raise UserError(
                f"{o.input_line}: an interval's lower bound must be below its upper bound; write "
                f"{key}=interval({value.end},{value.start})."
            )
        if isinstance(value, RangeSweep) and value.step and (value.stop - value.start) / value.step <= 0:
            raise UserError(f"{o.input_line} holds no value (start {value.start}, stop {value.stop}, step "
                            f"{value.step}); give start < stop for a positive step, e.g. {key}=range(1,10).")
        if key == "hydra.sweeper.direction" and value not in ("minimize", "maximize"):
            raise UserError(f"hydra.sweeper.direction={value} is not a direction: use minimize or maximize (the "
                            f"run's objective.direction, e.g. minimize for aae, maximize for rr).")
        if key == "hydra.sweeper.n_trials" and (not isinstance(value, int) or isinstance(value, bool) or value < 1):
            raise UserError(f"hydra.sweeper.n_trials={value}: a study needs at least one trial; give "
                            f"hydra.sweeper.n_trials=1 or more.")


def _check_objective_metric(cfg, metrics: dict) -> None:
    """A sweeper optimising a metric that the run does not write would rank every trial +-inf: refuse."""
    from hydra.core.hydra_config import HydraConfig

    node = cfg.get("objective")
    target = str(_select(HydraConfig.get(), "sweeper._target_") or "")
    if node is None or not target or target.endswith("BasicSweeper") or metrics.get("status") != "completed":
        return
    metric = str(node.get("metric"))
    value: object = metrics
    for part in metric.split("."):
        value = value.get(part) if isinstance(value, dict) else None
    if value is None and metrics.get(metric) is None:
        keys = ", ".join(k for k, v in metrics.items() if isinstance(v, (int, float)) and not isinstance(v, bool))
        raise UserError(f"objective.metric={metric} is not in this run's metrics.json, so the sweeper would rank "
                        f"every trial as the worst; name one of its numbers ({keys}), e.g. objective.metric=aae.")


def _select(node, key: str):
    from omegaconf import OmegaConf

    return OmegaConf.select(node, key, default=None)


def _check_name_lengths(path: Path, key: str) -> None:
    """Each folder name of an output directory fits the file system (255 bytes on most)."""
    probe = path
    while not os.path.isdir(probe) and probe != probe.parent:
        probe = probe.parent
    try:
        limit = os.pathconf(probe, "PC_NAME_MAX")
    except (OSError, ValueError):
        limit = 255
    for part in path.parts:
        if len(os.fsencode(part)) > limit:
            raise UserError(
                f"File name too long: the folder name {part[:40]}... in {key} has {len(os.fsencode(part))} bytes, "
                f"more than the {limit} this file system allows; choose a shorter {key}=..."
            )


def _expand_output_dirs(argv: list[str]) -> list[str]:
    """``hydra.run.dir=~/x`` (quoted for Hydra) with ``~`` expanded: Hydra itself would create a folder named ``~``."""
    from hydra.core.override_parser.overrides_parser import OverridesParser

    parser = OverridesParser.create()
    out = []
    for a in argv:
        if a.split("=", 1)[0] in ("hydra.run.dir", "hydra.sweep.dir") and "~" in a:
            try:
                override = parser.parse_overrides([a])[0]
                value = override.value()
            except Exception:
                value = None
            if isinstance(value, str) and value.startswith("~"):
                a = f'{override.key_or_group}="{user_path(value)}"'
        out.append(a)
    return out


def _resuming(argv: list[str]) -> bool:
    """True when the command line says ``bionav.resume=true``."""
    words = [w.lstrip("+") for w in _override_words(argv)]
    return any(w.split("=", 1)[0] == "bionav.resume" and w.split("=", 1)[1].strip().lower() in ("true", "1", "yes")
               for w in words if "=" in w)


def _task(cfg) -> float | None:
    """One job; returns the run's objective (config ``objective``) for sweepers, worst on failure."""
    from hydra.core.hydra_config import HydraConfig
    from hydra.types import RunMode

    from bionav.clirecord import keep_record
    from bionav.experiments.objective import objective_from_config
    from bionav.experiments.runner import run_experiment

    hc = HydraConfig.get()
    run_dir = Path(hc.runtime.output_dir)
    multirun = hc.mode == RunMode.MULTIRUN
    if multirun:
        _SWEEP["dir"] = Path(str(hc.sweep.dir))
    objective = None
    try:
        objective = objective_from_config(cfg.get("objective"))
        keep_record(cfg, run_dir, multirun=multirun)
        metrics = run_experiment(cfg, run_dir, show_progress=sys.stderr.isatty() or not multirun)
    except UserError as exc:
        if multirun:
            log.error("job %s failed: %s", hc.job.num, exc)
            return objective.worst if objective else None
        _fail_refused(exc, run_dir, hc)
    except KeyboardInterrupt:
        if multirun:
            raise  # main() writes the summary of the finished jobs
        _fail(f"interrupted; what was recorded so far is in {run_dir} (metrics.json says failed).", 130)
    except Exception as exc:
        if multirun:
            log.error("job %s failed with an internal error: %s (see %s/error.log)", hc.job.num, exc, run_dir)
            return objective.worst if objective else None
        _fail(
            f"internal error: {type(exc).__name__}: {exc}. This is a bug in bionav or a plugin; the traceback is "
            f"in {run_dir / 'error.log'} and the run's log in {run_dir / 'run.mcap'}.",
            EXIT_INTERNAL_ERROR,
        )
    if multirun:
        try:
            _check_objective_metric(cfg, metrics)
        except UserError as exc:
            _fail(f"{exc} (job {hc.job.num}: {run_dir})")
        log.info(
            "job %s: %s",
            hc.job.num,
            ", ".join(f"{k}={metrics[k]:.4g}" for k in ("aae", "mae", "rr") if isinstance(metrics.get(k), float))
            or metrics.get("status"),
        )
    else:
        _print_result(metrics)
        print(f"run directory: {run_dir}")  # the last line: where everything the run wrote is
    return objective.value(metrics) if objective else None


def _fail_refused(exc: UserError, run_dir: Path, hc) -> None:
    """A single run's user error; a run refused at start leaves no directory behind."""
    from bionav.clirecord import forget_refused

    if getattr(exc, "refused_at_start", False) and forget_refused(
            run_dir, existed=bool(_STATE.get("run_dir_existed")), job_log=f"{hc.job.name}.log"):
        _fail(f"{exc} (nothing was recorded; no run directory was left behind)")
    _fail(f"{exc} (run directory: {run_dir})")


def _print_result(metrics: dict) -> None:
    from bionav.report.table import format_metrics

    print(format_metrics(metrics))


#: the sweep directory of the multirun in progress (set by the first job; read after an interrupt)
_SWEEP: dict[str, Path] = {}
#: what the checks before Hydra found: "show" (a finished run to show), "run_dir_existed", "sweeper_params"
_STATE: dict = {}


def _interrupted_sweep() -> None:
    """Ctrl-C during a sweep: write summary.csv/summary.md for the jobs so far, then exit 130."""
    sweep_dir = _SWEEP.get("dir")
    if sweep_dir is None or not sweep_dir.is_dir():
        _fail("interrupted before the first job started; nothing was recorded.", 130)
    from bionav.report.callback import write_sweep_summary

    try:
        n_jobs, n_failed, md_path = write_sweep_summary(sweep_dir)
    except KeyboardInterrupt:
        _fail(f"interrupted twice; the jobs' results are in {sweep_dir} (rebuild the summary with "
              f"`python -m bionav.report {sweep_dir}`).", 130)
    _fail(f"interrupted; the summary of the {n_jobs} jobs so far ({n_failed} failed or interrupted) is in {md_path}. "
          f"Finish the sweep with the same command plus bionav.resume=true hydra.sweep.dir={sweep_dir}", 130)


def _sweep_failures() -> None:
    """After a multirun: exit 1 with the count of failed jobs (unless bionav.fail_on_job_error=false)."""
    from bionav.report.callback import LAST_SWEEP

    if not LAST_SWEEP or not LAST_SWEEP.get("n_failed") or not LAST_SWEEP.get("fail_on_job_error", True):
        return
    n_failed, n_jobs = LAST_SWEEP["n_failed"], LAST_SWEEP["n_jobs"]
    _fail(f"{n_failed} of {n_jobs} jobs failed: {', '.join(LAST_SWEEP['failed'])} (their errors are in "
          f"{LAST_SWEEP['summary']}); the other jobs' results are kept. Fix and re-run them with bionav.resume=true, "
          f"or pass bionav.fail_on_job_error=false to exit with status 0 anyway.", 1)


def _completion_query(hydra_main) -> None:
    """Hydra's answer to a completion query, without bionav's internal groups."""
    import contextlib
    import io

    from bionav.completion import without_internal

    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        hydra_main()
    text = out.getvalue()
    print(without_internal(text) if text.strip() else text, end="\n" if text.strip() else "")


def limit_blas_threads() -> None:
    """One BLAS thread per worker: bionav parallelises over image pairs itself.

    Multi-threaded BLAS on the small matrices of per-pair work (SIFT
    descriptor distances) is an order of magnitude slower than one thread
    when the cores are already busy. Must run before numpy is imported;
    a user's explicit setting wins.
    """
    for var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")


def _answered_without_hydra(argv: list[str]) -> bool:
    """Answer ``--shell-completion install=bash`` and quick TAB completions without Hydra; True if answered."""
    from bionav.completion import BASH_SCRIPT, rewrite_query_line, wants_bash_install

    if wants_bash_install(argv):  # Hydra's script does not know `python -m bionav`
        print(BASH_SCRIPT, end="")
        return True
    rewrite_query_line()
    if any(a in ("-sc", "--shell-completion") for a in argv) and "query=bash" in argv:
        from bionav.completion import quick_choices

        choices = quick_choices()
        if choices is not None:
            print(" ".join(choices))
            return True
    return False


def _check_before_running(argv: list[str]) -> bool | None:
    """Every check that can refuse the command line before Hydra runs (raises :class:`UserError`).

    Prints bionav's own ``--help`` and returns None; otherwise returns whether
    this is a shell-completion query. Output directories are checked only after
    every value passed, so that a refused run leaves no directory behind.
    """
    from bionav.config import register_configs

    register_configs()
    from bionav.clihelp import help_text, wants_help

    if wants_help(argv) and "--hydra-help" not in argv:  # Hydra's own help copies its repository per group
        try:
            print(help_text(argv), end="")
        except UserError:
            raise
        except Exception as exc:  # a bad override: Hydra's composition message
            raise UserError(composition_message(exc, [a for a in argv if not a.startswith("-")])) from None
        return None
    output_dirs: list[tuple[Path, bool]] = []
    completion = any(a in ("-sc", "--shell-completion") for a in argv)  # `query=...` is not an override
    if not completion and not any(
        a in ("--help", "-h", "--hydra-help", "--info", "--cfg", "-c") or a.startswith("--info") for a in argv
    ):
        output_dirs = _precheck(argv)
    cfg = None
    if not completion and not any(a in ("--help", "-h", "--hydra-help", "-cp", "-cn", "-cd", "--config-path",
                                        "--config-name", "--config-dir") or a.startswith("--info") for a in argv):
        cfg = _check_composition(argv, validate=not any(a in ("--cfg", "-c") for a in argv))
    # only after every value passed: a refused run leaves no directory behind
    if any(a in ("-m", "--multirun") for a in argv):
        _check_sweep_overrides(argv)
    _check_records(argv, output_dirs, cfg)
    return completion


def _check_records(argv: list[str], output_dirs: list[tuple[Path, bool]], cfg) -> None:
    """Output directories: writable, not in use, and any run recorded there kept (:mod:`bionav.clirecord`)."""
    from bionav.clirecord import check_run_dir, check_sweep_dir

    resume = _resuming(argv)
    for path, sweep in output_dirs:
        _check_name_lengths(path, "hydra.sweep.dir" if sweep else "hydra.run.dir")
        existed = path.is_dir()
        _check_writable(path, sweep=sweep)  # a live writer first: "in use" says more than "finished"
        if sweep:
            check_sweep_dir(path, _override_words(argv), _STATE.get("sweeper_params"), resume=resume)
            continue
        _STATE["run_dir_existed"] = existed
        if check_run_dir(path, cfg, resume=resume):
            _STATE["show"] = path


def main(argv: list[str] | None = None) -> None:
    """Entry point of ``python -m bionav`` and the ``bionav`` console script."""
    from bionav.cli_main import end_on_termination_signals, guard_closed_pipe

    guard_closed_pipe()  # `python -m bionav --help | head -1` ends quietly
    argv = list(sys.argv[1:] if argv is None else argv)
    # `python -m bionav homing=sift -m ...`: Hydra's parser takes overrides only after its flags
    argv = [a for a in argv if a in ("-m", "--multirun")] + [a for a in argv if a not in ("-m", "--multirun")]
    limit_blas_threads()
    if _answered_without_hydra(argv):
        return
    try:
        completion = _check_before_running(argv)
    except UserError as exc:
        _fail(str(exc))
    if completion is None:  # bionav's --help was printed
        return

    argv = _expand_output_dirs(argv)
    multirun = any(a in ("-m", "--multirun") for a in argv)
    shows = [a for a in argv if a in ("--cfg", "-c", "--info", "--shell-completion", "-sc") or a.startswith("--info")]
    if multirun and shows:
        _fail(f"{shows[0]} shows one composed config, so it cannot be combined with -m (a sweep): drop -m and "
              f"give one value per key, e.g. homing=sift instead of homing=sift,mfdid.")

    if _STATE.get("show") is not None:
        from bionav.clirecord import show_finished

        return show_finished(_STATE["show"])
    if not shows and not completion and not any(a.split("=", 1)[0] == "hydra.output_subdir" for a in argv):
        argv.append("hydra.output_subdir=null")  # bionav writes the record itself, and never over a resumed run's

    import hydra

    hydra_main = hydra.main(version_base="1.3", config_path=None, config_name="config")(_task)
    sys.argv = [sys.argv[0] or "bionav", *argv]
    end_on_termination_signals()
    try:
        if completion and any(a.startswith("query=") for a in argv):
            _completion_query(hydra_main)
        else:
            hydra_main()
    except KeyboardInterrupt:
        if multirun:
            _interrupted_sweep()
        _fail("interrupted before the run started; nothing was recorded.", 130)
    if multirun:
        _sweep_failures()
        if _SWEEP.get("dir") is not None:
            print(f"sweep directory: {_SWEEP['dir']}")
