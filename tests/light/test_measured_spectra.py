"""Measured spectra (bionav/data/spectra) against their sources and closed forms; log contrasts by hand."""

import os
from pathlib import Path

import numpy as np
import pytest
from scipy.special import ndtr

from bionav.light.bands import FWHM_NM, PEAK_NM, WAVELENGTHS_NM, band_integrate
from bionav.light.daylight import SkyState, illumination, solar_spectrum
from bionav.light.materials import MATERIALS
from bionav.light.measured_spectra import (
    LEAF_NIR_PLATEAU,
    astm_g173,
    cell_mean,
    d65,
    extraterrestrial_solar_spectrum,
    gas_absorption,
    green_leaf_reflectance,
    petal_reflectances,
)
from bionav.spectral.sensor_model import LogSensorModel

REPO = Path(__file__).resolve().parents[2]
EXTERNAL = Path(os.environ.get("BIONAV_EXTERNAL_DATA", REPO.parent / "shared" / "data"))
BUMBLEVIEW = EXTERNAL / "bumbleview"
needs_bumbleview = pytest.mark.skipif(not (BUMBLEVIEW / "xmpl_data.csv").is_file(),
                                      reason=f"bumbleview spectra not found at {BUMBLEVIEW} (set BIONAV_EXTERNAL_DATA)")


def test_cell_mean_closed_forms():
    x = np.array([0.0, 10.0, 20.0])
    # a linear source: the cell mean is the value at the cell centre
    np.testing.assert_allclose(cell_mean(x, 3.0 * x + 1.0, [5.0, 7.5, 10.0]), [16.0, 23.5, 31.0])
    # a hat 0 -> 1 -> 0: mean over [8, 12] = 1 - (2/10) / 2 ... = 0.9
    assert cell_mean(x, [0.0, 1.0, 0.0], [6.0, 10.0, 14.0])[1] == pytest.approx(0.9)
    # outside the table: the end values
    np.testing.assert_allclose(cell_mean(x, [1.0, 2.0, 4.0], [-50.0, -40.0, 80.0, 90.0]), [1.0, 1.0, 4.0, 4.0])
    # several columns at once
    assert cell_mean(x, np.c_[x, 2 * x], [5.0, 10.0]).shape == (2, 2)


def test_astm_g173_integrals_and_solar_constant():
    wl = np.arange(280.5, 1200.0, 1.0)
    g = astm_g173(wl)
    # NREL's ASTM G173-03: 1366.1 W/m^2 extraterrestrial over 280-4000 nm; 280-1200 nm hold about 77 % of it
    assert np.sum(g["extraterrestrial"]) == pytest.approx(1050.0, rel=0.02)
    assert np.all(g["global_tilt"] <= g["extraterrestrial"] + 1e-9)
    # the sun of the daylight model is the measured one where the table has data, a black body elsewhere
    np.testing.assert_allclose(solar_spectrum(wl), extraterrestrial_solar_spectrum(wl))
    assert np.isnan(extraterrestrial_solar_spectrum([250.0, 1300.0])).all()


def test_ozone_bands():
    a = gas_absorption([300.0, 350.0, 440.0, 600.0, 800.0])["ozone"]
    assert a[0] == pytest.approx(10.0) and a[2] == 0.0 and a[4] == 0.0  # Huggins band, no absorption, none
    assert 0.11 < a[3] < 0.13  # Chappuis maximum near 600 nm


def test_model_daylight_resembles_d65():
    """Global daylight of the model (sun 40 deg, clear) has the spectral shape of CIE D65 within 20 % (400-700 nm).

    D65 is an average of measured daylight (CCT 6500 K, overcast included); a clear sky at a 40 degree sun is
    somewhat bluer at 400-450 nm and redder at 650-700 nm (measured here: +15 % / -14 %).
    """
    wl = np.arange(400.0, 701.0, 10.0)
    glob = illumination(SkyState(np.deg2rad(40.0), turbidity=0.08), wl).global_horizontal
    ref = d65(wl)
    rel = (glob / glob.mean()) / (ref / ref.mean())
    assert np.all(np.abs(rel - 1) < 0.2), rel.round(2)


@needs_bumbleview
def test_shipped_petals_are_bin_means_of_the_source():
    raw = np.loadtxt(BUMBLEVIEW / "xmpl_data.csv", delimiter=",")
    names, petals = petal_reflectances(np.arange(300.0, 701.0, 5.0))
    assert len(names) == 120 and petals.shape == (120, 81)
    assert names[0] == "Gentiana_acaulis_ventral_medial_1"
    rng = np.random.default_rng(0)
    for k in rng.choice(120, 8, replace=False):
        for c in (350.0, 440.0, 500.0, 600.0, 680.0):
            sel = (raw[:, 0] >= c - 2.5) & (raw[:, 0] < c + 2.5)
            want = max(raw[sel, k + 1].mean() / 100.0, 0.005)  # percent -> fraction, clipped like the loader
            got = petals[k, int((c - 300) / 5)]
            assert got == pytest.approx(want, abs=2e-5)


@needs_bumbleview
def test_shipped_leaf_and_d65_equal_the_source():
    leaf = np.loadtxt(BUMBLEVIEW / "background_green_leaf.csv", delimiter=",")
    measured = leaf[leaf[:, 0] <= 700]
    np.testing.assert_allclose(green_leaf_reflectance(measured[:, 0]), measured[:, 1], atol=1e-9)
    assert np.all(leaf[leaf[:, 0] > 700, 1] == 0)  # the source's padding, which bionav does not use
    src = np.loadtxt(BUMBLEVIEW / "d65_standards.csv", delimiter=",")
    np.testing.assert_allclose(d65(src[:, 0]), src[:, 1], rtol=1e-5)


def test_leaf_red_edge_extrapolation():
    r = np.array([green_leaf_reflectance([w])[0] for w in (700.0, 705.0, 720.0, 800.0, 1100.0)])
    assert r[0] == pytest.approx(0.143)  # the last measured value, joined continuously
    assert np.all(np.diff(r[:4]) > 0) and r[4] == pytest.approx(LEAF_NIR_PLATEAU, rel=1e-3)
    assert r[3] == pytest.approx(LEAF_NIR_PLATEAU, abs=0.01)
    # petals hold their 690-700 nm mean beyond 700 nm
    p = np.stack([petal_reflectances([w])[1][:, 0] for w in (690.0, 695.0, 700.0, 800.0, 1000.0)], axis=1)
    np.testing.assert_allclose(p[:, 3], np.clip(p[:, :3].mean(axis=1), 0.005, None), atol=1e-3)
    np.testing.assert_allclose(p[:, 3], p[:, 4])


def test_flowers_and_vegetation_use_the_measured_spectra():
    leaf = green_leaf_reflectance(WAVELENGTHS_NM)
    np.testing.assert_allclose(MATERIALS["grass"].mean_spectrum(), 0.9 * leaf)
    fl = MATERIALS["flowers"]
    assert fl.base_spectra().shape == (120, WAVELENGTHS_NM.size)
    s = fl.sample(np.random.default_rng(1), 50)
    assert s.shape == (50, WAVELENGTHS_NM.size) and np.all((s >= 0.005) & (s <= 0.98))


def test_log_contrast_of_two_known_spectra_by_hand():
    """UV-IR contrast (counts) of a step spectrum against a flat one: 819.2 log10 of band-integral ratios.

    Spectrum A is flat; B is A times 0.1 below 575 nm. The UV band lies wholly below 575 nm, the
    IR band (Gaussian 800 nm, FWHM 200 nm) has the fraction Phi((575 - 800) / sd) below it, so
    ``(UV-IR)_B - (UV-IR)_A = 819.2 * (log10(0.1) - log10(0.1 F + 1 - F))``; the intensity of A
    cancels, as it must for a log-ratio sensor.
    """
    sensor = LogSensorModel(noise_counts=0.0)
    wl = WAVELENGTHS_NM
    a = 3.7 * np.ones(wl.size)
    b = np.where(wl < 575.0, 0.1, 1.0) * a
    sd_ir = FWHM_NM[4] / (2 * np.sqrt(2 * np.log(2)))
    f = ndtr((575.0 - PEAK_NM[4]) / sd_ir)
    want = 819.2 * (np.log10(0.1) - np.log10(0.1 * f + 1 - f))
    ca, cb = sensor.ideal_counts(band_integrate(a)), sensor.ideal_counts(band_integrate(b))
    assert (cb[0] - cb[4]) - (ca[0] - ca[4]) == pytest.approx(want, abs=1.0)
    # scaling the light by 1000 moves every channel by 3 decades and no contrast
    c1000 = sensor.ideal_counts(band_integrate(1000 * a))
    np.testing.assert_allclose(c1000 - ca, 3 * 819.2)


def test_rendered_worlds_take_their_band_albedos_from_the_material_table():
    """One material table: a rendered surface kind's five-band albedo is its material's band reflectance."""
    from bionav.light.materials import GREY_ALBEDO, MATERIALS, RENDER_KINDS, band_albedos

    table = band_albedos(("UV", "B", "G", "R", "IR", "grey"))
    assert set(table) == set(RENDER_KINDS) == set(GREY_ALBEDO)
    # grass is the measured green leaf (bumbleview) x 0.9: dark in UV, brightest beyond the red edge (IR)
    np.testing.assert_array_equal(table["grass"][:5], MATERIALS["grass"].reflectance)
    assert table["grass"][0] < 0.1 and np.argmax(table["grass"][:5]) == 4
    np.testing.assert_array_equal(table["asphalt"][:5], MATERIALS["tar"].reflectance)
    assert table["concrete"][5] == GREY_ALBEDO["concrete"] == 0.45
    np.testing.assert_array_equal(band_albedos(("G", "UV"))["brick"], [0.100, 0.050])  # the table's brick, reordered
    with pytest.raises(ValueError, match="no default albedos for bands"):
        band_albedos(("UV", "X"))
