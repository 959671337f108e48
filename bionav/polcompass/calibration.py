"""Per-unit calibration of the POL-OP channels from one rotation.

The thesis (4.2.1) notes that component tolerances make the units' output
swings differ and compensates them in software. Turning the compass under a
constant polarization pattern through at least half a turn (one period of the
signal) reveals each channel's tolerances: with ``x = d cos(2a - 2alpha_i)``
and ``a = a_0 - psi`` (``psi`` the rotation, CCW), the output of unit ``i`` is
``V_i(psi) = c_i + g_i p(cos(2 psi - beta_i))`` where ``p`` is the odd
function ``log10((1 + d u) / (1 - d u))``. Its Fourier series in ``2 psi`` has
only the constant and odd harmonics, so a least-squares fit of
``m + sum_{k in {1,3,5,7}} A_k cos(2k psi) + B_k sin(2k psi)`` gives

* the centre ``c_i = m`` exactly (offset and photodiode mismatch),
* the relative gain ``g_i / mean(g)`` from the fundamental's amplitude (all
  units see the same degree ``d``); the mean gain stays at its nominal value,
* the polarizer angle relative to unit 0 from the fundamental's phase,
  ``alpha_i - alpha_0 = -(beta_i - beta_0) / 2``; unit 0 keeps its nominal angle
  (it defines the sensor frame).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from bionav.errors import UserError
from bionav.geometry import wrap_axial
from bionav.validation import Range


@dataclass(frozen=True)
class UnitCalibration:
    """Per-unit constants used to turn volts into e-vector angles.

    Attributes
    ----------
    center_v : ndarray, shape ``(K,)``
        Output for ``x = 0``, volts.
    volts_per_decade : ndarray, shape ``(K,)``
        Gain, volts per decade.
    unit_angles : ndarray, shape ``(K,)``
        Polarizer angles, radians, sensor frame.
    """

    center_v: np.ndarray
    volts_per_decade: np.ndarray
    unit_angles: np.ndarray

    @classmethod
    def nominal(cls, unit_angles=(0.0, np.pi / 3.0, 2.0 * np.pi / 3.0), *, center_v=2.5, volts_per_decade=0.5):
        """The design values (no calibration)."""
        k = len(unit_angles)
        return cls(np.full(k, float(center_v)), np.full(k, float(volts_per_decade)), np.asarray(unit_angles, float))

    def to_dict(self) -> dict:
        """JSON-ready form (angles in radians)."""
        return {
            "center_v": [float(v) for v in self.center_v],
            "volts_per_decade": [float(v) for v in self.volts_per_decade],
            "unit_angles": [float(v) for v in self.unit_angles],
        }

    #: the values a calibration may hold: volts within the 0-5 V rails, a gain that resolves a decade
    #: within them (0 would divide by zero), polarizer angles in radians within a turn, 1..8 analog lines
    CENTER_V = Range(ge=0.0, le=5.0)
    VOLTS_PER_DECADE = Range(ge=0.01, le=50.0)
    UNIT_ANGLE = Range(ge=-2.0 * np.pi, le=2.0 * np.pi)
    MAX_UNITS = 8

    @classmethod
    def from_dict(cls, data: dict, *, source: str = "The compass calibration",
                  fix: str = "Recalibrate with experiment.mode=rotation.", units: int | None = None) -> "UnitCalibration":
        """Inverse of :meth:`to_dict`, every field checked (finite, in range, one value per unit).

        Raises
        ------
        UserError
            Naming ``source``, the field and its allowed values: a missing field, a ragged or
            non-numeric list, NaN or infinity, a value outside :attr:`CENTER_V`,
            :attr:`VOLTS_PER_DECADE` or :attr:`UNIT_ANGLE`, lists of different lengths.
        """
        from bionav.datafile import FileFields

        fields = FileFields(data, source=source, fix=fix)
        center = fields.array("center_v", shape=(None,), valid=cls.CENTER_V)
        k = center.size
        if not 1 <= k <= cls.MAX_UNITS or (units is not None and k != units):
            fields.fail("center_v", f"has {k} values", f"one per unit of this compass ({units} units)" if units
                        else f"one per unit, 1 to {cls.MAX_UNITS} units")
        gain = fields.array("volts_per_decade", shape=(k,), valid=cls.VOLTS_PER_DECADE)
        angles = fields.array("unit_angles", shape=(k,), valid=cls.UNIT_ANGLE)
        return cls(center, gain, angles)

    @classmethod
    def load(cls, path, *, setting: str = "experiment.calibration_path", units: int | None = None) -> "UnitCalibration":
        """Read a calibration written by :meth:`save`; ``setting`` names the option in error messages.

        ``units``: the number of units the compass has (a calibration of another one is refused).
        """
        from bionav.datafile import read_user_json
        from bionav.files import user_path

        fix = (f"Point {setting} at a calibration.json written by a rotation run (experiment=pol_compass "
               "mode=rotation), or drop it to calibrate from the scan.")
        data = read_user_json(path, what="The compass calibration", fix=fix, kind="calibration")
        return cls.from_dict(data, source=f"The compass calibration {user_path(path)}", fix=fix, units=units)

    def save(self, path) -> None:
        """Write the calibration as JSON."""
        Path(path).write_text(json.dumps(self.to_dict(), indent=2))


def calibrate_from_rotation(
    volts,
    rotation,
    *,
    nominal: UnitCalibration | None = None,
    harmonics=(1, 3, 5, 7),
) -> UnitCalibration:
    """Estimate per-unit centre, gain and polarizer angle from a rotation.

    Parameters
    ----------
    volts : ndarray, shape ``(N, K)``
        Unit output voltages while the compass turns under a constant sky
        (looking at the zenith) or polarizer.
    rotation : ndarray, shape ``(N,)``
        Rotation of the compass for each sample, radians CCW (pan angle).
        Must cover at least half a turn.
    nominal : UnitCalibration, optional
        Design values; their mean gain and unit 0's angle are kept.
    harmonics : tuple of int, optional
        Odd harmonics of ``2 psi`` in the fit; only as many as keep the fit
        twice overdetermined in the number of distinct angles are used.

    Returns
    -------
    UnitCalibration
    """
    volts = np.asarray(volts, float)
    rotation = np.asarray(rotation, float)
    if volts.ndim != 2 or volts.shape[0] != rotation.shape[0]:
        raise ValueError(f"volts must be (N, K) and rotation (N,), got {volts.shape} and {rotation.shape}")
    k = volts.shape[1]
    nominal = nominal or UnitCalibration.nominal()
    if len(nominal.unit_angles) != k:
        raise ValueError(f"nominal calibration has {len(nominal.unit_angles)} units, data {k}")
    span = np.ptp(np.unwrap(2.0 * np.sort(rotation))) / 2.0 if rotation.size else 0.0
    n_angles = np.unique(np.round(np.mod(2.0 * rotation, 2.0 * np.pi), 9)).size
    # Keep the fit at least twice overdetermined in distinct angles (few positions: fewer harmonics).
    harmonics = tuple(harmonics[: max(0, min(len(harmonics), (n_angles // 2 - 1) // 2))])
    if span < np.pi * 0.95 or not harmonics:
        raise UserError(
            f"Calibration needs a rotation of at least 180 degrees at 6 or more distinct angles; got "
            f"{np.degrees(span):.0f} degrees at {n_angles} angles. Scan a wider pan range "
            "(experiment.pan_range_deg) or give experiment.calibration_path."
        )
    columns = [np.ones_like(rotation)]
    for h in harmonics:
        columns += [np.cos(2 * h * rotation), np.sin(2 * h * rotation)]
    design = np.stack(columns, axis=1)
    coef, *_ = np.linalg.lstsq(design, volts, rcond=None)  # (1 + 2H, K)
    center = coef[0]
    amplitude = np.hypot(coef[1], coef[2])
    phase = np.arctan2(coef[2], coef[1])
    gain = np.mean(nominal.volts_per_decade) * amplitude / np.mean(amplitude)
    angles = nominal.unit_angles[0] + wrap_axial(-(phase - phase[0]) / 2.0 - (nominal.unit_angles - nominal.unit_angles[0])) + (
        nominal.unit_angles - nominal.unit_angles[0]
    )
    return UnitCalibration(center, gain, angles)
