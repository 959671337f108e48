"""Spectral contrasts of the five-channel UV..IR sensor (thesis chapter 6).

Modules: :mod:`~bionav.spectral.bands` (channels and features),
:mod:`~bionav.spectral.sky` (daylight model), :mod:`~bionav.spectral.materials`
(five-band reflectances), :mod:`~bionav.spectral.sensor_model` (log amplifier,
ADC), :mod:`~bionav.spectral.samples` (simulated sample sets),
:mod:`~bionav.spectral.csv_io` (CSV sample sets),
:mod:`~bionav.spectral.protocol` (the ADuC812 serial line protocol).
"""
