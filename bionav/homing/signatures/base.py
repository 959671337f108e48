"""Base class of the ``bionav.signatures`` plugins (thesis 3.5, 5.2)."""

from __future__ import annotations

import dataclasses
from typing import Any, ClassVar

import numpy as np

from bionav.validation import typed_config


def parameters_of(config: Any, config_cls: type) -> Any:
    """The entries of a mapping that are fields of ``config_cls``; ``None`` and instances unchanged.

    Keys that are not fields (a ``name`` or Hydra's ``_target_``, or the parameters of another
    signature in a shared mapping) are left out, as the Python API always did; the command line
    refuses unknown keys before this (:func:`bionav.config.plugin_config`).
    """
    if config is None or dataclasses.is_dataclass(config) or not hasattr(config, "keys"):
        return config
    names = {f.name for f in dataclasses.fields(config_cls)}
    return {k: config[k] for k in config.keys() if k in names}


class Signature:
    """A parameter signature: a compact vector ``f(I)`` describing a panorama.

    Subclasses set ``Config`` (dataclass of parameters: rings ``R``, number of
    Fourier coefficients ``K``, histogram bins ``B`` as relevant), ``name`` (the
    thesis identifier) and ``rotation_invariant``, and implement :meth:`compute`.

    Class attributes
    ----------------
    Config : type
        Dataclass of the signature's parameters.
    name : str
        Thesis identifier, e.g. ``"mffc_phase"``.
    rotation_invariant : bool
        True when ``compute(np.roll(I, m, axis=1))`` equals ``compute(I)``, so
        snapshot and current view need no common orientation.
    uses_raw : bool
        True when :meth:`compute` uses the raw mirror image if one is given.
    """

    Config: ClassVar[type]
    name: ClassVar[str] = ""
    rotation_invariant: ClassVar[bool] = False
    uses_raw: ClassVar[bool] = False

    def __init__(self, config: Any = None) -> None:
        self.config = typed_config(parameters_of(config, self.Config), self.Config, key="signature",
                                   what=f"signature={self.name}")

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.config!r})"

    def compute(self, image: np.ndarray, *, raw: Any = None) -> np.ndarray:
        """Signature vector of one image.

        Parameters
        ----------
        image : ndarray, shape (H, W)
            Canonical unfolded panorama (:mod:`bionav.geometry`).
        raw : optional
            Raw mirror image, used only by signatures with ``uses_raw``.

        Returns
        -------
        ndarray, shape (L,), float64
        """
        raise NotImplementedError

    def derivative(self, image: np.ndarray, direction: np.ndarray, *, step: float = 0.05) -> np.ndarray:
        """Directional derivative ``d/dt f(image + t * direction)`` at ``t = 0``.

        The matched-filter estimator passes the predicted image change of a unit
        move (:func:`bionav.homing.flow_templates.translation_derivatives`) as
        ``direction``. The default is the central difference on the two
        *predicted images* ``image +/- step * direction``::

            (f(image + step * direction) - f(image - step * direction)) / (2 * step)

        (exact for signatures linear in the image; for the others ``step`` is the
        size of the predicted move in units of the assumed landmark distance).
        Signatures with a closed form (appendix C) override this.

        Parameters
        ----------
        image, direction : ndarray, shape (H, W)
        step : float
            Predicted move, > 0.

        Returns
        -------
        ndarray, shape (L,), float64
        """
        img = np.asarray(image, dtype=np.float64)
        d = np.asarray(direction, dtype=np.float64)
        return (self.compute(img + step * d) - self.compute(img - step * d)) / (2.0 * step)


def signature_derivative(signature: Any, image: np.ndarray, direction: np.ndarray, *, step: float = 0.05) -> np.ndarray:
    """``signature.derivative`` when it has one, else the central difference on predicted images.

    Lets third-party signatures that only implement ``compute`` (duck-typed, not
    subclasses of :class:`Signature`) take part in the matched filter.
    """
    method = getattr(signature, "derivative", None)
    if method is not None:
        return method(image, direction, step=step)
    return Signature.derivative(signature, image, direction, step=step)
