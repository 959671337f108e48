"""Chapter 4: the polarized-light compass."""

from __future__ import annotations

from bionav.thesis.items.base import Context, copy_plot, item, metric
from bionav.thesis.outcome import Check, Outcome, Row
from bionav.thesis.presets import Preset
from bionav.thesis.runs import RunSpec


# ---------------------------------------------------------------------------
# chapter 4: polarized-light compass
# ---------------------------------------------------------------------------
def _pol(mode: str, *extra: str) -> RunSpec:
    return RunSpec(("experiment=pol_compass", f"mode={mode}", *extra), group="pol_compass")


def _pol_filter(p: Preset) -> RunSpec:
    return _pol("filter_test", f"experiment.samples_per_step={p.pol_samples}")


def _pol_vs_em(p: Preset) -> RunSpec:
    return _pol("vs_em_compass", f"experiment.vs_em.samples={p.pol_vs_em_samples}")


def _pol_rotation(p: Preset) -> RunSpec:
    return _pol("rotation", f"experiment.samples_per_step={p.pol_samples}")


@item("fig4_2", "Fig. 4.2",
      "one check (indirect, bionav keeps the unit voltages only in run.mcap and the plot): the compass' "
      "axial output follows the filter angle (heading MAE <= 5 deg), which needs the three units' outputs "
      "shifted by 60 degrees as built", aliases=("4.2",))
class _Fig42:
    @staticmethod
    def runs(p: Preset) -> list[RunSpec]:
        return [_pol_filter(p)]

    @staticmethod
    def evaluate(ctx: Context, specs: list[RunSpec]) -> Outcome:
        out = Outcome()
        res = ctx.result(specs[0])
        mae = metric(res, "heading_mae_deg")
        out.rows.append(Row("heading MAE against the filter angle (deg)", None, mae))
        out.checks.append(Check("axial heading MAE against the filter angle <= 5 deg",
                                None if mae is None else mae <= 5.0, "" if mae is None else f"{mae:.2f} deg"))
        copy_plot(ctx, res, "plots/fig4_2_unit_voltages.png", "fig4_2.png", out)
        return out


@item("fig4_4", "Fig. 4.4",
      "the thesis gives no number ('works as expected'); check: the averaged axial RMSE against the "
      "electromagnetic compass <= 10 deg", aliases=("4.4",))
class _Fig44:
    @staticmethod
    def runs(p: Preset) -> list[RunSpec]:
        return [_pol_vs_em(p)]

    @staticmethod
    def evaluate(ctx: Context, specs: list[RunSpec]) -> Outcome:
        out = Outcome()
        res = ctx.result(specs[0])
        v = metric(res, "averaged_rmse_deg")
        out.rows.append(Row("averaged axial RMSE against the TCM2 (deg)", None, v))
        out.rows.append(Row("raw axial RMSE against the TCM2 (deg)", None, metric(res, "heading_rmse_deg")))
        out.checks.append(Check("averaged RMSE <= 10 deg", None if v is None else v <= 10.0))
        copy_plot(ctx, res, "plots/fig4_4_averaged.png", "fig4_4.png", out)
        return out


@item("fig4_5", "Fig. 4.5",
      "the compass cannot tell 0 from 180 degrees at the zenith: in a rotation at tilt 0 the error function "
      "resolves the candidate pair of eq. 4.6 for at most 5 % of the samples (resolved_fraction); the figure "
      "plots the raw first candidate against the electromagnetic compass", aliases=("4.5",))
class _Fig45:
    @staticmethod
    def runs(p: Preset) -> list[RunSpec]:
        return [_pol_vs_em(p), _pol_rotation(p)]

    @staticmethod
    def evaluate(ctx: Context, specs: list[RunSpec]) -> Outcome:
        out = Outcome()
        vs, rot = ctx.result(specs[0]), ctx.result(specs[1])
        frac = metric(rot, "resolved_fraction")
        out.rows.append(Row("resolved fraction of the candidate pair, rotation at tilt 0", None, frac))
        out.rows.append(Row("axial heading MAE of the rotation (deg)", None, metric(rot, "heading_mae_deg")))
        out.checks.append(Check("the pair (phi, phi + pi) stays unresolved (resolved fraction <= 0.05)",
                                None if frac is None else frac <= 0.05))
        copy_plot(ctx, vs, "plots/fig4_5_raw.png", "fig4_5.png", out)
        copy_plot(ctx, rot, "plots/heading_vs_pan.png", "fig4_5_rotation.png", out)
        return out


@item("fig4_6", "Fig. 4.6",
      "a clear and a cloudy sky scanned: the residual of the measured e-vectors against the sky model "
      "(heading_rmse_deg of the scan) is larger under clouds (scattered orientations) than under a clear sky",
      aliases=("4.6",))
class _Fig46:
    @staticmethod
    def runs(p: Preset) -> list[RunSpec]:
        return [_pol("evector_scan", "experiment.sky.cloud_cover=0.0"),
                _pol("evector_scan", "experiment.sky.cloud_cover=0.6")]

    @staticmethod
    def evaluate(ctx: Context, specs: list[RunSpec]) -> Outcome:
        out = Outcome()
        clear, cloudy = ctx.result(specs[0]), ctx.result(specs[1])
        a, b = metric(clear, "heading_rmse_deg"), metric(cloudy, "heading_rmse_deg")
        out.rows.append(Row("e-vector residual RMSE, clear sky (deg)", None, a))
        out.rows.append(Row("e-vector residual RMSE, cloud cover 0.6 (deg)", None, b))
        out.rows.append(Row("mean degree of polarization, clear sky", None, metric(clear, "mean_degree")))
        out.rows.append(Row("mean degree of polarization, cloud cover 0.6", None, metric(cloudy, "mean_degree")))
        out.checks.append(Check("clouds scatter the e-vectors (residual larger than under a clear sky)",
                                None if a is None or b is None else b > a))
        copy_plot(ctx, clear, "plots/fig4_6_evector_field.png", "fig4_6_clear.png", out)
        copy_plot(ctx, cloudy, "plots/fig4_6_evector_field.png", "fig4_6_cloudy.png", out)
        out.notes.append("Simulated skies (the thesis' recordings of 29 July and 4 August 2009 are not available).")
        return out
