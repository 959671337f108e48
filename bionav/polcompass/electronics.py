"""Electronics of the polarized-light compass: log-ratio amplifiers and the ADC.

Each POL-OP unit feeds its two photocurrents into a logarithmic ratio
amplifier (LOG112, thesis table A.1) whose output is

    V = V_c + G * log10(s_1 / s_2)                                   (eq. 4.2)

with ``G = 0.5 V per decade`` around ``V_c = 2.5 V`` by default, clipped to
the 0-5 V rails, then digitised by the DLP-IO8-G board's 10-bit ADC over
0-5 V as ``count = round(V * 1023 / 5)`` (and read back as
``V = count * 5 / 1023``). Real components differ: every channel has its own
gain and offset, the two photodiodes of a unit their own sensitivities, and
the output carries noise. Everything after the ADC is shared by the simulated
and the real compass.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ChainParameters:
    """Nominal sensor-chain constants.

    Parameters
    ----------
    center_v : float
        Output for equal photocurrents, volts.
    volts_per_decade : float
        Log-ratio gain ``G``, volts per decade of ``s_1 / s_2``.
    full_scale_v : float
        ADC input range ``[0, full_scale_v]`` volts (also the output rails).
    adc_bits : int
        ADC resolution.
    """

    center_v: float = 2.5
    volts_per_decade: float = 0.5
    full_scale_v: float = 5.0
    adc_bits: int = 10

    @property
    def max_count(self) -> int:
        """Largest ADC count (1023 for 10 bits)."""
        return 2**self.adc_bits - 1


@dataclass(frozen=True)
class ChannelMismatch:
    """Component tolerances of the ``K`` POL-OP channels (true hardware values).

    Attributes
    ----------
    gain : ndarray, shape ``(K,)``
        Relative log-ratio gain (1 = nominal).
    offset_v : ndarray, shape ``(K,)``
        Output offset, volts.
    sensitivity_ratio : ndarray, shape ``(K,)``
        Sensitivity of photodiode 1 over photodiode 2 (1 = matched).
    angle_error : ndarray, shape ``(K,)``
        Mounting error of each unit's polarizer pair, radians.
    """

    gain: np.ndarray
    offset_v: np.ndarray
    sensitivity_ratio: np.ndarray
    angle_error: np.ndarray

    @classmethod
    def ideal(cls, n_units: int = 3) -> "ChannelMismatch":
        """Perfectly matched components."""
        return cls(np.ones(n_units), np.zeros(n_units), np.ones(n_units), np.zeros(n_units))


def sample_mismatch(
    rng: np.random.Generator,
    *,
    n_units: int = 3,
    gain_sigma: float = 0.03,
    offset_sigma_v: float = 0.03,
    sensitivity_sigma: float = 0.05,
    angle_sigma: float = np.deg2rad(1.0),
) -> ChannelMismatch:
    """Draw component tolerances (Gaussian, one standard deviation each).

    Parameters
    ----------
    rng : numpy.random.Generator
    n_units : int, optional
    gain_sigma : float, optional
        Relative gain spread.
    offset_sigma_v : float, optional
        Offset spread in volts.
    sensitivity_sigma : float, optional
        Relative spread of the photodiode sensitivity ratio.
    angle_sigma : float, optional
        Polarizer mounting spread, radians.
    """
    return ChannelMismatch(
        gain=1.0 + gain_sigma * rng.standard_normal(n_units),
        offset_v=offset_sigma_v * rng.standard_normal(n_units),
        sensitivity_ratio=np.exp(sensitivity_sigma * rng.standard_normal(n_units)),
        angle_error=angle_sigma * rng.standard_normal(n_units),
    )


def log_ratio_voltage(ratio, *, chain: ChainParameters = ChainParameters(), mismatch: ChannelMismatch | None = None):
    """Output voltage of the log-ratio amplifiers (eq. 4.2), before noise and clipping.

    Parameters
    ----------
    ratio : ndarray, shape ``(..., K)``
        Photocurrent ratio ``s_1 / s_2`` of each unit.
    chain : ChainParameters, optional
    mismatch : ChannelMismatch, optional
        Channel tolerances; ``None`` means ideal.

    Returns
    -------
    ndarray, shape ``(..., K)``
        Volts.
    """
    ratio = np.asarray(ratio, float)
    if mismatch is None:
        return chain.center_v + chain.volts_per_decade * np.log10(ratio)
    return (
        chain.center_v
        + mismatch.offset_v
        + chain.volts_per_decade * mismatch.gain * np.log10(ratio * mismatch.sensitivity_ratio)
    )


def adc_counts(volts, *, chain: ChainParameters = ChainParameters()):
    """Digitise volts: clip to the rails, ``round(V * max_count / full_scale)`` as int64."""
    v = np.clip(np.asarray(volts, float), 0.0, chain.full_scale_v)
    return np.rint(v * chain.max_count / chain.full_scale_v).astype(np.int64)


def counts_to_volts(counts, *, chain: ChainParameters = ChainParameters()):
    """ADC counts back to volts, ``count * full_scale / max_count`` (DLP-IO8-G: ``* 5 / 1023``)."""
    return np.asarray(counts, float) * chain.full_scale_v / chain.max_count
