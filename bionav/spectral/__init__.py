"""Spectral contrasts of the five-channel UV..IR sensor (thesis chapter 6).

The light itself (channels, daylight, clouds, materials) lives in
:mod:`bionav.light` (:mod:`~bionav.light.bands`, :mod:`~bionav.light.daylight`,
:mod:`~bionav.light.clouds`, :mod:`~bionav.light.materials`). Here:
:mod:`~bionav.spectral.sensor_model` (log amplifier, ADC),
:mod:`~bionav.spectral.samples` (simulated sample sets),
:mod:`~bionav.spectral.csv_io` (CSV sample sets),
:mod:`~bionav.spectral.protocol` (the ADuC812 serial line protocol).
The scanned outdoor scenes (garden, backyard) are rendered worlds:
:mod:`bionav.world.worlds.garden`.
"""
