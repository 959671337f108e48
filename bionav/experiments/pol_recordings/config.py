"""Config of ``experiment=pol_recordings`` (issue 15); its top-level ``recordings.*`` node is
:class:`bionav.polcompass.recordings_config.RecordingsConfig`.

Angles in degrees only in keys ending ``_deg``. Checked by the runner before the run
(:func:`bionav.experiments.settings.experiment_config`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from bionav.validation import bounded


@dataclass
class PolRecordingsConfig:
    """``experiment=pol_recordings`` (issue 15): decode recorded POL-OP rotations, score every sample.

    compare : decoders scored in ``sessions.csv`` besides ``decoder=``.
    simulate : also decode each session simulated in the sky model (the sim-to-real gap), with
        ``sim_noise`` (count noise, fraction), ``sim_gain_sigma`` (photodiode gain spread),
        ``sim_canopy_cover`` (cloud-map cover standing in for canopy gaps), ``sim_max_degree``.
        ``sim_gain_sigma`` = 0.1 is measured: the standard deviation of the self-calibrated log photodiode
        gains of the recorded sensor's healthy units (``recordings.calibration=auto``: 0.096; docs/polcompass.md),
        ``sim_angle_sigma_deg`` = 2 that of their polarizer offsets (2.1 degrees);
        ``sim_canopy_cover`` = 0 is fitted (with the view field, seeds 0-3, canopy sessions only) as the cover whose
        simulated canopy sessions score closest to the real ones: with the cloud map a snapshot of a ``CloudLayer``,
        covers 0 / 0.01 / 0.02 / 0.05 gave 3.65 / 3.73 / 3.75 / 3.92 degrees against 2.87 real, so no cover above 0
        helps (docs/polcompass.md). ``sim_repeats``: each
        session is simulated that many times (each its own device and cloud draw), errors pooled.
    sim_view_sigma : each photodiode's own smooth departure from the shared sky ring (log counts, world frame;
        :func:`bionav.polcompass.sessions.view_field`); 0.1 is *fitted* on the counts, not on heading errors: the
        self-calibration's ring residual of the 18 daylight sessions has a median of 0.087 (0.081-0.101 leaving one
        day out), and the simulation's residual is about 0.9 ``sim_view_sigma``. ``sim_view_shared``: the fraction of that field's
        variance a unit's photodiodes have in common (it cancels in a POL-OP's log ratio; the ring residual cannot
        tell it): 0.8 is *fitted* on the daylight heading MAE (0 / 0.5 / 0.8 / 0.95 over seeds 0-3: simulated 4.7 /
        4.1 / 3.6 / 3.3 degrees against 3.6 real, means of the seeds) and checked on dusk and canopy (docs/polcompass.md).
        With the gain split below and ``recordings.reference=stitched`` it still matches (2.77 simulated against
        2.73 real by day). ``sim_gain_shared``: the fraction of the log-gain variance a unit's photodiodes have in
        common (it cancels in a POL-OP's log ratio); 0.5 is *measured* on the counts: the healthy units'
        self-calibrated log gains spread by 0.096, the log ratios of their POL-OP pairs by 0.094 rms, so each
        photodiode's own part is 0.094 / sqrt(2) = 0.066 and the unit's common part 0.070 (a share of 0.53).
        ``sim_tilt_sigma_deg``, ``sim_azimuth_sigma_deg``:
        unit pointing tolerances (0: tilts up to 6 degrees gave ring residuals of 0.01-0.08 only).
    record_samples : every decoded sample of the chosen decoder into run.mcap.
    """

    name: str = "pol_recordings"
    compare: list[str] = field(
        default_factory=lambda: ["sky_fit", "two_unit", "sol", "four_zeros", "eigenvector", "mean_vector"])
    simulate: bool = True
    sim_noise: float = bounded(0.01, ge=0.0, le=1.0)
    sim_gain_sigma: float = bounded(0.1, ge=0.0, le=1.0)
    sim_canopy_cover: float = bounded(0.0, ge=0.0, le=1.0)
    sim_repeats: int = bounded(4, ge=1, le=100)
    sim_angle_sigma_deg: float = bounded(2.0, ge=0.0, le=45.0)
    sim_max_degree: float = bounded(0.5, gt=0.0, le=1.0)
    sim_tilt_sigma_deg: float = bounded(0.0, ge=0.0, le=45.0)
    sim_azimuth_sigma_deg: float = bounded(0.0, ge=0.0, le=45.0)
    sim_view_sigma: float = bounded(0.1, ge=0.0, le=2.0)
    sim_view_shared: float = bounded(0.8, ge=0.0, le=1.0)
    sim_gain_shared: float = bounded(0.5, ge=0.0, le=1.0)
    record_samples: bool = True
