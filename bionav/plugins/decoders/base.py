"""The contract of ``bionav.decoders`` plugins.

A decoder plugin is a class with a typed ``Config`` dataclass (ranges declared
with :func:`bionav.validation.bounded`, checked where values enter), constructed as ``Plugin(config)``, whose
:meth:`Decoder.decode` turns the e-vectors the units of an array read at each
sample into the solar azimuth in the sensor frame
(:class:`bionav.polcompass.decoders.SunEstimate`). A decoder sees one sample
at a time (vectorised over samples): no information from other samples.
"""

from __future__ import annotations

from typing import ClassVar


class Decoder:
    """Base class of decoder plugins."""

    Config: ClassVar[type]
    #: whether :meth:`decode` needs the expected sun elevation (time and place)
    needs_sun_elevation: ClassVar[bool] = False

    def __init__(self, config) -> None:
        self.config = config

    def decode(self, evectors, valid, *, array, sun_elevation: float):
        """Solar azimuth of every sample.

        Parameters
        ----------
        evectors : bionav.polcompass.array.UnitEvectors
            What every unit read, shape ``(N, K)`` per field.
        valid : ndarray of bool, shape ``(N, K)``
            Units usable at each sample.
        array : bionav.polcompass.array.PolArray
        sun_elevation : float
            Expected sun elevation (radians) from time and place.

        Returns
        -------
        bionav.polcompass.decoders.SunEstimate
        """
        raise NotImplementedError
