"""Data shipped with bionav (with their licences beside them).

* ``seville2009/`` -- the Seville 2009 ant world (``world5000_gray.mat``) and
  133 homeward ant routes (``AntRoutes.mat``); MIT licence (``LICENSE``), see
  ``CITATION.md``. Read them through :func:`bionav.db.mesh.seville_world_path`
  and :func:`bionav.db.mesh.seville_routes_path`.
* ``spectra/`` -- measured spectra of the chapter-6 world (ASTM G173 sun, Bird &
  Riordan gas absorption, bumbleview petal, leaf and D65 tables); MIT and BSD-3
  sources, see ``spectra/README.md``. Read them through
  :mod:`bionav.light.measured_spectra`.
"""

from __future__ import annotations

from pathlib import Path


def data_path(*parts: str) -> Path:
    """Path of a file shipped in ``bionav/data``."""
    return Path(__file__).resolve().parent.joinpath(*parts)
