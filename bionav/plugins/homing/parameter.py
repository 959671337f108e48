"""``homing=parameter``: homing by descent in a parameter-signature potential (thesis 5.2).

Select the signature with ``signature=<name>`` (the 19 thesis names, e.g.
``mffc_phase``) and the gradient estimator with ``homing.gradient``. See
:mod:`bionav.homing.parameter` for the algorithms and
:mod:`bionav.plugins.signatures` for the signatures.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, Mapping, Optional

import numpy as np

from bionav.geometry import PanoramaGeometry
from bionav.homing.base import HomeVector, HomingMethod
from bionav.validation import bounded

GRADIENTS = ("auto", "test_steps", "matched_filter")


@dataclass
class Config:
    """Parameters of ``homing=parameter``.

    signature : thesis name of the parameter signature, used when the caller
        does not pass a signature instance (the command line's ``signature=``
        group does).
    gradient : ``test_steps`` (eq. 5.19: potentials at the neighbouring grid
        images), ``matched_filter`` (Möller & Vardy 2006: predicted images, no
        test steps; closed forms C.9/C.11 for [mffc_phase]/[mffc_abs]), or
        ``auto`` = the thesis' protocol: ``matched_filter`` for the ``mffc_*``
        signatures and ``test_steps`` for all others.
    rings, n_coeffs, bins : when set, override the signature's parameter of the
        same name (``None`` keeps the signature's own config); ignored by
        signatures without that parameter, so one value can be given to a
        sweep over several signatures.
    mf_step : size of the predicted move of the matched filter's finite
        differences, in units of the assumed (equal) landmark distance; used by
        signatures without a closed-form derivative.
    """

    signature: str = "mffc_phase"
    gradient: str = bounded("auto", choices=("auto", "test_steps", "matched_filter"))
    rings: Optional[int] = bounded(None, ge=1, le=1000)
    n_coeffs: Optional[int] = bounded(None, ge=1, le=1000)
    bins: Optional[int] = bounded(None, ge=2, le=4096)
    mf_step: float = bounded(0.05, gt=0.0, le=1.0)


def _to_gray(image: np.ndarray) -> np.ndarray:
    img = np.asarray(image, dtype=np.float64)
    return img.mean(axis=2) if img.ndim == 3 else img


class ParameterHoming(HomingMethod):
    """Parameter homing with one of the 19 signatures of thesis 3.5.

    Parameters
    ----------
    config : Config, mapping or None
        :class:`Config` (a mapping such as an OmegaConf node is accepted).
    geometry : PanoramaGeometry
        Geometry of the images passed to :meth:`prepare` (the matched filter's
        flow templates need azimuth and elevation of every pixel).
    signature : Signature or mapping, optional
        A signature instance (e.g. built from the ``signature=`` config group;
        anything with ``compute(image, *, raw=None)``, ``rotation_invariant``
        and a ``config`` dataclass);
        or a mapping of parameters for the signature named by ``config.signature``;
        or ``None`` for that signature with its defaults. The signature class is
        resolved by :func:`bionav.plugins.signatures.signature_class`.

    Notes
    -----
    * Signatures are computed once per image in :meth:`prepare`; with the
      matched filter, ``prepare`` also stores the signature's derivatives for
      unit moves along ``x`` and ``y`` of that image, so :meth:`home_vector` is
      only vector arithmetic.
    * Home vectors are in the current view's own frame: the test-step offsets
      and the flow templates are both expressed in it. A rotation-invariant
      signature therefore needs no aligned views (``requires_alignment`` is
      False); the others do.
    * The matched filter ignores raw mirror images (predicted images only exist
      as unfolded panoramas), so [cog]/[cog_l] then use their synthetic mirror image throughout.
    * Colour images are averaged over their channels.
    """

    Config = Config
    requires_alignment = True
    uses_test_steps = True

    def __init__(self, config: Any = None, *, geometry: PanoramaGeometry, signature: Any = None) -> None:
        from bionav.homing.signatures.base import parameters_of
        from bionav.plugins.signatures import signature_class
        from bionav.validation import typed_config

        config = typed_config(parameters_of(config, Config), Config, key="homing", what="homing=parameter")
        super().__init__(config, geometry=geometry)
        if not hasattr(signature, "compute"):  # a mapping of parameters, or None
            signature = signature_class(config.signature)(signature)
        names = {f.name for f in dataclasses.fields(signature.config)}
        overrides = {
            k: getattr(config, k) for k in ("rings", "n_coeffs", "bins") if getattr(config, k) is not None and k in names
        }
        if overrides:
            signature = type(signature)(dataclasses.replace(signature.config, **overrides))
        self.signature = signature
        self.signature_name = str(getattr(signature, "name", "") or type(signature).__name__)
        gradient = config.gradient
        if gradient == "auto":
            gradient = "matched_filter" if self.signature_name.startswith("mffc") else "test_steps"
        self.gradient = gradient
        self.uses_test_steps = gradient == "test_steps"
        self.requires_alignment = not bool(getattr(signature, "rotation_invariant", False))

    def prepare(self, image: np.ndarray, *, raw: Any = None) -> dict[str, np.ndarray]:
        """Signature of one image (and, for the matched filter, its derivatives).

        Parameters
        ----------
        image : ndarray, shape (H, W) or (H, W, C)
            Canonical panorama matching ``geometry``.
        raw : optional
            Raw mirror image for signatures computed on it ([cog], [cog_l]);
            ignored by the matched filter.

        Returns
        -------
        dict
            ``f``: signature, shape (L,); with the matched filter also ``df_dx``,
            ``df_dy``: its derivatives for unit moves (equal distance 1) along the
            current view's ``x`` and ``y``.
        """
        img = _to_gray(image)
        if self.gradient == "test_steps":
            return {"f": self.signature.compute(img, raw=raw)}
        from bionav.homing.flow_templates import translation_derivatives
        from bionav.homing.signatures.base import signature_derivative

        geometry = self.geometry
        if (geometry.height, geometry.width) != img.shape:
            geometry = geometry.resized(img.shape[1], img.shape[0])
        phi, psi = translation_derivatives(img, geometry=geometry)
        step = self.config.mf_step
        return {
            "f": self.signature.compute(img),
            "df_dx": signature_derivative(self.signature, img, phi, step=step),
            "df_dy": signature_derivative(self.signature, img, psi, step=step),
        }

    def home_vector(
        self,
        snapshot: Mapping[str, np.ndarray],
        current: Mapping[str, np.ndarray],
        *,
        neighbours: Mapping[tuple[int, int], Mapping[str, np.ndarray]] | None = None,
    ) -> HomeVector:
        """Negative potential gradient at the current view (eqs. 5.18, 5.19 or C.9/C.11).

        Parameters
        ----------
        snapshot, current : dict
            Results of :meth:`prepare`.
        neighbours : mapping, optional
            Test steps only: prepared images of the current position's grid
            neighbours keyed by ``(dx, dy)`` in the current view's frame.
            Central differences where both neighbours along an axis exist,
            one-sided ones otherwise (:func:`bionav.homing.parameter.gradient_from_test_steps`).

        Returns
        -------
        HomeVector
            ``angle`` in radians CCW in the current view's frame; NaN when the
            gradient vanishes or no test step is available. ``extras``: the
            potential ``p`` at the current view.
        """
        from bionav.homing import parameter as ph

        fs, fc = snapshot["f"], current["f"]
        p0 = ph.parameter_potential(fs, fc)
        if self.gradient == "test_steps":
            if not neighbours:
                return HomeVector(angle=math.nan, extras={"potential": p0, "reason": "no test steps"})
            pots = {d: ph.parameter_potential(fs, n["f"]) for d, n in neighbours.items()}
            grad = ph.gradient_from_test_steps(p0, pots)
        else:
            grad = ph.matched_filter_gradient(fs, fc, current["df_dx"], current["df_dy"])
        hx, hy = -grad
        if not (np.isfinite(hx) and np.isfinite(hy)) or (hx == 0.0 and hy == 0.0):
            return HomeVector(angle=math.nan, extras={"potential": p0})
        return HomeVector(angle=float(math.atan2(hy, hx)), extras={"potential": p0})

    def all_pairs_angles(self, prepared, *, headings: np.ndarray, neighbours: np.ndarray) -> np.ndarray:
        """Grid-frame home angles of all pairs from matrix operations on the prepared signatures.

        The same angles as :meth:`home_vector` pair by pair (see
        :meth:`bionav.homing.base.HomingMethod.all_pairs_angles`). The test
        steps are the four grid neighbours, so their gradient is in the grid
        frame; the matched filter's gradient is in the current view's frame and
        is turned by the current view's heading. (For rotated current views this
        equals the per-pair call with the neighbour offsets expressed in the
        current view's frame.)
        """
        from bionav.homing import parameter as ph

        f = np.stack([p["f"] for p in prepared])
        if self.gradient == "test_steps":
            grad = ph.gradient_matrix_from_test_steps(ph.potential_matrix(f, f), neighbours)
        else:
            dfx = np.stack([p["df_dx"] for p in prepared])
            dfy = np.stack([p["df_dy"] for p in prepared])
            grad = ph.matched_filter_gradient_matrix(f, f, dfx, dfy)
        return self._grid_angles(grad, headings)

    def all_pairs_angles_by_coefficients(
        self, prepared, *, n_coeffs, image_shape, headings: np.ndarray, neighbours: np.ndarray
    ) -> np.ndarray:
        """:meth:`all_pairs_angles` for several numbers ``K`` of Fourier coefficients at once.

        ``prepared`` holds the images prepared with this method's signature,
        whose ``n_coeffs`` must be at least ``max(n_coeffs)``; the signature
        must have ``coefficient_index`` (the DFT signatures). Potentials or
        matched-filter gradients for every ``K`` are partial sums over the
        coefficients (:func:`bionav.homing.parameter.potential_matrices_by_coefficients`),
        equal to those of signatures with ``n_coeffs=K`` up to float rounding.

        Parameters
        ----------
        prepared : list of dict
        n_coeffs : sequence of int, shape (N,)
        image_shape : (H, W)
            Shape of the prepared (grey) images.
        headings, neighbours : ndarray
            As in :meth:`all_pairs_angles`.

        Returns
        -------
        ndarray, shape (N, S, C)
            Grid-frame home angles, radians; NaN where none.
        """
        from bionav.homing import parameter as ph

        kidx = self.signature.coefficient_index(tuple(image_shape))
        f = np.stack([p["f"] for p in prepared])
        if self.gradient == "test_steps":
            pots = ph.potential_matrices_by_coefficients(f, f, kidx, n_coeffs)
            grad = ph.gradient_matrix_from_test_steps(pots, neighbours)
        else:
            dfx = np.stack([p["df_dx"] for p in prepared])
            dfy = np.stack([p["df_dy"] for p in prepared])
            grad = ph.matched_filter_gradient_matrices_by_coefficients(f, f, dfx, dfy, kidx, n_coeffs)
        return self._grid_angles(grad, headings)

    def _grid_angles(self, grad: np.ndarray, headings: np.ndarray) -> np.ndarray:
        """Home angles (grid frame, wrapped) from potential gradients of shape (..., S, C, 2)."""
        from bionav.geometry import wrap_angle

        hx, hy = -grad[..., 0], -grad[..., 1]
        with np.errstate(invalid="ignore"):
            angles = np.arctan2(hy, hx)
        angles[(hx == 0) & (hy == 0)] = np.nan
        angles[~(np.isfinite(hx) & np.isfinite(hy))] = np.nan
        if self.gradient != "test_steps":
            # flow templates live in the current view's own frame
            angles = angles + np.asarray(headings)
        return wrap_angle(angles)
