"""The five-channel sensor's signal chain: photodiode, log-ratio amplifier, 12-bit ADC.

Thesis 6.1 (Kollmeier et al. 2007): each channel's photodiode current is
logarithmised by a Burr-Brown LOG112 log-ratio amplifier against a reference
current and digitised by one of the ADuC812's 12-bit ADCs; a sixth ADC reads
the reference. The model:

``V_b = V_offset + K * log10(I_b / I_white_b)``,
``count_b = clip(round(V_b / V_ref * 4096 + noise), 0, 4095)``

with ``K = 0.5 V`` per decade (the LOG112's transfer; 819 counts per decade at a
2.5 V reference), ``I_b`` the channel's band-integrated radiance and ``I_white_b``
the radiance of a white Lambertian reflector under a reference clear sky with
the sun at 50 degrees elevation (so the channels are *white-balanced*: that
reflector reads ``V_offset`` in every channel). The noise is Gaussian in counts
(amplifier and ADC), drawn per reading. The sixth value ``ref`` reads the
reference input, i.e. ``V_offset`` plus noise.

Because the signal is logarithmic, the difference of two channels (a *contrast*)
is the log ratio of two band radiances and does not depend on the overall
illumination intensity (Möller 2002).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


def _white_reference() -> np.ndarray:
    from bionav.light.bands import band_integrate
    from bionav.light.daylight import SkyState, illumination

    state = SkyState(sun_elevation=np.deg2rad(50.0), sun_azimuth=0.0)
    return band_integrate(illumination(state).global_horizontal) / np.pi


@dataclass(frozen=True)
class LogSensorModel:
    """Parameters of the log amplifier and ADC chain.

    Attributes
    ----------
    volts_per_decade : float
        Log-amplifier gain ``K`` in V per decade of photocurrent.
    vref : float
        ADC reference voltage (full scale).
    adc_bits : int
        ADC resolution (12 on the ADuC812).
    offset_volts : float
        Output for the white reference radiance.
    noise_counts : float
        Standard deviation of the per-reading noise, in counts.
    white_radiance : tuple of float
        Band radiance ``I_white_b`` that reads ``offset_volts``; default from
        the reference sky (see module docstring).
    """

    volts_per_decade: float = 0.5
    vref: float = 2.5
    adc_bits: int = 12
    offset_volts: float = 2.0
    noise_counts: float = 4.0
    white_radiance: tuple = field(default_factory=lambda: tuple(_white_reference()))

    @property
    def full_scale(self) -> int:
        """Largest count, ``2**bits - 1``."""
        return 2**self.adc_bits - 1

    @property
    def counts_per_decade(self) -> float:
        """ADC counts per decade of radiance (819 for the defaults)."""
        return self.volts_per_decade / self.vref * 2**self.adc_bits

    @property
    def offset_counts(self) -> float:
        """Count of the white reference (and of the ``ref`` channel)."""
        return self.offset_volts / self.vref * 2**self.adc_bits

    def ideal_counts(self, band_radiance) -> np.ndarray:
        """Noise-free, unquantised, unclipped counts of band radiances ``(..., 5)``."""
        rad = np.maximum(np.asarray(band_radiance, dtype=float), 1e-30)
        return self.offset_counts + self.counts_per_decade * np.log10(rad / np.asarray(self.white_radiance))

    def read(self, band_radiance, *, rng: np.random.Generator, n_readings: int = 1) -> np.ndarray:
        """Simulated raw readings: 5 channels plus the reference, as the board sends them.

        Parameters
        ----------
        band_radiance : array_like, shape (..., 5)
            Band-integrated radiance per channel (UV, B, G, R, IR).
        rng : numpy.random.Generator
        n_readings : int
            Readings per input (subsequent samples of one pointing).

        Returns
        -------
        ndarray of int, shape (n_readings, ..., 6)
            ``uv, b, g, r, ir, ref`` counts in ``[0, 4095]``.
        """
        ideal = self.ideal_counts(band_radiance)
        ideal = np.concatenate([ideal, np.full(ideal.shape[:-1] + (1,), self.offset_counts)], axis=-1)
        noisy = ideal[None] + rng.normal(0.0, self.noise_counts, (n_readings,) + ideal.shape)
        return np.clip(np.rint(noisy), 0, self.full_scale).astype(np.int64)

    def log_radiance(self, counts) -> np.ndarray:
        """Invert the chain: ``log10(I_b / I_white_b)`` from counts ``(..., 5)``."""
        return (np.asarray(counts, dtype=float) - self.offset_counts) / self.counts_per_decade
