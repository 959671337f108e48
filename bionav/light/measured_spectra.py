"""Measured spectra shipped with bionav (``bionav/data/spectra``), resampled onto any wavelength grid.

Sources (provenance and licences in ``bionav/data/spectra/README.md``; the
files are rebuilt by ``scripts/make_spectra_data.py``):

* **Sun**: ASTM G173-03 extraterrestrial spectrum (NREL, from SMARTS 2.9.2;
  Gueymard 2004, doi:10.1016/j.solener.2003.08.039), 280-1200 nm.
* **Gas absorption**: ozone, water-vapour and mixed-gas coefficients of Bird &
  Riordan (1986), J. Clim. Appl. Meteorol. 25, 87-97,
  doi:10.1175/1520-0450(1986)025<0087:SSSMFD>2.0.CO;2 (ozone: Huggins band below
  340 nm, Chappuis band 450-750 nm with its maximum near 600 nm; water vapour at
  720, 820 and 940 nm; the oxygen A band at 760 nm).
* **Petals**: 120 reflectance spectra 300-700 nm of alpine flowers (Gentiana,
  Primula, Rhododendron, Silene), and a green-leaf background reflectance
  300-700 nm, from the bumbleview package 0.2.8 (T. M. Huber, MIT licence).
* **D65**: CIE standard illuminant D65 (relative), as shipped by bumbleview.

Resampling: the finely sampled sun (0.5-1 nm) is averaged over each target
cell (``lambda +- step / 2``, :func:`cell_mean`), so its Fraunhofer lines are
averaged rather than aliased; the 5-nm reflectance tables (the petals already
averaged into 5-nm bins) and the coarse ozone table are interpolated linearly.
Outside a table's range the functions say what they do (their ``Notes``).
"""

from __future__ import annotations

import csv
from functools import lru_cache

import numpy as np

from bionav.data import data_path
from bionav.errors import UserError


@lru_cache(maxsize=None)
def _table(name: str) -> tuple[tuple[str, ...], np.ndarray]:
    path = data_path("spectra", name)
    try:
        with open(path, newline="") as fh:
            rows = [r for r in csv.reader(line for line in fh if not line.startswith("#")) if r]
        header = tuple(rows[0])
        values = np.array([[float(v) for v in r] for r in rows[1:]])
    except (OSError, ValueError, IndexError) as exc:
        raise UserError(f"bionav's spectral table {path} is missing or unreadable ({exc}); reinstall bionav "
                        f"(pip install --force-reinstall bionav) or rebuild it with scripts/make_spectra_data.py.") from exc
    values.setflags(write=False)
    return header, values


def cell_mean(src_wl, src_values, wavelengths_nm) -> np.ndarray:
    """Mean of a piecewise-linear spectrum over the cells of a uniform target grid.

    Parameters
    ----------
    src_wl : array_like, shape (S,)
        Increasing source wavelengths, nm.
    src_values : array_like, shape (S, ...)
        Source values.
    wavelengths_nm : array_like, shape (L,)
        Target wavelengths (cell centres), nm; uniformly spaced (a single
        wavelength is a cell of width zero: plain linear interpolation).

    Returns
    -------
    ndarray, shape (L, ...)
        Cell means; targets outside ``[src_wl[0], src_wl[-1]]`` hold the end values.
    """
    x = np.asarray(src_wl, dtype=float)
    y = np.asarray(src_values, dtype=float).reshape(len(x), -1)
    wl = np.asarray(wavelengths_nm, dtype=float)
    half = 0.5 * float(wl[1] - wl[0]) if wl.size > 1 else 0.0
    if half <= 0:
        return np.stack([np.interp(wl, x, col) for col in y.T], axis=-1).reshape(wl.shape + np.shape(src_values)[1:])
    # cumulative integral of the piecewise-linear source, extended flat beyond its ends
    xe = np.r_[x[0] - 1e6, x, x[-1] + 1e6]
    ye = np.vstack([y[:1], y, y[-1:]])
    cum = np.vstack([np.zeros((1, y.shape[1])), np.cumsum(0.5 * (ye[1:] + ye[:-1]) * np.diff(xe)[:, None], axis=0)])

    def integral(at):
        i = np.clip(np.searchsorted(xe, at, side="right") - 1, 0, len(xe) - 2)
        dx = at - xe[i]
        slope = (ye[i + 1] - ye[i]) / (xe[i + 1] - xe[i])[:, None]
        return cum[i] + ye[i] * dx[:, None] + 0.5 * slope * dx[:, None] ** 2

    out = (integral(wl + half) - integral(wl - half)) / (2 * half)
    return out.reshape(wl.shape + np.shape(src_values)[1:])


def extraterrestrial_solar_spectrum(wavelengths_nm) -> np.ndarray:
    """ASTM G173-03 extraterrestrial solar spectral irradiance, W m^-2 nm^-1, shape ``(L,)``.

    Notes
    -----
    The table covers 280-1200 nm; outside it the function returns NaN (the
    caller decides how to continue; :func:`bionav.light.daylight.solar_spectrum`
    uses a black body there).
    """
    _, v = _table("astm_g173.csv")
    wl = np.asarray(wavelengths_nm, dtype=float)
    out = cell_mean(v[:, 0], v[:, 1], wl)
    return np.where((wl >= v[0, 0]) & (wl <= v[-1, 0]), out, np.nan)


def astm_g173(wavelengths_nm) -> dict[str, np.ndarray]:
    """All three ASTM G173-03 spectra (``extraterrestrial``, ``global_tilt``, ``direct_circumsolar``), W m^-2 nm^-1.

    ``global_tilt`` is the irradiance on a plane tilted 37 degrees towards the
    sun at air mass 1.5 (sun 41.8 degrees high), ozone 0.34 atm-cm, Angstrom
    beta 0.084 at 1 micrometre (the standard's conditions). NaN outside 280-1200 nm.
    """
    header, v = _table("astm_g173.csv")
    wl = np.asarray(wavelengths_nm, dtype=float)
    inside = (wl >= v[0, 0]) & (wl <= v[-1, 0])
    return {name: np.where(inside, cell_mean(v[:, 0], v[:, k], wl), np.nan) for k, name in enumerate(header) if k}


def gas_absorption(wavelengths_nm) -> dict[str, np.ndarray]:
    """Absorption coefficients of ozone, water vapour and mixed gases (Bird & Riordan 1986), each ``(L,)``.

    Returns
    -------
    dict
        ``ozone`` (1/cm of an ozone column in atm-cm; optical depth = coefficient x column, about
        0.3 atm-cm at mid latitudes), ``water_vapor`` (1/cm of precipitable water) and
        ``mixed_gases`` (O2, CO2; per air mass) -- the last two enter Bird & Riordan's
        non-exponential transmittance laws (:func:`bionav.light.daylight.gas_transmittance`).

    Notes
    -----
    Linear interpolation of the table (sampled every 5-25 nm; the narrow water and
    oxygen lines are thus smoothed as in the original model); zero above 1200 nm;
    below 300 nm the 300 nm values (an underestimate of the Hartley band, where the
    UV channel's sensitivity is below 1 %).
    """
    header, v = _table("bird_riordan_absorption.csv")
    wl = np.asarray(wavelengths_nm, dtype=float)
    return {name: np.where(wl > v[-1, 0], 0.0, np.interp(wl, v[:, 0], v[:, k]))
            for k, name in enumerate(header) if k}


#: Red edge of green leaves beyond the measured 700 nm (see :func:`green_leaf_reflectance`).
LEAF_RED_EDGE_NM = 720.0
LEAF_RED_EDGE_WIDTH_NM = 10.0
LEAF_NIR_PLATEAU = 0.48


def green_leaf_reflectance(wavelengths_nm) -> np.ndarray:
    """Green-leaf reflectance (fraction), shape ``(L,)``: measured 300-700 nm, red edge modelled beyond.

    Notes
    -----
    bumbleview's green-leaf background is measured from 300 to 700 nm (its rows
    705-750 nm are zero padding, not data). Beyond 700 nm the reflectance
    follows a logistic red edge with inflection at :data:`LEAF_RED_EDGE_NM`
    (720 nm; healthy leaves 715-725 nm, Horler et al. 1983,
    doi:10.1080/01431168308948546) and scale :data:`LEAF_RED_EDGE_WIDTH_NM`,
    joined continuously to the measured 700 nm value and rising to the
    near-infrared plateau :data:`LEAF_NIR_PLATEAU` (0.48; fresh leaves 0.45-0.55
    at 800 nm, Gates et al. 1965, doi:10.1364/AO.4.000011), held to 1100 nm
    (the plateau extends to about 1300 nm). Below 300 nm: the 300 nm value.
    """
    _, v = _table("green_leaf.csv")
    wl = np.asarray(wavelengths_nm, dtype=float)
    end = v[-1, 0]
    measured = np.interp(wl, v[:, 0], v[:, 1])
    r_end = float(v[-1, 1])

    def s(x):
        return 1.0 / (1.0 + np.exp(-(x - LEAF_RED_EDGE_NM) / LEAF_RED_EDGE_WIDTH_NM))

    edge = r_end + (LEAF_NIR_PLATEAU - r_end) * (s(wl) - s(end)) / (1.0 - s(end))
    return np.where(wl <= end, measured, edge)


def petal_reflectances(wavelengths_nm) -> tuple[list[str], np.ndarray]:
    """The 120 measured petal reflectances (fraction), shape ``(120, L)``, and their names.

    Notes
    -----
    Measured 300-700 nm (5-nm bin means of bumbleview's ~0.4 nm samples,
    interpolated linearly; measurement noise can make single bins slightly
    negative, they are clipped at 0.005). Beyond 700 nm each spectrum holds the mean of its 690-700 nm
    bins: petal pigments (anthocyanins, carotenoids, flavonoids) absorb below
    about 650 nm, so the 700 nm value is the pigment-free scattering of the
    petal tissue that continues into the near infrared (an assumption: petals
    have no red edge of their own, and real petals are often brighter still
    beyond 750 nm). Below 300 nm: the 300 nm value.
    """
    header, v = _table("petals.csv")
    wl = np.asarray(wavelengths_nm, dtype=float)
    end = v[-1, 0]
    measured = np.stack([np.interp(wl, v[:, 0], col) for col in v[:, 1:].T], axis=-1)
    tail = v[v[:, 0] >= end - 10.0, 1:].mean(axis=0)
    out = np.where((wl <= end)[:, None], measured, tail[None, :])
    return list(header[1:]), np.clip(out.T, 0.005, 1.0)


def d65(wavelengths_nm) -> np.ndarray:
    """CIE D65 relative spectral power (100 at 560 nm), shape ``(L,)``; NaN outside the table (300-750 nm)."""
    _, v = _table("d65.csv")
    wl = np.asarray(wavelengths_nm, dtype=float)
    return np.where((wl >= v[0, 0]) & (wl <= v[-1, 0]), np.interp(wl, v[:, 0], v[:, 1]), np.nan)
