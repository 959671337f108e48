"""bionav's built-in ``bionav.signatures`` plugins: the 19 parameter signatures of thesis 3.5.

Selected as ``homing=parameter signature=<name>``. :func:`signature_class`
resolves a name through the plugin registry (the entry points in
pyproject.toml are the one registry).
"""

from __future__ import annotations

from typing import Any

from bionav.errors import PluginError

#: the 19 thesis names, in the order of thesis 3.5 (each is a ``bionav.signatures`` entry point)
SIGNATURE_NAMES: tuple[str, ...] = (
    "cog", "image", "cog_l", "mean", "std", "skew", "kurt", "hist", "ent", "fc", "mean_fft", "std_fft",
    "cog_fft", "fc_abs", "mean_fft_abs", "std_fft_abs", "cog_fft_abs", "mffc_phase", "mffc_abs",
)


def signature_class(name: str) -> type:
    """Signature class registered under ``name`` in the ``bionav.signatures`` entry points.

    Raises
    ------
    PluginError
        If no installed distribution registers ``name``.
    """
    from bionav.registry import load_plugin

    return load_plugin("signature", name)


def builtin_signature_class(name: str) -> type:
    """The class of one of bionav's 19 thesis signatures (:data:`SIGNATURE_NAMES`).

    Raises
    ------
    PluginError
        If ``name`` is not one of :data:`SIGNATURE_NAMES`.
    """
    if name not in SIGNATURE_NAMES:
        raise PluginError(
            f"unknown signature {name!r}. Choose one of: {', '.join(SIGNATURE_NAMES)} "
            f"(e.g. signature=mffc_phase)."
        )
    return signature_class(name)


def make_signature(name: str, config: Any = None):
    """Instantiate signature ``name`` with ``config`` (dataclass, mapping or ``None`` for defaults)."""
    return signature_class(name)(config)
