"""Base class of the ``bionav.signatures`` plugins (thesis 3.5, 5.2)."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np

from bionav.errors import UserError


def coerce_config(config_cls: type, config: Any):
    """Turn ``None``, a mapping (dict, OmegaConf node) or a ``config_cls`` into a ``config_cls``.

    Keys of a mapping that are not fields of ``config_cls`` (e.g. a ``name`` or
    Hydra's ``_target_``) are ignored.
    """
    if config is None:
        return config_cls()
    if isinstance(config, config_cls):
        return config
    if isinstance(config, Mapping) or hasattr(config, "keys"):
        names = {f.name for f in dataclasses.fields(config_cls)}
        return config_cls(**{k: config[k] for k in config.keys() if k in names})
    raise TypeError(f"cannot build {config_cls.__qualname__} from {type(config).__name__}")


def _check_positive(config: Any, owner: str) -> None:
    for name in ("rings", "n_coeffs", "bins"):
        value = getattr(config, name, None)
        if value is not None and (int(value) != value or value < 1):
            raise UserError(
                f"signature.{name}={value!r} is not valid for signature {owner!r}: it must be a "
                f"positive integer. Set signature.{name} to 1 or more."
            )


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
        self.config = coerce_config(self.Config, config)
        _check_positive(self.config, self.name)

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
