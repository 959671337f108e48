"""Material reflectances: the one home of bionav's material tables.

* :data:`MATERIALS`: five-band reflectance spectra with sample-to-sample
  variability of natural and artificial materials (thesis chapter 6 sample
  sets and spectral scenes).
* :func:`band_albedos`: the per-band albedos of the *rendered* worlds' surface
  kinds (:data:`RENDER_KINDS`): in the five bands the reflectances of
  :data:`MATERIALS`, in a monochrome ``grey`` channel :data:`GREY_ALBEDO`.

Spectral reflectances
---------------------

Values are diffuse (Lambertian) reflectance factors at the five channels
(UV 350, B 440, G 500, R 680, IR 800 nm), read off typical spectra of the USGS
Spectral Library (splib07) and the ECOSTRESS library for 440-800 nm: green
vegetation with the chlorophyll trough at 680 nm and the red edge to a high
near-infrared plateau; soils, sand and rock rising monotonically with
wavelength; paints and plastics with their pigment colour in the visible.

**UV assumption** (no package or library ships 350 nm reflectances for these
materials): natural materials reflect little UV-A. Green leaves 2-4 % (epidermal
flavonoids absorb UV-A; field measurements of leaves give 3-6 % at 350 nm), dead
plant material 4-5 %, and soils/rocks/sand about 0.55-0.6 of their 440 nm value
(continuing the monotone decrease of their spectra below 400 nm). Paints and
plastics are assumed to absorb UV-A strongly (titanium-dioxide white pigment
absorbs below about 380 nm, binders and UV stabilisers absorb too): 4-8 %
whatever their visible colour. Bare (galvanised) metal is the exception, a
grey reflector also in the UV. Glossy surfaces (lacquer, plastic) add a
specular reflection of the sky of a few per cent (Fresnel reflectance of a
clear coat, ~4 % at normal incidence).

Per-sample variability: each sample multiplies the base spectrum by a
log-normal brightness factor (``brightness_sd``, natural log) and each band by
a log-normal jitter (``band_sd``).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from bionav.light.bands import CHANNELS, PEAK_NM, WAVELENGTHS_NM, band_integrate


@dataclass(frozen=True)
class Material:
    """A material's reflectance spectrum (or spectra) and its variability.

    Attributes
    ----------
    name : str
    category : str
        ``"natural"`` or ``"artificial"``.
    reflectance : tuple of float
        Diffuse reflectance at UV, B, G, R, IR: the table values of materials
        without measured spectra; for measured ones the channel-weighted mean
        of the mean spectrum (``int S_b rho / int S_b``), for reference.
    gloss : tuple of float
        Range ``(low, high)`` of the specular (sky-mirroring) reflectance.
    brightness_sd, band_sd : float
        Log-normal sample-to-sample variation of the whole spectrum and, smoothly
        over wavelength, of each band.
    spectra : tuple
        Measured base spectra on :data:`~bionav.light.bands.WAVELENGTHS_NM`
        (tuples of floats, one per measured sample); empty for table materials,
        whose spectrum is interpolated from ``reflectance``
        (:func:`spectrum_from_bands`).
    leaf_fraction : tuple of float
        Range of the green-leaf share of an areal mixture (flowers seen among
        their leaves); ``(0, 0)`` for pure materials.
    source : str
        Where the spectrum comes from.
    """

    name: str
    category: str
    reflectance: tuple
    gloss: tuple = (0.0, 0.0)
    brightness_sd: float = 0.25
    band_sd: float = 0.08
    spectra: tuple = ()
    leaf_fraction: tuple = (0.0, 0.0)
    source: str = "five-band table (USGS splib07 / ECOSTRESS shapes; UV assumption)"

    def base_spectra(self) -> np.ndarray:
        """Base reflectance spectra, shape ``(K, L)`` on :data:`~bionav.light.bands.WAVELENGTHS_NM`."""
        if self.spectra:
            return np.asarray(self.spectra, dtype=float)
        return spectrum_from_bands(self.reflectance)[None, :]

    def mean_spectrum(self) -> np.ndarray:
        """The material's mean reflectance spectrum (leaf mixture at its mid share), shape ``(L,)``."""
        mean = self.base_spectra().mean(axis=0)
        f = 0.5 * (self.leaf_fraction[0] + self.leaf_fraction[1])
        return (1 - f) * mean + f * _leaf_spectrum() if f > 0 else mean

    def sample(self, rng: np.random.Generator, n: int = 1) -> np.ndarray:
        """``n`` random reflectance spectra, shape ``(n, L)`` on ``WAVELENGTHS_NM``, clipped to [0.005, 0.98].

        Each sample takes one base spectrum (uniformly among the measured
        ones), mixes in green leaf if the material has a ``leaf_fraction``,
        and multiplies by a log-normal brightness factor and a smooth
        log-normal band jitter (five factors at the channel peaks, linearly
        interpolated over wavelength).
        """
        base = self.base_spectra()
        pick = base[rng.integers(0, len(base), n)]
        if self.leaf_fraction[1] > 0:
            f = rng.uniform(*self.leaf_fraction, (n, 1))
            pick = (1 - f) * pick + f * _leaf_spectrum()[None, :]
        bright = np.exp(rng.normal(0.0, self.brightness_sd, (n, 1)))
        jitter = np.exp(rng.normal(0.0, self.band_sd, (n, len(PEAK_NM))))
        smooth = np.stack([np.interp(WAVELENGTHS_NM, PEAK_NM, j) for j in jitter])
        return np.clip(pick * bright * smooth, 0.005, 0.98)


def spectrum_from_bands(reflectance, wavelengths_nm=WAVELENGTHS_NM) -> np.ndarray:
    """A reflectance spectrum through five band values: linear between the channel peaks, flat beyond, ``(L,)``."""
    return np.interp(np.asarray(wavelengths_nm, dtype=float), PEAK_NM, np.asarray(reflectance, dtype=float))


def band_mean_reflectance(spectrum) -> np.ndarray:
    """Channel-weighted mean reflectance ``int S_b rho / int S_b`` of spectra ``(..., L)``, shape ``(..., 5)``."""
    return band_integrate(spectrum) / band_integrate(np.ones(WAVELENGTHS_NM.shape))


@lru_cache(maxsize=1)
def _leaf_spectrum() -> np.ndarray:
    from bionav.light.measured_spectra import green_leaf_reflectance

    out = green_leaf_reflectance(WAVELENGTHS_NM)
    out.setflags(write=False)
    return out


def _m(name, cat, refl, **kw):
    return Material(name, cat, tuple(float(v) for v in refl), **kw)


_LEAF_SOURCE = ("measured green leaf (bumbleview 0.2.8, 300-700 nm) x canopy factor {f:g}; "
                "red edge and NIR plateau modelled beyond 700 nm")


def _canopy(name, factor, **kw):
    """Vegetation: the measured green-leaf spectrum times a grey canopy factor (shading inside the canopy)."""
    spec = factor * _leaf_spectrum()
    return Material(name, "natural", tuple(float(v) for v in band_mean_reflectance(spec)),
                    spectra=(tuple(float(v) for v in spec),), source=_LEAF_SOURCE.format(f=factor), **kw)


def _flowers():
    from bionav.light.measured_spectra import petal_reflectances

    _, petals = petal_reflectances(WAVELENGTHS_NM)
    spectra = tuple(tuple(float(v) for v in row) for row in petals)
    mean = 0.5 * petals.mean(axis=0) + 0.5 * _leaf_spectrum()
    return Material("flowers", "natural", tuple(float(v) for v in band_mean_reflectance(mean)), spectra=spectra,
                    leaf_fraction=(0.3, 0.8), band_sd=0.04,
                    source="120 measured petal spectra (bumbleview 0.2.8, 300-700 nm, flat beyond) mixed with "
                           "30-80 % measured green leaf")


#: Every material bionav knows, keyed by name. Natural kinds follow thesis 6.2.1's
#: sample list, artificial kinds 6.3.1's (plastic, lacquered metal, painted surfaces).
MATERIALS: dict[str, Material] = {
    m.name: m
    for m in (
        # natural: vegetation, measured (low UV, chlorophyll trough at R, red edge to high IR)
        _canopy("grass", 0.9),
        _canopy("shrub", 0.8),
        _canopy("tree", 0.75),
        _canopy("conifer", 0.5),
        _flowers(),
        _m("dead_leaves", "natural", (0.040, 0.070, 0.100, 0.250, 0.400)),
        _m("dead_wood", "natural", (0.050, 0.090, 0.120, 0.230, 0.300)),
        # natural: minerals and ground
        _m("tar", "natural", (0.045, 0.060, 0.065, 0.075, 0.085), band_sd=0.05),
        _m("rock", "natural", (0.120, 0.200, 0.230, 0.280, 0.300)),
        _m("gravel", "natural", (0.095, 0.160, 0.190, 0.240, 0.270)),
        _m("sand", "natural", (0.120, 0.200, 0.260, 0.380, 0.430)),
        _m("soil", "natural", (0.040, 0.070, 0.090, 0.150, 0.190)),
        # artificial: paints (UV-absorbing pigments and binders)
        _m("paint_white", "artificial", (0.080, 0.800, 0.850, 0.870, 0.870), gloss=(0.0, 0.02), brightness_sd=0.1),
        _m("paint_red", "artificial", (0.050, 0.060, 0.070, 0.550, 0.700), gloss=(0.0, 0.02)),
        _m("paint_green", "artificial", (0.050, 0.100, 0.250, 0.060, 0.500), gloss=(0.0, 0.02)),
        _m("paint_blue", "artificial", (0.060, 0.400, 0.250, 0.050, 0.450), gloss=(0.0, 0.02)),
        _m("paint_yellow", "artificial", (0.050, 0.100, 0.550, 0.750, 0.780), gloss=(0.0, 0.02)),
        _m("paint_grey", "artificial", (0.060, 0.300, 0.300, 0.300, 0.310), gloss=(0.0, 0.02)),
        _m("paint_black", "artificial", (0.040, 0.040, 0.040, 0.040, 0.050), gloss=(0.0, 0.02), brightness_sd=0.1),
        # artificial: plastics (UV stabilisers) and lacquered metal (clear coat: specular sky)
        _m("plastic_white", "artificial", (0.060, 0.700, 0.750, 0.780, 0.800), gloss=(0.02, 0.06), brightness_sd=0.1),
        _m("plastic_red", "artificial", (0.050, 0.070, 0.080, 0.500, 0.650), gloss=(0.02, 0.06)),
        _m("plastic_blue", "artificial", (0.055, 0.350, 0.200, 0.050, 0.400), gloss=(0.02, 0.06)),
        _m("plastic_green", "artificial", (0.050, 0.080, 0.220, 0.060, 0.350), gloss=(0.02, 0.06)),
        _m("plastic_black", "artificial", (0.040, 0.040, 0.040, 0.045, 0.050), gloss=(0.02, 0.06), brightness_sd=0.1),
        _m("lacquered_metal", "artificial", (0.050, 0.200, 0.220, 0.300, 0.350), gloss=(0.03, 0.10), brightness_sd=0.5),
        _m("metal_bare", "artificial", (0.450, 0.520, 0.540, 0.560, 0.570), gloss=(0.05, 0.15), brightness_sd=0.15),
        # building materials (for scenes, not in the sample sets)
        _m("brick", "artificial", (0.050, 0.080, 0.100, 0.300, 0.380)),
        _m("roof_tile", "artificial", (0.040, 0.060, 0.070, 0.220, 0.300)),
        _m("concrete", "artificial", (0.150, 0.250, 0.280, 0.320, 0.340)),
        _m("wood_painted", "artificial", (0.060, 0.350, 0.380, 0.420, 0.450), gloss=(0.0, 0.02)),
        _m("glass", "artificial", (0.020, 0.050, 0.050, 0.050, 0.050), gloss=(0.06, 0.12)),
    )
}

#: Natural sample kinds and their share in ``sim_natural`` (thesis 6.2.1 list).
NATURAL_MIX: dict[str, float] = {
    "grass": 0.18, "shrub": 0.12, "flowers": 0.04, "tree": 0.18, "conifer": 0.06, "dead_leaves": 0.08,
    "dead_wood": 0.08, "tar": 0.05, "rock": 0.06, "gravel": 0.05, "sand": 0.04, "soil": 0.06,
}

#: Artificial sample kinds and their share in ``sim_artificial`` (thesis 6.3.1).
ARTIFICIAL_MIX: dict[str, float] = {
    "paint_white": 0.08, "paint_red": 0.07, "paint_green": 0.07, "paint_blue": 0.07,
    "paint_yellow": 0.06, "paint_grey": 0.07, "paint_black": 0.05, "plastic_white": 0.07,
    "plastic_red": 0.06, "plastic_blue": 0.06, "plastic_green": 0.05, "plastic_black": 0.05,
    "lacquered_metal": 0.20, "metal_bare": 0.04,
}

#: The ground round the natural samples (whose reflection lights surfaces tilted towards it):
#: the ground kinds of :data:`NATURAL_MIX` in their shares there.
NATURAL_GROUND_MIX: dict[str, float] = {
    "grass": 0.18, "dead_leaves": 0.08, "tar": 0.05, "gravel": 0.05, "sand": 0.04, "soil": 0.06,
}

#: The ground round the artificial samples (built-up surroundings: paving, asphalt, lawn).
ARTIFICIAL_GROUND_MIX: dict[str, float] = {"concrete": 1.0, "tar": 1.0, "grass": 1.0}


@lru_cache(maxsize=1)
def _landscape_albedo() -> np.ndarray:
    w = np.array(list(NATURAL_GROUND_MIX.values()))
    out = sum(wi * MATERIALS[k].mean_spectrum() for wi, k in zip(w / w.sum(), NATURAL_GROUND_MIX))
    out.setflags(write=False)
    return out


def landscape_albedo(wavelengths_nm=WAVELENGTHS_NM) -> np.ndarray:
    """Spectral albedo of the landscape round the observer, shape ``(L,)``.

    The share-weighted mean reflectance of the ground kinds of
    :data:`NATURAL_GROUND_MIX` (grass, dead leaves, tar, gravel, sand, soil):
    about 0.06 at 350 nm, 0.09 at 440, 0.12 at 500, 0.19 at 680 and 0.30 at
    800 nm (channel means), the green landscape's dark UV and bright near
    infrared (satellite albedos of vegetated land: 0.03-0.08 visible, 0.25-0.35
    near infrared). It lights the sky from below (ground-sky and ground-cloud
    reflections, :mod:`bionav.light.daylight`).

    Parameters
    ----------
    wavelengths_nm : array_like, shape (L,)
        Wavelengths in nm (300-1100; held constant outside).
    """
    return np.interp(np.asarray(wavelengths_nm, dtype=float), WAVELENGTHS_NM, _landscape_albedo())


#: The material of :data:`MATERIALS` that each surface kind of the rendered worlds is made of
#: (the ``kind`` of a :class:`bionav.world.scene.RenderMaterial`, e.g. the campus of
#: :mod:`bionav.world.worlds.outdoor`): the five-band albedos of a rendered world are these
#: materials' reflectances.
RENDER_KINDS: dict[str, str] = {
    "concrete": "concrete", "brick": "brick", "glass": "glass", "foliage": "tree", "bark": "dead_wood",
    "grass": "grass", "paving": "concrete", "asphalt": "tar", "metal": "metal_bare", "paint": "lacquered_metal",
    "wood": "dead_wood", "soil": "soil",
}

#: Albedo of each surface kind for a monochrome (``grey``) camera (the grey campus of the *uni* stand-in,
#: ``sim_uni``): rough textbook values, not derived from the spectra (the grey camera's band is none of the
#: five channels); kept as they are because every rendered sim_uni pixel depends on them.
GREY_ALBEDO: dict[str, float] = {
    "concrete": 0.45, "brick": 0.3, "glass": 0.15, "foliage": 0.3, "bark": 0.25, "grass": 0.3, "paving": 0.4,
    "asphalt": 0.15, "metal": 0.5, "paint": 0.6, "wood": 0.35, "soil": 0.2,
}


def band_albedos(channels: tuple[str, ...]) -> dict[str, np.ndarray]:
    """Albedo of every surface kind of the rendered worlds, per band.

    Parameters
    ----------
    channels : tuple of str
        Band names: ``UV``, ``B``, ``G``, ``R``, ``IR`` (the five sensor
        channels, :data:`~bionav.light.bands.CHANNELS`) or ``grey``.

    Returns
    -------
    dict
        Kind (:data:`RENDER_KINDS`) -> albedo, shape ``(C,)``: in the five
        bands the band reflectance of the kind's material (``Material.reflectance``:
        channel means of the measured spectra, or the five-band table);
        in ``grey`` :data:`GREY_ALBEDO`.
    """
    unknown = [c for c in channels if c != "grey" and c not in CHANNELS]
    if unknown:
        raise ValueError(f"no default albedos for bands {unknown}; pass albedos explicitly")
    index = {c: i for i, c in enumerate(CHANNELS)}
    return {kind: np.array([GREY_ALBEDO[kind] if c == "grey" else MATERIALS[name].reflectance[index[c]]
                            for c in channels])
            for kind, name in RENDER_KINDS.items()}
