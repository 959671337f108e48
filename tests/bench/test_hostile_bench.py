"""Hostile input of every benchmark entry point, through the user's door (``python -m ...`` subprocesses).

Each case: a non-zero exit status, no traceback, a message naming the option at
fault, and an end within a time bound (sizes are checked before any work).
Output into a closed pipe (``... | head -1``) ends quietly.
"""

from __future__ import annotations

import subprocess
import sys
import time

import pytest

#: seconds a refused command may take (interpreter start and imports on a loaded 2-core machine)
BOUND_S = 90.0
TINY = ["--repeat", "1", "--batch", "2", "--steps", "24", "--size", "72", "12", "--render-size", "144", "24"]


def _run(module: str, argv: list[str], **kwargs) -> tuple[subprocess.CompletedProcess, float]:
    t0 = time.monotonic()
    proc = subprocess.run([sys.executable, "-m", module, *argv], capture_output=True, text=True,
                          timeout=BOUND_S + 30, **kwargs)
    return proc, time.monotonic() - t0


def _missing_feature() -> str | None:
    import llvmlite.binding as ll

    # a feature LLVM knows for this target (a key of the host's feature map) that this CPU lacks
    host = ll.get_host_cpu_features()
    lacking = sorted(name for name, present in host.items() if not present)
    for name in ("avx512vp2intersect", "fma4", "sse4a", "avx2", "amx-tile"):
        if name in lacking:
            return name
    return lacking[0] if lacking else None


BENCH_CASES = [
    (["--size", "0", "0"], "--size"),
    (["--size", "-288", "50"], "--size"),
    (["--size", "100000", "100000"], "--size"),
    (["--size", "x", "50"], "--size"),
    (["--size", "73", "50"], "--size"),  # odd width: min-warping's double search
    (["--steps", "0"], "--steps"),
    (["--steps", "-3"], "--steps"),
    (["--steps", "1000000"], "--steps"),
    (["--render-size", "1", "1"], "--render-size"),
    (["--render-size", "100000", "100"], "--render-size"),
    (["--repeat", "0"], "--repeat"),
    (["--repeat", "1000000000"], "--repeat"),
    (["--batch", "0"], "--batch"),
    (["--batch", "1000000000"], "--batch"),
    (["--threads", "0"], "--threads"),
    (["--threads", "100000"], "--threads"),
    (["--background-load", "-1"], "--background-load"),
    (["--background-load", "100000"], "--background-load"),
    (["--compass-fraction", "nan"], "--compass-fraction"),
    (["--compass-fraction", "0"], "--compass-fraction"),
    (["--grid-snapshots", "0"], "--grid-snapshots"),
    (["--grid-rounds", "1000000"], "--grid-rounds"),
    (["--pairs", "9"], "--pairs"),
    (["--method", "nope"], "--method"),
    (["--method", "warping2d", "--grid", "sim_original"], "--grid"),
    (["--grid", "no_such_db", "--grid-snapshots", "1"], "--grid"),
    (["--method", "sift", "--variants", "nope"], "--variants"),
    (["--method", "sift", "--sift-size", "1", "1"], "--sift-size"),
    (["--method", "sift", "--sift-size", "4096", "1024"], "--sift-size"),
    (["--method", "sift", "--images", "1000000000"], "--images"),
    (["--method", "sift", "--db", "no_such_db", "--images", "2"], "--db"),
    (["--cpu-name", "no-such-cpu"], "--cpu-name"),
    (["--cpu-features", "+avx2"], "--cpu-features"),
    (["--cpu-name", "mine", "--cpu-features=-avx2"], "--cpu-name"),
    (["--method", "hiss", "--reference", "true"], "--reference"),
    (["--reference", "/no/such/driver", *TINY], "--reference"),
    (["--reference", "false", *TINY], "--reference"),
    (["--reference", f"{sys.executable} -c \"print('garbage')\"", *TINY], "--reference"),
    (["--reference", f"{sys.executable} -c \"raise SystemExit('driver broke')\"", *TINY], "--reference"),
    (["--reference", "'unbalanced", *TINY], "--reference"),
    (["--method", "sweep", "--workers", "0"], "--workers"),
    (["--method", "sweep", "--workers", "100000"], "--workers"),
    (["--method", "sweep", "--dbs", ","], "--dbs"),
    (["--method", "sweep", "--dbs", "sim_original,no_such_db"], "--dbs"),
    (["--method", "sweep", "--override", "garbage"], "--override"),
    (["--method", "cleaning", "--runs", "0"], "--runs"),
    (["--method", "cleaning", "--runs", "1000000000"], "--runs"),
    (["--method", "cleaning", "--layout", "nope"], "--layout"),
    (["--method", "cleaning", "--runs", "1", "--override", "experiment.vision=nope"], "--override"),
]

OTHER_CASES = [
    ("bionav.bench.decoders", ["--samples", "1000000000"], "--samples"),
    ("bionav.bench.decoders", ["--samples", "0"], "--samples"),
    ("bionav.bench.decoders", ["--rotations", "0"], "--rotations"),
    ("bionav.bench.decoders", ["--rotations", "1000", "--samples", "100000"], "--samples"),
    ("bionav.bench.decoders", ["--repeat", "-1"], "--repeat"),
    ("bionav.bench.decoders", ["--decoder", "nope"], "--decoder"),
    ("bionav.bench.sweep", ["--n-jobs", "0"], "--n-jobs"),
    ("bionav.bench.sweep", ["--homing", "nope"], "--homing"),
    ("bionav.bench.sweep", ["--db", "nope"], "--db"),
    ("bionav.bench.sweep", ["--sweep", "garbage"], "--sweep"),
    ("bionav.bench.mesh", ["--threads", "0"], "--threads"),
    ("bionav.bench.mesh", ["--threads", "100000"], "--threads"),
    ("bionav.bench.mesh", ["--repeat", "0"], "--repeat"),
    ("bionav.bench.mesh", ["--grid", "100000"], "--grid"),
]


def _assert_refused(proc, elapsed, option):
    err = proc.stderr.strip()
    assert proc.returncode != 0, proc.stdout[-500:]
    assert "Traceback" not in proc.stderr and "Traceback" not in proc.stdout, err[-2000:]
    assert option in err, err
    assert "\n\n" not in err and len(err.splitlines()) <= 3, err  # one paragraph, no usage block
    assert elapsed < BOUND_S, f"took {elapsed:.0f} s"


@pytest.mark.slow
@pytest.mark.parametrize("argv, option", BENCH_CASES, ids=[" ".join(a)[:60] for a, _ in BENCH_CASES])
def test_bench_refuses_hostile_input(argv, option, tmp_path):
    proc, elapsed = _run("bionav.bench", argv, cwd=tmp_path)
    _assert_refused(proc, elapsed, option)


@pytest.mark.slow
@pytest.mark.parametrize("module, argv, option", OTHER_CASES, ids=[f"{m} {' '.join(a)}" for m, a, _ in OTHER_CASES])
def test_other_bench_commands_refuse_hostile_input(module, argv, option, tmp_path):
    proc, elapsed = _run(module, argv, cwd=tmp_path)
    _assert_refused(proc, elapsed, option)


def test_cpu_name_refuses_to_execute_code_for_features_this_cpu_lacks(tmp_path):
    missing = _missing_feature()
    if missing is None:  # pragma: no cover - a CPU with every candidate feature
        pytest.skip("this CPU has every candidate feature")
    import llvmlite.binding as ll

    cpu = ll.get_host_cpu_name()  # a name LLVM knows; the refusal is for the feature this CPU lacks
    proc, elapsed = _run("bionav.bench", ["--cpu-name", cpu, "--cpu-features", f"+sse2,+{missing}"], cwd=tmp_path)
    _assert_refused(proc, elapsed, "--cpu-name")
    assert "lacks" in proc.stderr and missing in proc.stderr and "illegal instruction" in proc.stderr


@pytest.mark.parametrize("module, argv", [
    ("bionav.bench", ["--help"]),
    ("bionav.bench", ["--json", *TINY, "--method", "hiss"]),
    ("bionav.bench.decoders", ["--decoder", "two_unit", "--rotations", "1", "--samples", "8", "--repeat", "1"]),
    ("bionav.bench.mesh", ["--help"]),
    ("bionav.bench.sweep", ["--help"]),
])
def test_output_into_a_closed_pipe_ends_quietly(module, argv, tmp_path):
    """``... | head -0``: the reader is gone before the first line; no traceback, a non-zero status."""
    t0 = time.monotonic()
    proc = subprocess.Popen([sys.executable, "-m", module, *argv], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            cwd=tmp_path)
    proc.stdout.close()
    try:
        _, err = proc.communicate(timeout=BOUND_S + 60)
    except subprocess.TimeoutExpired:  # pragma: no cover - a hang is the failure
        proc.kill()
        raise
    err = err.decode(errors="replace")
    assert proc.returncode != 0
    assert "Traceback" not in err and "BrokenPipeError" not in err, err[-2000:]
    assert time.monotonic() - t0 < BOUND_S + 60
