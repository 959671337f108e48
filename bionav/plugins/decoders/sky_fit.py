"""``decoder=sky_fit`` (default) and ``decoder=two_unit``: bionav's own decoders."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.plugins.decoders.base import Decoder
from bionav.polcompass.decoders import sky_table, sun_from_sky_fit
from bionav.polcompass.published_decoders import sun_from_two_units
from bionav.validation import bounded


@dataclass
class SkyFitConfig:
    """Parameters of ``decoder=sky_fit``.

    residual : ``perpendicular`` (every e-vector perpendicular to the sun, elevation from time and
        place) or ``angle`` (the tabulated model e-vector angles of any sky model).
    n_grid : solar azimuths tried, then refined by a parabola.
    weight_power : unit weight = measured degree ** weight_power.
    robust_iterations, robust_scale_deg : Cauchy re-weighting rounds and their scale on each unit's angle residual
        (degrees); reject_deg: after them, units whose angle residual exceeds it are dropped and the last solve
        is unweighted by the loss (0: no rejection). Choice of 20 / 30 degrees: docs/polcompass.md.
    model_error_deg : model-error scale of the noise weighting (``noise_counts``).
    margin : normalised error gap for a resolved eq. 4.6 pair (else the brighter side decides).
    max_degree, neutral_point_separation_deg : the sky model of ``residual=angle`` (0: Rayleigh).
    noise_counts : count noise of one photodiode (counts; 0: off). Units are weighted by their signal above
        it (:func:`bionav.polcompass.decoders.angle_noise`), units whose angle noise exceeds
        ``model_error_deg`` take no part. 0.5 is measured on the recorded sensor: quantisation (0.29) and
        dark noise (0.0-0.5 counts rms per photodiode after sunset, docs/polcompass.md "Dusk").
    min_units : fewest units taking part for a sample to be decoded; fewer: no heading (``valid`` false),
        unless ``pol_op_fallback``.
    pol_op_fallback : such samples, and samples where a unit reads one of its POL-OPs only, are decoded from every
        usable POL-OP instead (:func:`bionav.polcompass.decoders.sun_from_pol_op_fit`: a unit with one saturated pair
        still gives one equation); docs/polcompass.md "Real skies".
    """

    residual: str = bounded("perpendicular", choices=("perpendicular", "angle"))
    n_grid: int = bounded(720, ge=36, le=7200)
    weight_power: float = bounded(1.0, ge=0.0, le=4.0)
    robust_iterations: int = bounded(2, ge=0, le=10)
    robust_scale_deg: float = bounded(20.0, gt=0.0, le=90.0)
    reject_deg: float = bounded(30.0, ge=0.0, le=90.0)
    model_error_deg: float = bounded(10.0, gt=0.0, le=90.0)
    margin: float = bounded(0.01, ge=0.0, le=1.0)
    max_degree: float = bounded(0.76, gt=0.0, le=1.0)
    neutral_point_separation_deg: float = bounded(0.0, ge=0.0, le=60.0)
    noise_counts: float = bounded(0.5, ge=0.0, le=1e6)
    min_units: int = bounded(2, ge=1, le=64)
    pol_op_fallback: bool = True


class SkyFit(Decoder):
    """Least squares over all units against the sky model's e-vector pattern (bionav's default)."""

    Config = SkyFitConfig
    needs_sun_elevation = True

    def __init__(self, config: SkyFitConfig) -> None:
        super().__init__(config)
        self._tables: dict = {}

    def table(self, array, sun_elevation: float):
        key = (id(array), round(float(sun_elevation), 6))
        if key not in self._tables:
            self._tables[key] = sky_table(
                array,
                sun_elevation,
                n_grid=self.config.n_grid,
                max_degree=self.config.max_degree,
                neutral_point_separation=np.deg2rad(self.config.neutral_point_separation_deg),
            )
        return self._tables[key]

    def decode(self, evectors, valid, *, array, sun_elevation: float):
        return sun_from_sky_fit(
            evectors,
            valid,
            table=self.table(array, sun_elevation),
            array=array,
            sun_elevation=float(sun_elevation),
            residual=self.config.residual,
            weight_power=self.config.weight_power,
            robust_iterations=self.config.robust_iterations,
            robust_scale=np.deg2rad(self.config.robust_scale_deg),
            reject=np.deg2rad(self.config.reject_deg) if self.config.reject_deg > 0 else None,
            model_error=np.deg2rad(self.config.model_error_deg),
            margin=self.config.margin,
            noise_counts=self.config.noise_counts,
            min_units=self.config.min_units,
            pol_op_fallback=self.config.pol_op_fallback,
        )


@dataclass
class TwoUnitConfig:
    """Parameters of ``decoder=two_unit``: elevation-error gap (degrees) for a resolved eq. 4.6 pair."""

    margin_deg: float = bounded(2.0, ge=0.0, le=90.0)


class TwoUnit(Decoder):
    """The thesis' two-unit solution (eqs. 4.4-4.6) generalised to tilted units."""

    Config = TwoUnitConfig
    needs_sun_elevation = True

    def decode(self, evectors, valid, *, array, sun_elevation: float):
        return sun_from_two_units(evectors, valid, sun_elevation=sun_elevation, margin=np.deg2rad(self.config.margin_deg))
