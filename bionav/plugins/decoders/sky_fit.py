"""``decoder=sky_fit`` (default) and ``decoder=two_unit``: bionav's own decoders."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.errors import UserError
from bionav.plugins.decoders.base import Decoder, check_range
from bionav.polcompass.decoders import sky_table, sun_from_sky_fit, sun_from_two_units


@dataclass
class SkyFitConfig:
    """Parameters of ``decoder=sky_fit``."""

    residual: str = "perpendicular"  # perpendicular (e-vectors perpendicular to the sun) | angle (model e-vector angles)
    n_grid: int = 720  # solar azimuths tried (then refined), [36, 7200]
    weight_power: float = 1.0  # unit weight = measured degree ** weight_power, [0, 4]
    robust_iterations: int = 2  # Cauchy re-weighting rounds, [0, 10]
    robust_scale_deg: float = 10.0  # residual scale of the re-weighting, degrees, (0, 90]
    margin: float = 0.01  # normalised error gap for a resolved eq. 4.6 pair, [0, 1]
    max_degree: float = 0.76  # sky model's maximum degree (only the pattern's angles matter), (0, 1]
    neutral_point_separation_deg: float = 0.0  # 0: Rayleigh; >0: Berry et al. 2004, [0, 60]

    def __post_init__(self):
        if self.residual not in ("perpendicular", "angle"):
            raise UserError(f"decoder.residual={self.residual!r} is unknown; choose perpendicular or angle.")
        check_range("n_grid", self.n_grid, 36, 7200)
        check_range("robust_iterations", self.robust_iterations, 0, 10)
        check_range("robust_scale_deg", self.robust_scale_deg, 1e-6, 90.0)
        check_range("weight_power", self.weight_power, 0.0, 4.0)
        check_range("margin", self.margin, 0.0, 1.0)
        check_range("max_degree", self.max_degree, 1e-6, 1.0)
        check_range("neutral_point_separation_deg", self.neutral_point_separation_deg, 0.0, 60.0)


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
            margin=self.config.margin,
        )


@dataclass
class TwoUnitConfig:
    """Parameters of ``decoder=two_unit``."""

    margin_deg: float = 2.0  # elevation-error gap for a resolved eq. 4.6 pair, degrees, [0, 90]

    def __post_init__(self):
        check_range("margin_deg", self.margin_deg, 0.0, 90.0)


class TwoUnit(Decoder):
    """The thesis' two-unit solution (eqs. 4.4-4.6) generalised to tilted units."""

    Config = TwoUnitConfig
    needs_sun_elevation = True

    def decode(self, evectors, valid, *, array, sun_elevation: float):
        return sun_from_two_units(evectors, valid, sun_elevation=sun_elevation, margin=np.deg2rad(self.config.margin_deg))
