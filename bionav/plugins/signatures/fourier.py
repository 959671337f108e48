"""DFT signatures (thesis 3.5.3 and 3.5.4, eqs. 3.55-3.62).

``n_coeffs`` ``K`` keeps the coefficients ``k = 0 .. K-1`` of the 1-D DFT along
the columns. With phase ([fc] [mean_fft] [std_fft] [cog_fft]) a coefficient
contributes its real and imaginary part; without phase (``*_abs``) its
amplitude, which makes the signature rotation invariant. See
:mod:`bionav.homing.signatures.fourier` for the documented choices.

Reading of the thesis' definitions:

* [fc] (eq. 3.55) and [fc_abs] (eq. 3.59): "the DFT is applied line-by-line"
  (3.5), so they hold the first ``K`` coefficients of *every row*: ``2 H K``
  and ``H K`` values. (Eq. 3.59 writes ``F_k(mu)`` on the left but sums the row
  ``I_i`` on the right; the right-hand side is used.)
* [mean_fft], [std_fft], [cog_fft] and their ``_abs`` versions transform one
  per-column profile (eqs. 3.56-3.58, 3.60-3.62): ``2 K`` resp. ``K`` values.
  (The thesis' heading writes ``[mean_ft]``; the tables use ``[mean_fft]``.)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.homing.signatures.base import Signature
from bionav.validation import bounded


@dataclass
class FourierConfig:
    """Parameters of the DFT signatures.

    n_coeffs : number of Fourier coefficients ``K`` (``k = 0 .. K-1``; thesis
        sweep: 1-20, 25, 30, 35, 40; its best results use 4-20).
    """

    n_coeffs: int = bounded(8, ge=1, le=1000)


def _coefficient_index(n_coeffs: int, repeats: int) -> np.ndarray:
    return np.tile(np.arange(int(n_coeffs)), int(repeats))


class _RowSpectrum(Signature):
    Config = FourierConfig
    #: blocks of ``H K`` entries per row spectrum: 2 (real, imaginary) or 1 (amplitudes)
    parts = 2

    def spectrum(self, image) -> np.ndarray:
        from bionav.homing.signatures.fourier import row_spectrum

        return row_spectrum(image, n_coeffs=self.config.n_coeffs)

    def coefficient_index(self, image_shape) -> np.ndarray:
        """Coefficient ``k`` of every entry of :meth:`compute` (and :meth:`derivative`) for images of ``(H, W)``.

        The signature with ``K`` coefficients is the one with more coefficients
        restricted to the entries with ``k < K``, in the same order, which lets
        a sweep over ``K`` compute it once (partial sums over ``k``).

        Returns
        -------
        ndarray of int, shape (L,)
        """
        return _coefficient_index(self.config.n_coeffs, self.parts * int(image_shape[0]))


class Fc(_RowSpectrum):
    """[fc]: real and imaginary parts of ``F_0 .. F_{K-1}`` of every row; shape ``(2 H K,)``."""

    name = "fc"
    rotation_invariant = False

    def compute(self, image, *, raw=None) -> np.ndarray:
        from bionav.homing.signatures.fourier import complex_to_real

        return complex_to_real(self.spectrum(image))


class FcAbs(_RowSpectrum):
    """[fc_abs]: amplitudes ``|F_0| .. |F_{K-1}|`` of every row; shape ``(H K,)``; rotation invariant."""

    name = "fc_abs"
    rotation_invariant = True
    parts = 1

    def compute(self, image, *, raw=None) -> np.ndarray:
        return np.abs(self.spectrum(image)).ravel()


class _Profile(Signature):
    Config = FourierConfig
    profile_name = ""
    with_phase = True

    def compute(self, image, *, raw=None) -> np.ndarray:
        from bionav.homing.signatures import fourier

        z = fourier.profile_spectrum(getattr(fourier, self.profile_name)(image), n_coeffs=self.config.n_coeffs)
        return fourier.complex_to_real(z) if self.with_phase else np.abs(z)

    def coefficient_index(self, image_shape) -> np.ndarray:
        """Coefficient ``k`` of every entry of :meth:`compute` (see :meth:`Fc.coefficient_index`); shape ``(L,)``."""
        return _coefficient_index(self.config.n_coeffs, 2 if self.with_phase else 1)


class MeanFft(_Profile):
    """[mean_fft]: DFT of the column averages with phase (eq. 3.56); shape ``(2 K,)``."""

    name = "mean_fft"
    profile_name = "column_mean"
    rotation_invariant = False


class StdFft(_Profile):
    """[std_fft]: DFT of the column standard deviations with phase (eq. 3.57); shape ``(2 K,)``."""

    name = "std_fft"
    profile_name = "column_std"
    rotation_invariant = False


class CogFft(_Profile):
    """[cog_fft]: DFT of the column centres of gravity with phase (eq. 3.58); shape ``(2 K,)``."""

    name = "cog_fft"
    profile_name = "column_cog"
    rotation_invariant = False


class MeanFftAbs(_Profile):
    """[mean_fft_abs]: amplitude spectrum of the column averages (eq. 3.60); shape ``(K,)``."""

    name = "mean_fft_abs"
    profile_name = "column_mean"
    with_phase = False
    rotation_invariant = True


class StdFftAbs(_Profile):
    """[std_fft_abs]: amplitude spectrum of the column standard deviations (eq. 3.61); shape ``(K,)``."""

    name = "std_fft_abs"
    profile_name = "column_std"
    with_phase = False
    rotation_invariant = True


class CogFftAbs(_Profile):
    """[cog_fft_abs]: amplitude spectrum of the column centres of gravity (eq. 3.62); shape ``(K,)``."""

    name = "cog_fft_abs"
    profile_name = "column_cog"
    with_phase = False
    rotation_invariant = True


class MffcPhase(Fc):
    """[mffc_phase]: matched-filter Fourier coefficients with phase (thesis appendix C.1).

    The same vector as [fc] (real and imaginary parts of the first ``K``
    coefficients of every row, potential eq. C.2); with
    ``homing.gradient=matched_filter`` its derivative is the closed form of
    eqs. C.5-C.9: the DFT of the flow-template image derivative,
    ``F_k(Phi_j)``, instead of a finite difference.
    """

    name = "mffc_phase"

    def derivative(self, image, direction, *, step: float = 0.05) -> np.ndarray:
        """Closed form (eq. C.5): ``[Re F_k(direction_j), Im F_k(direction_j)]``; ``step`` is unused."""
        from bionav.homing.signatures.fourier import complex_to_real, row_spectrum

        return complex_to_real(row_spectrum(direction, n_coeffs=self.config.n_coeffs))


class MffcAbs(FcAbs):
    """[mffc_abs]: matched-filter Fourier amplitudes (Möller & Vardy 2006; thesis appendix C.2).

    The same vector as [fc_abs] (potential eq. C.10); rotation invariant. Its
    derivative is the closed form behind eq. C.11::

        d|F_k(C_j)| = (Re F_k(Phi_j) Re F_k(C_j) + Im F_k(Phi_j) Im F_k(C_j)) / |F_k(C_j)|

    and 0 where ``|F_k(C_j)| = 0`` (the amplitude is not differentiable there).
    """

    name = "mffc_abs"

    def derivative(self, image, direction, *, step: float = 0.05) -> np.ndarray:
        """Closed form of eq. C.11 (``A_jk / |F_k(C_j)|``); ``step`` is unused."""
        from bionav.homing.signatures.fourier import row_spectrum

        fc = self.spectrum(image)
        fd = row_spectrum(direction, n_coeffs=self.config.n_coeffs)
        amp = np.abs(fc)
        a = fd.real * fc.real + fd.imag * fc.imag
        return np.divide(a, amp, out=np.zeros_like(a), where=amp > 0).ravel()
