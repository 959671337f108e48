"""``experiment=pol_compass``: the polarized-light compass experiments of thesis chapter 4.

Modes (``mode=<name>``, i.e. ``experiment.mode``):

``filter_test``
    Thesis 4.2.1, fig. 4.2: the compass under unpolarized light seen through
    one extra polarizer; the pan-tilt unit turns the compass against the
    filter in 3 degree steps, 100 samples each; mean unit voltages per angle.
``rotation``
    The pan-tilt unit turns the compass through its whole pan range (about
    +-159 degrees, more than the signal's 180 degree period), ``N`` samples
    per step; heading error against the pan angle after removing the constant
    offset, axial (modulo 180 degrees) unless the error function can resolve
    the candidate pair (only for tilted views, ``experiment.tilt_deg != 0``).
``vs_em_compass``
    Thesis 4.2.2, figs. 4.4-4.5: against the TCM2 electromagnetic compass on
    the same plate at 18 positions, 100 samples each (averaged and raw).
``evector_scan``
    Thesis 4.2.3, fig. 4.6: a pan/tilt grid over the sky, e-vector angle and
    degree per point in a polar plot, against the sky model.
``partial_sky``
    Thesis 9.1 (future work), simulation: heading error of a scanning compass
    (a model fitted to every clear patch, which also resolves the pair) and of
    the zenith-only compass against the clear-sky fraction and the sun
    elevation.

Metrics: ``heading_rmse_deg``, ``heading_mae_deg``, ``n_samples`` (plus
``axial``, ``resolved_fraction`` and mode-specific keys). The simulated and
the real compass share everything after the ADC; every raw reading is in
``run.mcap`` (see :mod:`bionav.plugins.sensors.replay`), and a replay
reproduces the metrics exactly.
"""

from __future__ import annotations

from contextlib import ExitStack
from typing import Any

import numpy as np
from omegaconf import DictConfig, OmegaConf

from bionav.errors import UserError
from bionav.experiments.pol_compass.config import PolCompassConfig
from bionav.experiments.pol_compass.modes import (
    evector_scan_mode,
    partial_sky_mode,
    rotation_mode,
    sensor_calibration,
    vs_em_mode,
)
from bionav.experiments.pol_compass.session import (
    CALIBRATION_SCHEMA,
    CALIBRATION_TOPIC,
    FITTED_MAX_DEGREE,
    SESSION_SCHEMA,
    SESSION_TOPIC,
    CompassSession,
    cloud_field,
    resolve_sun,
    sky_model,
    start_fakes,
)
from bionav.validation import typed_config

#: the readings experiment=pol_compass reads: the compass' counts per line, recorded POL-OP arrays, a replayed log
SENSOR_READINGS = ("bionav.PolCompassReading", "bionav.PolOpArrayReading", "bionav.ReplayedReading")

# ---------------------------------------------------------------------------
# glue
# ---------------------------------------------------------------------------
def run_session(exp, devices: dict, *, write, rng, scene=None, plots=None, out_dir=None, progress=None) -> dict:
    """Run one mode with opened devices; everything is recorded through ``write``.

    Parameters
    ----------
    exp : PolCompassConfig or mapping
        The checked ``experiment`` node (a mapping is typed and checked here).
    devices : dict
        ``sensor``, ``pantilt``, ``reference`` plugin instances (opened).
    write : callable
        ``write(topic, message, *, schema_name, schema)``.
    rng : numpy.random.Generator
        The scene's generator (cloud fields, random mount headings).
    scene : CompassScene, optional
        The simulated world (if anything is simulated).
    plots, out_dir : Path, optional
        Where figures and tables go (``None``: none written).
    progress : callable, optional
    """
    if not isinstance(exp, PolCompassConfig):  # defaults and ranges
        exp = typed_config(exp, PolCompassConfig, key="experiment", what="experiment=pol_compass")
    mode = exp.mode
    sensor = devices["sensor"]
    recorded = None
    if hasattr(sensor, "recorded"):
        messages = sensor.recorded(SESSION_TOPIC)
        recorded = messages[0] if messages else None
    sun, time_utc = resolve_sun(exp.sky, recorded_session=recorded)
    if recorded is not None:
        true_mount = recorded.get("true_mount_heading")
        sim_info = recorded.get("sim")
    else:
        true_mount = None if scene is None or mode == "partial_sky" else float(scene.mount_heading)
        sim_info = None if scene is None else simulation_parameters(exp, sensor)
    session = CompassSession(sensor, devices.get("pantilt"), devices.get("reference"), write, scene, sun,
                             progress or (lambda it, desc="", total=None: it), true_mount)
    write(SESSION_TOPIC, {"mode": mode, "time_utc": time_utc, "sun_azimuth": float(sun.azimuth),
                          "sun_elevation": float(sun.elevation), "true_mount_heading": true_mount, "sim": sim_info},
          schema_name="bionav.PolCompassSession", schema=SESSION_SCHEMA)
    session.record_pantilt_info()
    if devices.get("decoder") is None:  # the thesis compass: sensor.calibration=FILE, or what a replayed run applied
        session.fixed_calibration = sensor_calibration(sensor)
        if session.fixed_calibration is not None:
            write(CALIBRATION_TOPIC, session.fixed_calibration, schema_name="bionav.PolCompassCalibration",
                  schema=CALIBRATION_SCHEMA)
    if sim_info:  # say which simulation parameters were used (also in a replay of a simulated run)
        metrics = _run_mode(session, exp, devices, mode, scene=scene, rng=rng, plots=plots, out_dir=out_dir)
        return {**metrics, **sim_info}
    return _run_mode(session, exp, devices, mode, scene=scene, rng=rng, plots=plots, out_dir=out_dir)


def simulation_parameters(exp, sensor) -> dict:
    """The simulation's parameters for ``metrics.json``: ``sim_parameters`` (``fitted`` to the real recordings or
    ``thesis``), the sky's maximum degree and the simulated device's tolerances where the sensor has them."""
    sky = exp.sky
    how = sky.parameters
    max_degree = sky.max_degree
    if max_degree is None:
        from bionav.light import max_degree_from_turbidity

        max_degree = FITTED_MAX_DEGREE if how == "fitted" else max_degree_from_turbidity(sky.turbidity)
    info = {"sim_parameters": how, "sim_max_degree": float(max_degree)}
    config = getattr(sensor, "config", None)
    for key in ("angle_sigma_deg", "sensitivity_sigma", "gain_sigma", "noise_v"):
        if config is not None and hasattr(config, key):
            info[f"sim_{key}"] = float(getattr(config, key))
    return info


def _run_mode(session, exp, devices, mode, *, scene, rng, plots, out_dir) -> dict:
    """Run ``mode`` on an opened session (see :func:`run_session`)."""
    sun = session.sun
    if devices.get("decoder") is not None:  # recorded POL-OP array counts (sensor=recording, or its replay)
        from bionav.experiments.pol_compass.recorded import recorded_rotation_mode

        if mode != "rotation":
            raise UserError(f"recorded array counts support mode=rotation only, not mode={mode}.")
        return recorded_rotation_mode(session, exp, sensor_config=devices["array_config"], decoder=devices["decoder"],
                                      plots=plots)
    unit_angles = np.deg2rad(np.asarray(exp.unit_angles_deg, float))
    if scene is not None and mode != "partial_sky":
        from bionav.light import PolarizerLamp

        if mode == "filter_test":
            scene.source = PolarizerLamp(np.deg2rad(exp.filter.axis_deg), exp.filter.efficiency)
        else:
            scene.source = sky_model(exp.sky, sun, clouds=cloud_field(exp.sky, rng))
    kwargs = {"unit_angles": unit_angles, "plots": plots, "out_dir": out_dir}
    if mode in ("filter_test", "rotation"):
        return rotation_mode(session, exp, filter_test=mode == "filter_test", **kwargs)
    if mode == "vs_em_compass":
        return vs_em_mode(session, exp, **kwargs)
    if mode == "evector_scan":
        return evector_scan_mode(session, exp, **kwargs)
    return partial_sky_mode(session, exp, rng_scene=rng, **kwargs)


def _node_dict(node) -> dict | None:
    if node is None:
        return None
    return OmegaConf.to_container(node, resolve=True) if isinstance(node, DictConfig) else dict(node)


def _recorded_array(node: dict) -> bool:
    """Whether the sensor plays recorded POL-OP array counts (``sensor=recording`` or a replay of such a run)."""
    if node.get("name") == "recording":
        return True
    if node.get("name") == "replay":
        from bionav.experiments.pol_compass.recorded import is_array_reading
        from bionav.plugins.sensors.replay import read_topics

        try:
            first = read_topics(node.get("path", "run.mcap")).get(node.get("topic") or "/sensor/raw", [None])[0]
        except UserError:
            return False  # the replay plugin reports the missing log itself
        return is_array_reading(first)
    return False


def _check_reading_kind(sensor_class, name) -> None:
    """Refuse a sensor whose readings experiment=pol_compass cannot read (before the session, not after a rotation)."""
    kind = getattr(sensor_class, "schema_name", None)
    if kind not in SENSOR_READINGS:
        raise UserError(f"sensor={name} gives {kind} readings, but experiment=pol_compass reads "
                        f"{' or '.join(SENSOR_READINGS[:2])} (counts per POL-OP line or unit); choose sensor="
                        "polcompass_sim, polcompass_serial, recording or replay, or a plugin giving such readings "
                        "(docs/plugins.md, 'Sensors').")


def run(exp: PolCompassConfig, ctx) -> dict[str, Any]:
    """Run ``experiment=pol_compass`` with the checked ``exp`` (the rest of the config in ``ctx.cfg``)."""
    from bionav.polcompass import CompassScene, UnitCalibration

    cfg = ctx.cfg
    if cfg.get("sensor") is None or not cfg.sensor.get("name"):
        raise UserError("experiment=pol_compass needs a compass: sensor=polcompass_sim, polcompass_serial or replay.")
    if exp.calibration == "file" and exp.calibration_path:  # a bad file is refused before the session, not after it
        UnitCalibration.load(exp.calibration_path, units=len(exp.unit_angles_deg))
    nodes = {
        "sensor": _node_dict(cfg.sensor),
        "pantilt": _node_dict(cfg.get("pantilt")) if cfg.get("pantilt") and cfg.pantilt.get("name") else None,
        "reference": _node_dict(exp.reference) if exp.mode == "vs_em_compass" else None,
    }
    rng_scene, rng_sensor, rng_reference, rng_fakes = ctx.rng.spawn(4)
    from bionav import registry

    recorded_array = _recorded_array(nodes["sensor"])
    if recorded_array:
        nodes["pantilt"] = None  # the recorded robot turned itself; its yaw is the reference

    classes = {role: registry.load_plugin("sensor", node["name"]) for role, node in nodes.items() if node is not None}
    _check_reading_kind(classes.get("sensor"), (nodes["sensor"] or {}).get("name"))
    simulated = any(getattr(c, "simulated", False) for c in classes.values())
    fake_devices = exp.fake_devices
    needs_scene = simulated or fake_devices or exp.mode == "partial_sky"
    scene = None
    if needs_scene:
        from bionav.light import SkyModel, SunPosition

        scene = CompassScene(
            SkyModel(SunPosition(0.0, np.pi / 4)),  # replaced by the mode's source
            mount_heading=np.deg2rad(exp.sky.mount_heading_deg),
            magnetic_declination=np.deg2rad(exp.sky.magnetic_declination_deg),
        )
    with ExitStack() as stack:
        if fake_devices:
            start_fakes(stack, nodes, scene, rng_fakes)
        devices = {}
        streams = {"sensor": rng_sensor, "pantilt": None, "reference": rng_reference}
        for role, node in nodes.items():
            if node is None:
                devices[role] = None
                continue
            plugin = ctx.plugin("sensor", node)
            if role == "reference":
                plugin.config_prefix = "experiment.reference"
            if getattr(plugin, "simulated", False):
                plugin.attach_simulation(scene, streams[role])
            plugin.open()
            stack.callback(plugin.close)
            devices[role] = plugin
        if recorded_array:
            cfg_dec = cfg.get("decoder")
            node = cfg_dec if cfg_dec is not None and cfg_dec.get("name") else {"name": "sky_fit"}
            devices["decoder"] = ctx.plugin("decoder", node)
            if nodes["sensor"]["name"] == "recording":
                devices["array_config"] = devices["sensor"].config
            else:  # a replay: the array keys (and calibration) the recorded run used
                from bionav.experiments.pol_compass.recorded import recorded_array_config

                recorded = devices["sensor"].recorded(CALIBRATION_TOPIC)
                devices["array_config"] = recorded_array_config(recorded[-1] if recorded else None)
        metrics = run_session(
            exp,
            devices,
            write=ctx.log.write,
            rng=rng_scene,
            scene=scene,
            plots=ctx.plots,
            out_dir=ctx.dir,
            progress=ctx.progress,
        )
    return metrics
