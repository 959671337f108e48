"""The five spectral channels of the hand-held sensor and the features built from them.

Thesis 6.1, table 6.1 (Kollmeier et al. 2007): UV 350 nm, B 440 nm, G 500 nm,
R 680 nm, IR 800 nm peak sensitivity, with the listed 50 %-to-50 % bandwidths.
The measured filter curves (fig. 6.2) are not published as data; bionav models
each channel as a Gaussian with the table's peak and full width at half
maximum, which reproduces the peak and the bandwidth of table 6.1.

Features (thesis 6.2.2, table 6.2): every single channel (1-D), every
dual-channel pair (2-D, named ``"UV-B"`` etc. with the shorter wavelength
first) and all five channels (``"all"``), 16 features in the thesis' order.
"""

from __future__ import annotations

from itertools import combinations

import numpy as np

#: Channel names in order of wavelength.
CHANNELS: tuple[str, ...] = ("UV", "B", "G", "R", "IR")
#: Peak sensitivity of each channel in nm (table 6.1).
PEAK_NM: tuple[float, ...] = (350.0, 440.0, 500.0, 680.0, 800.0)
#: Bandwidth (50 % to 50 % sensitivity) of each channel in nm (table 6.1).
FWHM_NM: tuple[float, ...] = (50.0, 80.0, 70.0, 90.0, 200.0)
#: Wavelength grid (nm) on which spectra are integrated: the photodiode's range.
WAVELENGTHS_NM: np.ndarray = np.arange(300.0, 1101.0, 5.0)
WAVELENGTHS_NM.setflags(write=False)


def band_sensitivity(wavelengths_nm=WAVELENGTHS_NM) -> np.ndarray:
    """Relative spectral sensitivity of the five channels.

    Parameters
    ----------
    wavelengths_nm : array_like, shape (L,)
        Wavelengths in nm.

    Returns
    -------
    ndarray, shape (5, L)
        Gaussian sensitivity per channel (rows in :data:`CHANNELS` order),
        normalised to a maximum of 1 (as fig. 6.2).
    """
    wl = np.asarray(wavelengths_nm, dtype=float)
    peak = np.asarray(PEAK_NM)[:, None]
    sd = np.asarray(FWHM_NM)[:, None] / (2.0 * np.sqrt(2.0 * np.log(2.0)))
    return np.exp(-0.5 * ((wl[None, :] - peak) / sd) ** 2)


def band_integrate(spectrum, wavelengths_nm=WAVELENGTHS_NM) -> np.ndarray:
    """Channel signals of spectra: ``int S_b(lambda) L(lambda) dlambda``.

    Parameters
    ----------
    spectrum : array_like, shape (..., L)
        Spectral radiance or irradiance sampled at ``wavelengths_nm`` (any unit
        per nm).
    wavelengths_nm : array_like, shape (L,)
        Uniformly spaced wavelengths in nm.

    Returns
    -------
    ndarray, shape (..., 5)
        Signal per channel in the spectrum's unit times nm.
    """
    wl = np.asarray(wavelengths_nm, dtype=float)
    step = float(wl[1] - wl[0])
    return np.asarray(spectrum, dtype=float) @ band_sensitivity(wl).T * step


def feature_subsets() -> dict[str, tuple[int, ...]]:
    """The 16 features of tables 6.2/6.4 as channel-index tuples.

    Returns
    -------
    dict
        ``{"UV": (0,), ..., "IR": (4,), "UV-B": (0, 1), ..., "R-IR": (3, 4),
        "all": (0, 1, 2, 3, 4)}`` in this order.
    """
    out = {name: (i,) for i, name in enumerate(CHANNELS)}
    for i, j in combinations(range(len(CHANNELS)), 2):
        out[f"{CHANNELS[i]}-{CHANNELS[j]}"] = (i, j)
    out["all"] = tuple(range(len(CHANNELS)))
    return out


def dual_contrasts() -> dict[str, tuple[int, int]]:
    """The ten dual-channel contrasts ``"UV-B" -> (0, 1)`` (contrast = first minus second log signal)."""
    return {k: v for k, v in feature_subsets().items() if len(v) == 2}
