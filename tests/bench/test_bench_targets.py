"""``python -m bionav.bench``: the CPU numba compiled for (cpu, isa), --cpu-name, and the --reference hook.

Through the user's door (subprocesses), tiny sizes; no timing targets here.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

import pytest

from bionav.bench.cpu import KNOWN_TARGETS, host_cpu, isa_from_features, missing_host_features, target_environment

TINY = ["--repeat", "1", "--batch", "2", "--steps", "24", "--size", "72", "12", "--render-size", "144", "24"]


def _bench(argv, *, env=None, cwd=None):
    proc = subprocess.run([sys.executable, "-m", "bionav.bench", *argv], capture_output=True, text=True,
                          timeout=900, env=env, cwd=cwd)
    assert proc.returncode == 0, proc.stderr[-3000:]
    return [json.loads(line) for line in proc.stdout.splitlines() if line.startswith("{")]


@pytest.mark.parametrize("features, isa", [
    ("+sse,+sse2,+avx,+avx2,+fma", "avx2"),
    (KNOWN_TARGETS["haswell"], "avx2"),
    (KNOWN_TARGETS["x86-64-v3"], "avx2"),
    (KNOWN_TARGETS["skylake-avx512"], "avx512"),
    (KNOWN_TARGETS["x86-64-v4"], "avx512"),
    (KNOWN_TARGETS["x86-64-v2"], "sse"),
    ("+sse2,+avx,-avx2,-avx512f", "avx"),
    ("+neon,+fp-armv8", "neon"),
    ("+neon,+sve", "sve"),
    ("-sse2,-avx2", "scalar"),
])
def test_isa_is_the_widest_enabled_vector_extension(features, isa):
    assert isa_from_features(features) == isa


def test_each_target_has_its_own_numba_cache(tmp_path):
    a = target_environment("haswell", cache_root=tmp_path)
    b = target_environment("skylake-avx512", cache_root=tmp_path)
    assert a["NUMBA_CPU_NAME"] == "haswell" and a["NUMBA_CPU_FEATURES"] == KNOWN_TARGETS["haswell"]
    assert a["NUMBA_CACHE_DIR"] != b["NUMBA_CACHE_DIR"]
    assert a["NUMBA_CACHE_DIR"].startswith(str(tmp_path))
    with pytest.raises(ValueError, match="unknown CPU name"):
        target_environment("no-such-cpu")


@pytest.mark.slow
def test_rows_carry_the_host_target_and_cpu_name_recompiles(tmp_path):
    """Native rows name the host CPU; --cpu-name haswell rows name haswell / avx2 (or are refused without AVX2)."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_CPU")}
    env["BIONAV_CACHE"] = str(tmp_path / "cache")
    rows = _bench(["--json", "--method", "minwarping", *TINY], env=env)
    name, features = host_cpu()
    assert [r["variant"] for r in rows] == ["single", "double_fine", "compass", "compass_double_fine"]
    assert {(r["cpu"], r["isa"]) for r in rows} == {(name, isa_from_features(features))}
    if missing_host_features(KNOWN_TARGETS["haswell"]):
        proc = subprocess.run([sys.executable, "-m", "bionav.bench", "--cpu-name", "haswell", *TINY],
                              capture_output=True, text=True, env=env, timeout=120)
        assert proc.returncode == 2 and "lacks" in proc.stderr
        return
    rows = _bench(["--json", "--method", "minwarping", "--cpu-name", "haswell", *TINY], env=env)
    assert {(r["cpu"], r["isa"]) for r in rows} == {("haswell", "avx2")}
    assert all(r["cpu_ms_per_home_vector"] > 0 for r in rows)
    # the target's compiled code went to its own cache directory
    assert (tmp_path / "cache" / "numba").is_dir()
    assert [p.name.split("-")[0] for p in (tmp_path / "cache" / "numba").iterdir()] == ["haswell"]


FAKE_REFERENCE = textwrap.dedent("""
    import json, sys
    from pathlib import Path
    folder, n = Path(sys.argv[1]), int(sys.argv[2])
    head, *names = (folder / "manifest.txt").read_text().splitlines()
    w, h, horizon, rad_per_row, n_alpha, n_psi, fraction = head.split()
    for name in names:
        data = (folder / name).read_bytes()
        magic, size, maxval, pixels = data.split(b"\\n", 3)
        if magic != b"P5" or size.split() != [w.encode(), h.encode()] or maxval != b"255" \\
                or len(pixels) != int(w) * int(h) or max(pixels) == 0:
            sys.exit(3)
    if (len(names), n_alpha, n_psi, fraction, n) != (4, "24", "24", "0.3", 2):
        sys.exit(4)
    for k, v in enumerate(["single", "double_fine", "compass", "compass_double_fine"]):
        print(json.dumps({"variant": v, "cpu_ms_per_home_vector": 1.5 + k}))
""")


def test_reference_command_times_the_same_8bit_images_interleaved(tmp_path):
    """--reference CMD gets the images (8-bit PGM at --size) and its JSON lines appear next to bionav's rows."""
    script = tmp_path / "fake_reference.py"
    script.write_text(FAKE_REFERENCE)
    rows = _bench(["--json", *TINY, "--repeat", "2", "--reference", f"{sys.executable} {script}"], cwd=tmp_path)
    assert [r["variant"] for r in rows] == ["single", "double_fine", "compass", "compass_double_fine"]
    for k, r in enumerate(rows):
        assert r["input"] == "8bit" and r["rounds"] == 2
        assert r["reference_cpu_ms_per_home_vector"] == 1.5 + k and r["reference_cpu_ms_min"] == 1.5 + k
        # ratio: median over the rounds of bionav's CPU / the reference's of the same round (2 rounds: the mean)
        assert r["cpu_ratio_to_reference"] == pytest.approx(r["cpu_ms_per_home_vector"] / (1.5 + k), abs=2e-3)
        assert r["reference_command"].endswith("fake_reference.py")


@pytest.mark.slow
def test_cpu_name_skylake_avx512_runs_only_where_the_cpu_has_avx512(tmp_path):
    """AVX-512 code is timed on an AVX-512 machine and refused (naming the missing features) elsewhere."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_CPU")}
    env["BIONAV_CACHE"] = str(tmp_path / "cache")
    missing = missing_host_features(KNOWN_TARGETS["skylake-avx512"])
    argv = ["--json", "--method", "minwarping", "--cpu-name", "skylake-avx512", *TINY]
    if missing:
        proc = subprocess.run([sys.executable, "-m", "bionav.bench", *argv], capture_output=True, text=True, env=env,
                              timeout=120)
        assert proc.returncode == 2 and "Traceback" not in proc.stderr
        assert all(f in proc.stderr for f in missing) and "illegal instruction" in proc.stderr
        return
    rows = _bench(argv, env=env)
    assert {(r["cpu"], r["isa"]) for r in rows} == {("skylake-avx512", "avx512")}
