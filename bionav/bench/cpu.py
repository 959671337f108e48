"""The CPU numba compiles for, its vector-width family, and compiling for another CPU.

numba compiles every kernel for one target CPU: the host's (``llvmlite``'s
``get_host_cpu_name`` and its features) unless ``NUMBA_CPU_NAME`` and
``NUMBA_CPU_FEATURES`` name another. The name alone changes nothing in the
generated code (numba then keeps the host's features), so :data:`KNOWN_TARGETS`
gives the feature string of each CPU name ``python -m bionav.bench --cpu-name``
knows. Code compiled for a target runs on any host that has all the target's
features; executing it on a host that lacks one dies with an illegal
instruction, which :func:`missing_host_features` guards against.

Conventions: feature strings are LLVM's (comma-separated ``+name`` / ``-name``,
e.g. ``+avx2``); the vector-width family (:func:`isa_from_features`) is the
widest SIMD extension among the enabled features: ``avx512``, ``avx2``,
``avx``, ``sse``, ``sve``, ``neon`` or ``scalar``.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

_X86_64 = "+64bit,+cmov,+cx8,+fxsr,+mmx,+sse,+sse2"
_X86_64_V2 = _X86_64 + ",+cx16,+popcnt,+sahf,+sse3,+sse4.1,+sse4.2,+ssse3"
#: AVX2 code (issue 27): runs on every AVX2-or-newer x86 CPU
_HASWELL = ("+64bit,+avx,+avx2,+bmi,+bmi2,+cmov,+cx16,+cx8,+f16c,+fma,+fxsr,+lzcnt,+mmx,+movbe,+popcnt,"
            "+sse,+sse2,+sse3,+sse4.1,+sse4.2,+ssse3")
_X86_64_V3 = _X86_64_V2 + ",+avx,+avx2,+bmi,+bmi2,+f16c,+fma,+lzcnt,+movbe,+xsave"
_AVX512 = "+avx512bw,+avx512cd,+avx512dq,+avx512f,+avx512vl"
_SKYLAKE_AVX512 = ("+64bit,+adx,+aes,+avx,+avx2,+avx512bw,+avx512cd,+avx512dq,+avx512f,+avx512vl,+bmi,+bmi2,"
                   "+cmov,+cx16,+cx8,+f16c,+fma,+fsgsbase,+fxsr,+lzcnt,+mmx,+movbe,+pclmul,+popcnt,+prfchw,"
                   "+rdrnd,+rdseed,+sahf,+sse,+sse2,+sse3,+sse4.1,+sse4.2,+ssse3,+xsave")

#: CPU name -> the LLVM feature string numba must be given with it (``NUMBA_CPU_FEATURES``)
KNOWN_TARGETS: dict[str, str] = {
    "x86-64": _X86_64,
    "x86-64-v2": _X86_64_V2,
    "haswell": _HASWELL,
    "x86-64-v3": _X86_64_V3,
    "skylake-avx512": _SKYLAKE_AVX512,
    "x86-64-v4": _X86_64_V3 + "," + _AVX512,
}


def enabled_features(features: str) -> set[str]:
    """The names switched on (``+name``) in an LLVM feature string, without the ``+``."""
    return {f.strip()[1:] for f in features.split(",") if f.strip().startswith("+")}


def isa_from_features(features: str) -> str:
    """Vector-width family of an LLVM feature string: avx512, avx2, avx, sse, sve, neon or scalar."""
    on = enabled_features(features)
    for family, names in (("avx512", ("avx512f",)), ("avx2", ("avx2",)), ("avx", ("avx",)),
                          ("sse", ("sse2", "sse")), ("sve", ("sve",)), ("neon", ("neon", "asimd"))):
        if on.intersection(names):
            return family
    return "scalar"


def host_cpu() -> tuple[str, str]:
    """``(name, feature string)`` of the host CPU as LLVM sees it."""
    import llvmlite.binding as ll

    return ll.get_host_cpu_name(), ll.get_host_cpu_features().flatten()


def numba_target() -> dict:
    """The CPU numba compiles for in this process: ``{"cpu": name, "isa": family}``.

    Honours ``NUMBA_CPU_NAME`` and ``NUMBA_CPU_FEATURES`` as numba does (the
    name alone keeps the host's features).
    """
    from numba.core import config

    name, features = host_cpu()
    if config.CPU_NAME is not None:
        name = config.CPU_NAME
    if config.CPU_FEATURES is not None:
        features = config.CPU_FEATURES
    return {"cpu": name, "isa": isa_from_features(features)}


def missing_host_features(features: str) -> list[str]:
    """Features switched on in ``features`` that this host's CPU lacks (sorted)."""
    import llvmlite.binding as ll

    host = ll.get_host_cpu_features()
    return sorted(f for f in enabled_features(features) if not host.get(f, False))


def unrecognized(name: str, features: str) -> list[str]:
    """The CPU name and features LLVM does not know for this machine's target (sorted; empty if all known).

    LLVM only warns about them on stderr ("'x' is not a recognized processor for this target")
    and then compiles for a generic CPU, which can abort the process later ("LLVM ERROR: 64-bit
    code requested on a subtarget that doesn't support it"); so the name and the features are
    tried here on a target machine, with LLVM's stderr captured, before numba sees them.
    """
    import os
    import re
    import tempfile

    import llvmlite.binding as ll

    ll.initialize_native_target()
    with tempfile.TemporaryFile() as err:
        saved = os.dup(2)
        try:
            os.dup2(err.fileno(), 2)
            ll.Target.from_default_triple().create_target_machine(cpu=name, features=features)
        finally:
            os.dup2(saved, 2)
            os.close(saved)
        err.seek(0)
        text = err.read().decode("utf-8", "replace")
    return sorted(set(re.findall(r"'([^']*)' is not a recognized (?:processor|feature)", text)))


def target_environment(name: str, features: str | None = None, *, cache_root: Path | None = None) -> dict:
    """Environment variables that make numba compile for CPU ``name``.

    Parameters
    ----------
    name : str
        An LLVM CPU name; one of :data:`KNOWN_TARGETS` unless ``features`` is given.
    features : str, optional
        The LLVM feature string; default: that of :data:`KNOWN_TARGETS`.
    cache_root : pathlib.Path, optional
        Parent of the target's own numba cache directory (compiled code of one
        target must not be loaded for another); default ``~/.cache/bionav/numba``
        (``$BIONAV_CACHE/numba`` when set).

    Returns
    -------
    dict
        ``NUMBA_CPU_NAME``, ``NUMBA_CPU_FEATURES`` and ``NUMBA_CACHE_DIR``.

    Raises
    ------
    ValueError
        For an unknown name without ``features``, or an empty feature string.
    """
    if features is None:
        if name not in KNOWN_TARGETS:
            raise ValueError(f"unknown CPU name {name!r}; known: {', '.join(KNOWN_TARGETS)}")
        features = KNOWN_TARGETS[name]
    if not enabled_features(features):
        raise ValueError(f"the feature string {features!r} switches nothing on; give e.g. +sse2,+avx2")
    if cache_root is None:
        from bionav.files import default_cache_dir

        cache_root = default_cache_dir() / "numba"
    digest = hashlib.sha256(f"{name}\n{features}".encode()).hexdigest()[:12]
    return {"NUMBA_CPU_NAME": name, "NUMBA_CPU_FEATURES": features,
            "NUMBA_CACHE_DIR": str(Path(cache_root) / f"{name}-{digest}")}
