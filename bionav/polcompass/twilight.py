"""What the physics allows at dusk: the lowest sun at which a POL-OP array can still read an e-vector.

Two pieces: the count noise of one unit (:func:`bionav.polcompass.decoders.angle_noise`: an e-vector
angle noise ``sigma_a = sqrt(2) sigma_c / (2 C * 2 d sqrt(J / 2))`` for ``C`` counts per photodiode,
``J`` POL-OPs, degree ``d`` and count noise ``sigma_c``) and the twilight sky's brightness
(:func:`bionav.light.twilight.twilight_zenith_radiance`: single scattering with the Earth's shadow).
A unit is readable while ``sigma_a`` stays below the decoder's model-error scale (``sky_fit``'s
``model_error_deg``, 10 degrees), i.e. while it reads at least :func:`readable_counts` per photodiode;
scaling a measured count at a reference sun elevation with the sky's brightness gives the sun
elevation where that ends (:func:`lowest_readable_elevation`). Radians throughout.
"""

from __future__ import annotations

import numpy as np


def readable_counts(noise_counts: float, *, degree: float, max_angle_noise: float, pol_ops: int = 2) -> float:
    """Fewest counts per photodiode for an e-vector angle noise of at most ``max_angle_noise`` (radians).

    The inverse of :func:`bionav.polcompass.decoders.angle_noise`:
    ``C = sqrt(2) sigma_c / (4 d sqrt(J / 2) max_angle_noise)``.
    """
    if not (noise_counts >= 0 and degree > 0 and max_angle_noise > 0 and pol_ops >= 1):
        raise ValueError("noise_counts >= 0, degree > 0, max_angle_noise > 0 and pol_ops >= 1 are needed")
    return float(np.sqrt(2.0) * noise_counts / (4.0 * degree * np.sqrt(pol_ops / 2.0) * max_angle_noise))


def lowest_readable_elevation(counts: float, elevation: float, *, noise_counts: float, degree: float,
                              max_angle_noise: float, pol_ops: int = 2, optical_depth: float = 0.25,
                              lowest: float = np.deg2rad(-18.0)) -> float:
    """Sun elevation (radians) below which a unit reads too few counts for an e-vector.

    Parameters
    ----------
    counts : float
        Counts per photodiode measured with the sun at ``elevation`` (radians).
    noise_counts, degree, max_angle_noise, pol_ops
        As :func:`readable_counts`.
    optical_depth : float
        The sky model's vertical optical depth (:func:`bionav.light.twilight.twilight_zenith_radiance`).
    lowest : float
        Where the search stops (astronomical twilight ends at -18 degrees).

    Returns
    -------
    float
        Radians; ``elevation`` itself if ``counts`` are already too few, ``lowest`` if still readable there.
    """
    from bionav.light.twilight import twilight_zenith_radiance

    need = readable_counts(noise_counts, degree=degree, max_angle_noise=max_angle_noise, pol_ops=pol_ops)
    if counts < need:
        return float(elevation)
    grid = np.linspace(float(elevation), float(lowest), int(np.ceil(np.degrees(elevation - lowest) * 10)) + 1)
    predicted = counts * twilight_zenith_radiance(grid, optical_depth=optical_depth) / twilight_zenith_radiance(
        float(elevation), optical_depth=optical_depth)
    below = np.flatnonzero(predicted < need)
    if below.size == 0:
        return float(lowest)
    j = below[0]  # interpolate log counts between the last readable and the first unreadable grid point
    a, b = np.log(predicted[j - 1]), np.log(predicted[j])
    f = (a - np.log(need)) / (a - b)
    return float(grid[j - 1] + f * (grid[j] - grid[j - 1]))
