"""Regenerate the spectral tables shipped in ``bionav/data/spectra`` (provenance record).

Not needed at run time; bionav reads the CSV files this script writes. Run it
only to rebuild them from their sources (see ``bionav/data/spectra/README.md``)::

    pip install colour-science pvlib        # only for this script
    python scripts/make_spectra_data.py --bumbleview ../shared/data/bumbleview

* ASTM G-173-03 (extraterrestrial, global tilt, direct + circumsolar), 280-1200 nm,
  from colour-science's copy of the NREL table (``colour.plotting.datasets.astm_g_173``).
* Ozone, water-vapour and mixed-gas absorption coefficients of Bird & Riordan
  (1986), 300-1200 nm, from pvlib's SPECTRL2 implementation (``pvlib.spectrum.spectrl2``).
* bumbleview 0.2.8 (MIT): the 120 petal reflectances averaged into 5-nm bins
  centred on 300, 305, ..., 700 nm (percent -> fraction), the green-leaf
  background 300-700 nm (its 705-750 nm rows are zero padding, not data, and are
  dropped) and CIE D65 as bumbleview ships it.
"""

from __future__ import annotations

import argparse
import csv
import shutil
from pathlib import Path

import numpy as np

OUT = Path(__file__).resolve().parents[1] / "bionav" / "data" / "spectra"


def petal_bins(wl, refl_percent, centres, half_width=2.5):
    """Mean reflectance (fraction) of the samples in each ``centre +- half_width`` nm bin, shape (len(centres), N)."""
    out = np.empty((len(centres), refl_percent.shape[1]))
    for i, c in enumerate(centres):
        sel = (wl >= c - half_width) & (wl < c + half_width)
        out[i] = refl_percent[sel].mean(axis=0) / 100.0
    return out


def write_table(name: str, comment: str, header, rows) -> None:
    """Write ``OUT / name``: one ``# comment`` line, the CSV header, then the (already formatted) rows."""
    with open(OUT / name, "w", newline="") as fh:
        fh.write(f"# {comment}\n")
        w = csv.writer(fh)
        w.writerow(header)
        w.writerows(rows)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bumbleview", type=Path, required=True, help="folder with xmpl_data.csv etc.")
    args = ap.parse_args()
    OUT.mkdir(parents=True, exist_ok=True)

    from colour.plotting.datasets import astm_g_173 as g

    wl = sorted(w for w in g.DATA_ASTMG173_ETR if 280.0 <= w <= 1200.0)
    write_table("astm_g173.csv", "ASTM G173-03 reference solar spectra (NREL, derived from SMARTS 2.9.2), "
                "W m^-2 nm^-1; via colour-science (BSD-3). See README.md.",
                ["wavelength_nm", "extraterrestrial", "global_tilt", "direct_circumsolar"],
                ([f"{x:g}", f"{g.DATA_ASTMG173_ETR[x]:.6g}", f"{g.DATA_ASTMG173_GLOBAL_TILT[x]:.6g}",
                  f"{g.DATA_ASTMG173_DIRECT_CIRCUMSOLAR[x]:.6g}"] for x in wl))

    from pvlib.spectrum.spectrl2 import _SPECTRL2_COEFFS as c

    sel = (c["wavelength"] >= 300) & (c["wavelength"] <= 1200)
    write_table("bird_riordan_absorption.csv",
                "Absorption coefficients of ozone (1/cm of column in atm-cm), water vapour (1/cm of precipitable "
                "water) and uniformly mixed gases (O2, CO2; per air mass), Bird & Riordan (1986) after Leckner "
                "(1978); via pvlib (BSD-3). See README.md.",
                ["wavelength_nm", "ozone", "water_vapor", "mixed_gases"],
                ([f"{x:g}", f"{a:.6g}", f"{b:.6g}", f"{u:.6g}"]
                 for x, a, b, u in zip(c["wavelength"][sel], c["ozone_absorption"][sel],
                                       c["water_vapor_absorption"][sel], c["mixed_absorption"][sel])))

    src = args.bumbleview
    data = np.loadtxt(src / "xmpl_data.csv", delimiter=",")
    with open(src / "xmpl_meta.csv") as fh:
        names = ["_".join(row[:3]) + f"_{row[3]}" for row in csv.reader(fh) if row]
    centres = np.arange(300.0, 701.0, 5.0)
    bins = petal_bins(data[:, 0], data[:, 1:], centres)
    write_table("petals.csv", "120 petal reflectances (fraction), means of 5-nm bins of bumbleview 0.2.8 "
                "xmpl_data.csv (MIT, LICENSE_bumbleview). See README.md.",
                ["wavelength_nm", *names],
                ([f"{x:g}", *(f"{v:.5f}" for v in row)] for x, row in zip(centres, bins)))

    leaf = np.loadtxt(src / "background_green_leaf.csv", delimiter=",")
    leaf = leaf[leaf[:, 0] <= 700.0]
    write_table("green_leaf.csv", "green-leaf reflectance (fraction) 300-700 nm, bumbleview 0.2.8 "
                "background_green_leaf.csv (MIT, LICENSE_bumbleview); its zero rows 705-750 nm are padding and "
                "dropped. See README.md.",
                ["wavelength_nm", "reflectance"], ([f"{x:g}", f"{v:.4f}"] for x, v in leaf))

    d65 = np.loadtxt(src / "d65_standards.csv", delimiter=",")
    write_table("d65.csv", "CIE standard illuminant D65 (relative) as shipped by bumbleview 0.2.8 d65_standards.csv "
                "(MIT, LICENSE_bumbleview). See README.md.",
                ["wavelength_nm", "relative_power"], ([f"{x:g}", f"{v:.6g}"] for x, v in d65))
    shutil.copyfile(src / "LICENSE", OUT / "LICENSE_bumbleview")


if __name__ == "__main__":
    main()
