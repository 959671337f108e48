"""``experiment=contrast_scan``: 2-D scans with the five-channel sensor on a pan-tilt unit (thesis 6.4, 6.5.1).

The sensor scans ``n_pan x n_tilt`` directions (thesis: 113 x 26 steps of 2 and
3 degrees) column by column, once per entry of ``experiment.times`` (default:
the 14 scans of the one-day dataset, 17 June 2009, 11:27 to 20:43, with cloud
cover clearing in the evening). Simulated (``sensor=spectral5_sim``, the default:
a backyard scene under the spectral daylight model; the sun moves and the clouds
drift while a scan runs), on hardware (``sensor=spectral5_serial
sensor.port=... pantilt=ptu46 pantilt.port=...``), or replayed from a log
(``sensor=replay pantilt=replay sensor.path=... pantilt.path=...``).

Outputs: channel, contrast and separation images (figs. 6.8/6.9, D.7-D.17,
6.18-6.25), the separated pixels in the UV-IR plane (figs. 6.16/6.17), the
seven stability measures of every single channel and dual contrast against the
first scan, before and after sky/object separation with the ``J_sigma`` lines
learned on natural samples (figs. 6.10-6.15, D.3-D.6; ``stability.csv``),
and the raw scans in ``scans.npz``. Metrics: ``logMSEvar`` and
``logMSEvar_separated`` per feature (mean over the later scans),
``sky_accuracy`` per feature where the true sky is known (simulation; with
``sky_recall`` and ``object_recall`` per feature and scan), and summary scalars.
``experiment.separation=local`` places each line's class border per scan
(Otsu's threshold along the learned direction) instead of at the learned
threshold; see :func:`bionav.spectral.scan.image_discriminant`.
"""

from __future__ import annotations

import datetime as _dt

import numpy as np

from bionav.errors import UserError
from bionav.experiments.common import load_samples
from bionav.experiments.contrast_scan import plots as sp
from bionav.experiments.contrast_scan.config import ContrastScanConfig
from bionav.files import write_csv_atomic
from bionav.light.sun import parse_time

SCAN_TOPIC = "/contrast_scan/scan"
TRUTH_TOPIC = "/contrast_scan/sky_truth"
SENSOR_TOPIC = "/sensor/raw"
PANTILT_TOPIC = "/pantilt/state"
_SCAN_SCHEMA = {
    "type": "object", "title": "bionav.ContrastScan",
    "properties": {"index": {"type": "integer"}, "time": {"type": "string"},
                   "cloud_cover": {"type": "number"}, "cloud_optical_depth": {"type": "number"}},
}
_TRUTH_SCHEMA = {
    "type": "object", "title": "bionav.SkyTruth",
    "description": "True sky mask of a simulated scan, rows of 0/1 (row 0 = highest tilt).",
    "properties": {"index": {"type": "integer"}, "sky": {"type": "array"}},
}


def _per_scan(value, k, n, what):
    v = [value] if isinstance(value, (int, float, str)) else list(value)
    if len(v) == 1:
        return float(v[0])
    if len(v) != n:
        raise UserError(f"experiment.{what} has {len(v)} entries but experiment.times has {n}; give one value or "
                        f"one per scan.")
    return float(v[k])


def _scan_devices(cfg, ctx):
    """The run's sensor and pan-tilt unit (direct pointing when none is configured), the ``pantilt`` node and
    whether either device is simulated; a real sensor without a real pan-tilt unit is refused."""
    from bionav.spectral.scan import DirectPanTilt

    sensor_node = cfg.get("sensor")
    if not sensor_node:
        raise UserError("experiment=contrast_scan needs a sensor: sensor=spectral5_sim (simulation), "
                        "sensor=spectral5_serial sensor.port=... (hardware) or sensor=replay sensor.path=run.mcap.")
    sensor = ctx.plugin("sensor", sensor_node)
    pantilt_node = cfg.get("pantilt")
    pantilt = ctx.plugin("sensor", pantilt_node) if pantilt_node else DirectPanTilt()
    simulated = bool(getattr(sensor, "simulated", False) or getattr(pantilt, "simulated", False))
    if not pantilt_node and not simulated and not hasattr(sensor, "recorded"):
        raise UserError("A real sensor needs a real pan-tilt unit for experiment=contrast_scan: add pantilt=ptu46 "
                        "pantilt.port=/dev/ttyUSB1 (or use sensor=spectral5_sim for a simulated scan).")
    return sensor, pantilt, pantilt_node, simulated


def run(exp: ContrastScanConfig, ctx) -> dict:
    """Run ``experiment=contrast_scan`` with the checked ``exp`` (the rest of the config in ``ctx.cfg``)."""
    from bionav.light.clouds import CloudLayer
    from bionav.light.daylight import SkyState
    from bionav.spectral.scan import ScanGrid, run_scan
    from bionav.world.worlds.garden import backyard_scene

    cfg = ctx.cfg
    times = [parse_time(str(t), what="experiment.times entry", naive_utc=False) for t in exp.times]
    if not times:
        raise UserError("experiment.times is empty; give the scan times, e.g. experiment.times=[2009-06-17T11:27:04+02:00].")
    n_scans = len(times)
    grid = ScanGrid.from_steps(
        n_pan=exp.n_pan, pan_step=np.deg2rad(exp.pan_step_deg),
        n_tilt=exp.n_tilt, tilt_step=np.deg2rad(exp.tilt_step_deg),
        tilt_start=np.deg2rad(exp.tilt_start_deg),
        pan_centre=np.deg2rad(exp.pan_centre_deg),
    )
    sensor, pantilt, pantilt_node, simulated = _scan_devices(cfg, ctx)

    covers = exp.cloud_cover
    depths = exp.cloud_optical_depth
    scan_s = 60.0 * exp.scan_minutes
    cloud_seed = exp.cloud_seed
    t0 = times[0]

    def sky_at(k, t):
        clouds = CloudLayer(cover=_per_scan(covers, k, n_scans, "cloud_cover"),
                            optical_depth=_per_scan(depths, k, n_scans, "cloud_optical_depth"), seed=cloud_seed)
        return SkyState.from_time(t, clouds=clouds, time_s=(t - t0).total_seconds(),
                                  turbidity=exp.turbidity)

    scene = None
    if simulated:
        scene = backyard_scene(sky_at(0, t0), seed=exp.scene_seed)
        for device in (sensor, pantilt):
            if hasattr(device, "attach_simulation"):
                device.attach_simulation(scene, ctx.rng)

    def record_move(state):
        ctx.log.write(PANTILT_TOPIC, state, schema_name="bionav.PanTiltState")

    def record_reading(msg):
        ctx.log.write(SENSOR_TOPIC, msg, schema_name=getattr(sensor, "schema_name", "bionav.Spectral5Reading"),
                      schema=getattr(sensor, "schema", None))

    scans, truths = [], []
    with sensor, pantilt:
        if hasattr(pantilt, "limits") and pantilt_node:
            try:
                ctx.log.write("/pantilt/info", {"limits": list(pantilt.limits()), "resolution": list(pantilt.resolution())},
                              schema_name="bionav.PanTiltInfo")
            except (NotImplementedError, UserError):
                pass
        for k, t in enumerate(times):
            ctx.log.write(SCAN_TOPIC, {"index": k, "time": t.isoformat(),
                                       "cloud_cover": _per_scan(covers, k, n_scans, "cloud_cover"),
                                       "cloud_optical_depth": _per_scan(depths, k, n_scans, "cloud_optical_depth")},
                          schema_name="bionav.ContrastScan", schema=_SCAN_SCHEMA)

            def before_column(j, k=k, t=t):
                if scene is not None:
                    scene.sky = sky_at(k, t + _dt.timedelta(seconds=scan_s * j / grid.shape[1]))
                    scene.prefetch(*_reached(pantilt, np.full(grid.shape[0], grid.pans[j]), grid.tilts))

            scans.append(run_scan(sensor, pantilt, grid, before_column=before_column, on_move=record_move,
                                  on_reading=record_reading, progress=ctx.progress))
            if scene is not None:
                scene.sky = sky_at(k, t + _dt.timedelta(seconds=scan_s / 2))
                p, tl = grid.angles()
                _, truth = scene.render(scene.view_direction(p, tl))
                truths.append(truth)
                ctx.log.write(TRUTH_TOPIC, {"index": k, "sky": truth.astype(int).tolist()},
                              schema_name="bionav.SkyTruth", schema=_TRUTH_SCHEMA)
        if scene is None and hasattr(sensor, "recorded"):
            truths = [np.asarray(m["sky"], dtype=bool) for m in sensor.recorded(TRUTH_TOPIC)]
    scans = np.stack(scans)
    return analyse_scans(scans, times, truths if len(truths) == n_scans else None, exp=exp, ctx=ctx, grid=grid)


def analyse_scans(scans, times, truths, *, exp: ContrastScanConfig, ctx, grid) -> dict:
    """Contrast images, separation, stability series, plots and metrics of a set of scans."""

    from bionav.light.bands import CHANNELS, dual_contrasts
    from bionav.spectral.lda_analysis import learn_discriminants
    from bionav.spectral.scan import separation_images, stability_series
    from bionav.spectral.stability import MEASURES

    sigma = exp.sigma
    disc = learn_discriminants(load_samples(exp.learn), sigma=sigma)
    names = list(CHANNELS) + list(dual_contrasts())
    np.savez_compressed(ctx.dir / "scans.npz", counts=scans, times=np.array([t.isoformat() for t in times]),
                        pans=grid.pans, tilts=grid.tilts)
    # every scan's separation images, once: for the stability after separation, the plots and the accuracy
    seps = [separation_images(s[..., :5], {n: disc[n] for n in names}, threshold=exp.separation) for s in scans]
    rows = stability_series(scans[..., :5], seps, names=names)
    header = ["scan", "time", "feature", "separated", *MEASURES]
    write_csv_atomic(ctx.dir / "stability.csv", header,
                     ([{**r, "time": times[r["scan"]].isoformat()}.get(c, "") for c in header] for r in rows))
    hours = np.array([(t - times[0]).total_seconds() / 3600.0 for t in times])
    if exp.plots:
        _plots(scans, times, hours, rows, disc, seps, ctx.plots, exp.separation)
    metrics: dict = {"n_scans": int(len(scans)), "n_readings": int(scans.shape[0] * scans.shape[1] * scans.shape[2])}
    if len(scans) > 1:
        for sep, key in ((False, "logMSEvar"), (True, "logMSEvar_separated")):
            per = {n: float(np.mean([r["logMSEvar"] for r in rows if r["feature"] == n and r["separated"] == sep]))
                   for n in names}
            metrics[key] = per
            metrics[f"{key}_single_mean"] = _finite_mean([per[n] for n in CHANNELS])
            metrics[f"{key}_dual_mean"] = _finite_mean([per[n] for n in dual_contrasts()])
    if truths is not None:
        acc = {n: float(np.mean([np.mean(sp[n] == tr) for sp, tr in zip(seps, truths)])) for n in names}
        metrics["sky_accuracy"] = acc
        metrics["best_sky_accuracy_feature"] = max(acc, key=acc.get)
        # per scan: the fraction of the true sky called sky, and of the true objects called objects
        metrics["sky_recall"] = {n: [float(np.mean(sp[n][tr])) if tr.any() else None for sp, tr in zip(seps, truths)]
                                 for n in names}
        metrics["object_recall"] = {n: [float(np.mean(~sp[n][~tr])) if (~tr).any() else None
                                        for sp, tr in zip(seps, truths)] for n in names}
    return metrics


def _reached(pantilt, pans, tilts):
    """The poses a pan-tilt unit reaches for commanded ones (its quantisation, if it has one)."""
    try:
        res_pan, res_tilt = pantilt.resolution()
    except (AttributeError, NotImplementedError, UserError):
        return pans, tilts
    return np.round(pans / res_pan) * res_pan, np.round(tilts / res_tilt) * res_tilt


def _finite_mean(values) -> float:
    finite = [v for v in values if np.isfinite(v)]
    return float(np.mean(finite)) if finite else float("nan")


def _plots(scans, times, hours, rows, disc, seps, plots, border):
    from bionav.spectral.scan import image_discriminant

    labels = [t.strftime("%H:%M") for t in times]
    (plots / "scans").mkdir(exist_ok=True)
    for k in range(len(scans)):
        sp.plot_channel_images(scans[k], plots / "scans" / f"channels_{k:02d}.png", title=f"scan {k}: {labels[k]}")
    for k, tag in ((0, "first"), (len(scans) - 1, "last")):
        sp.plot_contrast_images(scans[k], plots / f"contrasts_{tag}.png", title=f"dual-channel contrasts, {labels[k]}")
        sp.plot_separation_images(seps[k], plots / f"separation_{tag}.png",
                                  title=f"sky (black) / objects (white), J_sigma lines of natural samples "
                                        f"({border} threshold), {labels[k]}")
        sp.plot_separated_scatter(scans[k], seps[k]["UV-IR"], disc["UV-IR"], plots / f"separated_uv_ir_{tag}.png",
                                  title=f"UV-IR pixels classified, {labels[k]}",
                                  local=(image_discriminant(scans[k, ..., :5], "UV-IR", disc["UV-IR"], threshold=border)
                                         if border == "local" else None))
    if len(scans) > 1:
        sp.plot_stability(rows, hours[1:], plots / "stability.png", separated=False)
        sp.plot_stability(rows, hours[1:], plots / "stability_separated.png", separated=True)
