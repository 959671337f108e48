"""The hot numba kernels compile to packed instructions without masked stores, for AVX2 and for AVX-512.

Independent of the machine running the tests: every kernel is compiled (never
run) in one subprocess per target, with numba's CPU name and features set to
an AVX2 CPU (haswell) and to an AVX-512 CPU (skylake-avx512), each with its
own empty cache (``tests/kernel_codegen.py``). On AVX2, a running minimum kept
with a conditional or in-place store vectorises only with masked stores
(none for bytes: the loop stays scalar; ``vmaskmovps``/``vpmaskmovq`` for
32/64-bit lanes, slow on AMD CPUs), so no kernel may contain one.
"""

from __future__ import annotations

import platform
import re
from concurrent.futures import ThreadPoolExecutor

import pytest
from kernel_codegen import kernel_asm

# slow: the module compiles every kernel in fresh processes for two targets (about 45 s)
pytestmark = [pytest.mark.skipif(platform.machine() not in ("x86_64", "AMD64"), reason="x86 targets and mnemonics"),
              pytest.mark.slow]

#: packed instructions each kernel must contain, on vector registers (ymm for AVX2, ymm or zmm for AVX-512)
PACKED = {
    "fill_window_minima[u8]": ["vpminub"],  # sliding minima of 8-bit distances
    "fill_window_minima[f32]": ["vminps"],
    "minwarp_scores[u8]": ["vpminub", "vpaddw"],  # byte minima over windows, 16-bit match values
    "minwarp_scores[f32]": ["vminps", "vaddps"],
    "compass_measure[u8]": ["vpminub"],
    "compass_measure[f32]": ["vminps"],
    "warp2d_scores": ["vaddps"],
    # 16-bit |a - b| summed in 16 bits; the normalisation packed too: 32-bit sums to float (AVX2 has no
    # packed 64-bit integer to float conversion: an int64 sum there kept it scalar, 0.75 ms per pair)
    "diagonal_distances[u8]": ["vpsubw", "vpabsw", "vpaddw", "vcvtdq2ps"],
    "diagonal_distances[f32]": ["vsubps", "vaddps"],
    "sift_match_sorted": ["vfmadd231ps"],  # descriptor dot products
    # explicit vectors (issue 42): the search's running minima and 16-bit sums stay in registers (byte minima,
    # bytes widened and added to words); the distance sums of 32 columns x 4 diagonals over all rows
    "minwarp_search_u8": ["vpminub", "vpmovzxbw", "vpaddw"],
    "diagonal_distances_u8": ["vpmaxsw", "vpaddw", "vpsubw", "vcvtdq2ps"],  # sum |a - b| as 2 sum max - sums
    # one compiled call per pair: the kernels above linked in (byte minima, 16-bit sums, the normalisation)
    "minwarp_pair_u8": ["vpminub", "vpmovzxbw", "vpmaxsw", "vcvtdq2ps"],
    "warping1d_scores": ["vfmadd231pd"],
}
#: int64 minima of the SIFT keys: compare and blend on AVX2, vpminsq (AVX-512 only) on AVX-512
INT64_MIN = {"avx2": ["vpcmpgtq", "vblendvpd"], "avx512": ["vpminsq"]}
SIFT_SCANS = ["sift_scan_core", "sift_scan_edge"]
#: kernels whose loops are scalar by nature (ray casting, agent trials, gathers): compiled, no masked stores
SCALAR = ["minwarp_scores_at[u8]", "minwarp_scores_at[f32]", "minwarp_scores_runs[u8]", "minwarp_scores_runs[f32]",
          "swap_roles[u8]", "swap_roles[f32]", "mesh_cast_kernel", "mesh_fill_grid", "world_candidates",
          "world_depth_kernel", "world_render_kernel", "world_surface_kernel", "coverage_sweep", "agent_success"]
#: kernels that must have no AVX-512 masked store either (their rewrite is the point: plain packed stores)
NO_K_MASK = [k for k in list(PACKED) + SIFT_SCANS if k != "warping1d_scores"] + [
    k for k in SCALAR if k.startswith(("minwarp", "swap_roles", "world_candidates"))]

_VEC = {"avx2": r"%ymm\d+", "avx512": r"%[yz]mm\d+"}


def _instructions(asm: str) -> list[str]:
    out = []
    for line in asm.splitlines():
        s = line.split("#")[0].strip()
        if s and not s.startswith(".") and not s.endswith(":"):
            out.append(s)
    return out


def _packed(lines, mnemonic, isa):
    pat = re.compile(rf"^{mnemonic}\s.*{_VEC[isa]}")
    return [s for s in lines if pat.search(s)]


def _avx2_masked_stores(lines):
    # AT&T syntax: ``vmaskmovps %ymm1, %ymm0, (%rdi)`` stores (memory operand last); masked loads are harmless
    return [s for s in lines if re.match(r"v(p)?maskmov\w*\s.*\)$", s)]


def _k_masked_stores(lines):
    # AT&T syntax: a store's memory operand is last, the mask follows it: ``vmovdqu8 %ymm0, (%rax) {%k1}``;
    # scatters always carry a mask (all lanes for an unconditional one) and are not counted
    return [s for s in lines if re.search(r"\)\s*\{%k\d\}", s) and "scatter" not in s]


@pytest.fixture(scope="module")
def asm():
    with ThreadPoolExecutor(2) as pool:
        jobs = {isa: pool.submit(kernel_asm, isa) for isa in ("avx2", "avx512")}
        return {isa: {k: _instructions(a) for k, a in job.result().items()} for isa, job in jobs.items()}


@pytest.mark.slow
def test_every_kernel_is_compiled_for_both_targets(asm):
    names = set(PACKED) | set(SIFT_SCANS) | set(SCALAR)
    for isa in ("avx2", "avx512"):
        assert set(asm[isa]) == names
        assert all(len(lines) > 10 for lines in asm[isa].values())


def test_avx2_code_uses_no_avx512(asm):
    # the target really is AVX2, whatever the host: no 512-bit registers, no mask registers
    for name, lines in asm["avx2"].items():
        assert not [s for s in lines if re.search(r"%zmm|%k\d", s)], name


@pytest.mark.parametrize("isa", ["avx2", "avx512"])
@pytest.mark.parametrize("name", sorted(PACKED))
def test_kernel_compiles_to_packed_instructions(asm, isa, name):
    lines = asm[isa][name]
    for mnemonic in PACKED[name]:
        assert _packed(lines, mnemonic, isa), f"{name} for {isa}: no packed {mnemonic}"


@pytest.mark.parametrize("isa", ["avx2", "avx512"])
@pytest.mark.parametrize("name", SIFT_SCANS)
def test_sift_key_minima_are_packed_int64_minima(asm, isa, name):
    lines = asm[isa][name]
    for mnemonic in INT64_MIN[isa]:
        assert _packed(lines, mnemonic, isa), f"{name} for {isa}: no packed {mnemonic}"


def test_no_kernel_has_avx2_masked_stores(asm):
    found = {name: _avx2_masked_stores(lines)[:3] for name, lines in asm["avx2"].items()}
    assert {k: v for k, v in found.items() if v} == {}


def test_rewritten_kernels_have_no_avx512_masked_stores(asm):
    found = {name: _k_masked_stores(asm["avx512"][name])[:3] for name in NO_K_MASK}
    assert {k: v for k, v in found.items() if v} == {}


def test_the_checks_catch_a_conditional_running_minimum():
    # the detectors themselves: the old form of minwarp_scores' inner loop on AVX2 and AVX-512
    lines = _instructions("vmaskmovps\t%ymm1, %ymm0, (%rdi,%rax,4)\nvmovdqu8\t%ymm2, (%rsi) {%k1}\n")
    assert _avx2_masked_stores(lines) and _k_masked_stores(lines)
    assert not _avx2_masked_stores(_instructions("vpmaskmovq\t-96(%rsi,%r11,8), %ymm1, %ymm3\n"))  # a load
    assert not _k_masked_stores(_instructions("vpscatterqq\t%ymm17, (,%ymm11) {%k1}\n"))
    assert not _packed(_instructions("vpminub\t%xmm1, %xmm2, %xmm3\n"), "vpminub", "avx2")  # 128-bit only
    assert _packed(_instructions("vpminub\t(%rax), %ymm2, %ymm3\n"), "vpminub", "avx2")


def test_explicit_vectors_fill_the_widest_registers(asm):
    """The distance sums are <32 x i16> vectors: one zmm per vector with AVX-512, two ymm with AVX2 (issue 42)."""
    assert _packed(asm["avx512"]["diagonal_distances_u8"], "vpmaxsw", "avx512")
    assert [s for s in asm["avx512"]["diagonal_distances_u8"] if s.startswith("vpmaxsw") and "%zmm" in s]
    assert [s for s in asm["avx2"]["diagonal_distances_u8"] if s.startswith("vpmaxsw") and "%ymm" in s]
    # two instructions per term: the sums hold no absolute value any more (the plain reference kernel does)
    assert not [s for s in asm["avx512"]["diagonal_distances_u8"] if s.startswith("vpabsw") and "%zmm" in s]
