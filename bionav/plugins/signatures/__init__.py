"""bionav's built-in ``bionav.signatures`` plugins: the 19 parameter signatures of thesis 3.5.

Selected as ``homing=parameter signature=<name>``. :func:`signature_class`
resolves a name through the plugin registry when it is available and falls
back to the built-in table below, so the homing plugin works on its own.
"""

from __future__ import annotations

import importlib
from typing import Any

from bionav.errors import PluginError

#: thesis name -> "module:Class" of bionav's built-in signatures (same as the pyproject entry points)
BUILTIN_SIGNATURES: tuple[tuple[str, str], ...] = (
    ("cog", "bionav.plugins.signatures.cog:Cog"),
    ("image", "bionav.plugins.signatures.image:Image"),
    ("cog_l", "bionav.plugins.signatures.cog:CogL"),
    ("mean", "bionav.plugins.signatures.statistics:Mean"),
    ("std", "bionav.plugins.signatures.statistics:Std"),
    ("skew", "bionav.plugins.signatures.statistics:Skew"),
    ("kurt", "bionav.plugins.signatures.statistics:Kurt"),
    ("hist", "bionav.plugins.signatures.histogram:Hist"),
    ("ent", "bionav.plugins.signatures.histogram:Ent"),
    ("fc", "bionav.plugins.signatures.fourier:Fc"),
    ("mean_fft", "bionav.plugins.signatures.fourier:MeanFft"),
    ("std_fft", "bionav.plugins.signatures.fourier:StdFft"),
    ("cog_fft", "bionav.plugins.signatures.fourier:CogFft"),
    ("fc_abs", "bionav.plugins.signatures.fourier:FcAbs"),
    ("mean_fft_abs", "bionav.plugins.signatures.fourier:MeanFftAbs"),
    ("std_fft_abs", "bionav.plugins.signatures.fourier:StdFftAbs"),
    ("cog_fft_abs", "bionav.plugins.signatures.fourier:CogFftAbs"),
    ("mffc_phase", "bionav.plugins.signatures.fourier:MffcPhase"),
    ("mffc_abs", "bionav.plugins.signatures.fourier:MffcAbs"),
)

#: the 19 thesis names, in the order of thesis 3.5
SIGNATURE_NAMES: tuple[str, ...] = tuple(name for name, _ in BUILTIN_SIGNATURES)


def builtin_signature_class(name: str) -> type:
    """The built-in signature class registered under ``name``.

    Raises
    ------
    PluginError
        If ``name`` is not one of :data:`SIGNATURE_NAMES`.
    """
    target = dict(BUILTIN_SIGNATURES).get(name)
    if target is None:
        raise PluginError(
            f"unknown signature {name!r}. Choose one of: {', '.join(SIGNATURE_NAMES)} "
            f"(e.g. signature=mffc_phase)."
        )
    module, cls = target.split(":")
    return getattr(importlib.import_module(module), cls)


def signature_class(name: str) -> type:
    """Signature class for ``name``: from the plugin registry, else bionav's built-in table.

    The built-in table is the fallback for names the registry does not know
    (bionav used from a source tree without installed entry points).

    Raises
    ------
    PluginError
        If neither the registry nor the built-in table knows ``name``.
    """
    from bionav.registry import load_plugin

    try:
        return load_plugin("signature", name)
    except PluginError:
        if name not in SIGNATURE_NAMES:
            raise
        return builtin_signature_class(name)


def make_signature(name: str, config: Any = None):
    """Instantiate signature ``name`` with ``config`` (dataclass, mapping or ``None`` for defaults)."""
    return signature_class(name)(config)
