"""Plumbing of ``experiment=pol_compass``: devices, simulated scene, fake devices, recording.

Every raw reading goes to ``run.mcap`` the moment it is taken (topics and
schemas as documented in :mod:`bionav.plugins.sensors.replay`), and all
processing works on those recorded dicts, so ``sensor=replay
pantilt=replay`` reproduces a session's metrics exactly.
"""

from __future__ import annotations

import datetime as _dt
from contextlib import ExitStack
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from bionav.errors import UserError
from bionav.plugins.sensors.replay import PANTILT_INFO_TOPIC, PANTILT_TOPIC, SENSOR_TOPIC

SESSION_TOPIC = "/pol_compass/session"
# Fitted on the real POL-OP recordings (experiment=pol_recordings, docs/polcompass.md "Sim-to-real"): with this
# maximum degree the simulated units read the measured median degree of the daylight sessions (0.36-0.40).
FITTED_MAX_DEGREE = 0.5
CALIBRATION_TOPIC = "/pol_compass/calibration"
REFERENCE_TOPIC = "/reference/raw"

PANTILT_INFO_SCHEMA = {
    "type": "object",
    "properties": {
        "limits": {"type": "array", "items": {"type": "number"}, "description": "pan min/max, tilt min/max, radians"},
        "resolution": {"type": "array", "items": {"type": "number"}, "description": "pan, tilt radians per position"},
    },
}
SESSION_SCHEMA = {
    "type": "object",
    "properties": {
        "mode": {"type": "string"},
        "time_utc": {"type": ["string", "null"]},
        "sun_azimuth": {"type": "number", "description": "radians CCW from east"},
        "sun_elevation": {"type": "number", "description": "radians"},
        "true_mount_heading": {"type": ["number", "null"], "description": "simulated mount heading, radians CCW from east"},
        "sim": {"type": ["object", "null"], "description": "simulation parameters (sim_parameters: fitted|thesis, ...)"},
    },
}
CALIBRATION_SCHEMA = {
    "type": "object",
    "title": "Calibration the compass was decoded with (sensor.calibration, or recorded for a replay)",
    "properties": {
        "kind": {"type": "string", "enum": ["units", "array"], "description": "units: UnitCalibration (thesis "
                 "compass); array: ArrayCalibration (POL-OP array)"},
        "source": {"type": "string", "description": "file path, 'auto' (self-calibrated) or 'none'"},
        "calibration": {"type": ["object", "null"], "description": "the calibration's to_dict(); null: nominal"},
        "array_config": {"type": ["object", "null"], "description": "how the recorded array reads (sensor=recording)"},
    },
    "required": ["kind", "source", "calibration"],
}


@dataclass
class CompassSession:
    """Devices of one compass session and the recorder.

    Attributes
    ----------
    sensor : SensorPlugin
        The polarized-light compass (``sensor=``).
    pantilt : PanTiltPlugin or None
    reference : SensorPlugin or None
        The electromagnetic reference compass (``vs_em_compass``).
    write : callable
        ``write(topic, message, *, schema_name, schema)`` (``ctx.log.write``).
    scene : CompassScene or None
        The simulated world, when anything is simulated.
    sun : SunPosition
        Sun position the compass assumes (resolved once per session).
    progress : callable
        ``progress(iterable, desc=..., total=...)``.
    true_mount_heading : float or None
        The simulated mount heading (radians CCW from east), recorded so that
        replays report the same simulation-only metrics; ``None`` for hardware.
    fixed_calibration : dict or None
        A calibration message (:data:`CALIBRATION_SCHEMA`) that replaces
        ``experiment.calibration``: the file ``sensor.calibration`` names, or
        the one a replayed run recorded; ``None``: ``experiment.calibration``.
    """

    sensor: Any
    pantilt: Any
    reference: Any
    write: Callable[..., None]
    scene: Any
    sun: Any
    progress: Callable = field(default=lambda it, desc="", total=None: it)
    true_mount_heading: float | None = None
    fixed_calibration: dict | None = None

    def read(self) -> dict:
        """Take and record one compass reading."""
        message = self.sensor.read()
        self.write(SENSOR_TOPIC, message, schema_name=self.sensor.schema_name, schema=self.sensor.schema)
        return message

    def read_reference(self) -> dict:
        """Take and record one reference-compass reading."""
        if self.reference is None:
            raise UserError("this mode needs a reference compass; set experiment.reference.name (tcm2, tcm2_sim or replay).")
        message = self.reference.read()
        self.write(REFERENCE_TOPIC, message, schema_name=self.reference.schema_name, schema=self.reference.schema)
        return message

    def move(self, pan: float, tilt: float) -> dict:
        """Move the pan-tilt unit and record the reached state."""
        if self.pantilt is None:
            raise UserError("this mode needs a pan-tilt unit; choose one with pantilt=sim|ptu46|replay.")
        state = self.pantilt.move_to(float(pan), float(tilt))
        self.write(PANTILT_TOPIC, state, schema_name=self.pantilt.schema_name, schema=self.pantilt.schema)
        return state

    def record_pantilt_info(self) -> None:
        """Record the pan-tilt unit's limits and resolution (once, after opening)."""
        if self.pantilt is None:
            return
        info = {"limits": [float(v) for v in self.pantilt.limits()], "resolution": [float(v) for v in self.pantilt.resolution()]}
        self.write(PANTILT_INFO_TOPIC, info, schema_name="bionav.PanTiltInfo", schema=PANTILT_INFO_SCHEMA)


def resolve_sun(sky, *, recorded_session: dict | None):
    """The sun position of a session.

    A replayed session uses the recorded position; otherwise ``sky.time``
    (ISO-8601, or ``now``) with ``latitude_deg``/``longitude_deg`` through
    PyEphem, or the given ``sun_azimuth_deg``/``sun_elevation_deg`` when
    ``time`` is null.

    Returns
    -------
    sun : SunPosition
    time_utc : str or None
    """
    from bionav.light import SunPosition, parse_time, sun_position

    if recorded_session is not None:
        return SunPosition(
            float(recorded_session["sun_azimuth"]), float(recorded_session["sun_elevation"])
        ), recorded_session.get("time_utc")
    time = sky.time
    if time is None:
        return SunPosition(np.deg2rad(sky.sun_azimuth_deg), np.deg2rad(sky.sun_elevation_deg)), None
    when = _dt.datetime.now(_dt.timezone.utc) if time == "now" else time
    sun = sun_position(when, latitude_deg=sky.latitude_deg, longitude_deg=sky.longitude_deg)

    return sun, parse_time(when).astimezone(_dt.timezone.utc).isoformat()


def sky_model(sky, sun, *, clouds=None):
    """The :class:`~bionav.light.SkyModel` the typed ``experiment.sky`` node
    (:class:`~bionav.experiments.pol_compass.config.PolSkyConfig`) describes."""
    from bionav.light import SkyModel, max_degree_from_turbidity

    max_degree = sky.max_degree
    if max_degree is None:
        fitted = sky.parameters == "fitted"
        max_degree = FITTED_MAX_DEGREE if fitted else max_degree_from_turbidity(sky.turbidity)
    return SkyModel(
        sun,
        max_degree=float(max_degree),
        neutral_point_separation=np.deg2rad(sky.neutral_point_separation_deg),
        clouds=clouds,
    )


def cloud_field(sky, rng, *, cover: float | None = None):
    """A cloud field for the typed ``experiment.sky`` node (None for a clear sky)."""
    from bionav.light import random_cloud_map

    cover = sky.cloud_cover if cover is None else float(cover)
    if cover <= 0.0:
        return None
    return random_cloud_map(rng, cover=cover, correlation_length=np.deg2rad(sky.cloud_correlation_deg))


def start_fakes(stack: ExitStack, nodes: dict, scene, rng) -> dict:
    """Serve fake devices for the serial plugins among ``nodes`` and point their ports at them.

    Parameters
    ----------
    stack : ExitStack
        Closes the fakes at the end of the session.
    nodes : dict
        Role -> plain config dict (``name`` plus parameters); updated in place.
    scene : CompassScene
        The simulated world driving the fakes.
    rng : numpy.random.Generator
        Noise of the fake devices.

    Returns
    -------
    dict
        Role -> the fake device (tests inject faults through it).
    """
    from bionav.plugins.sensors.fakes.dlpio8 import CompassCounts, FakeDLPIO8
    from bionav.plugins.sensors.fakes.ptu46 import FakePTU46
    from bionav.plugins.sensors.fakes.tcm2 import FakeTCM2
    from bionav.plugins.sensors.polcompass_sim import PolCompassSimConfig, build_hardware
    from bionav.plugins.sensors.tcm2_sim import simulated_attitude

    fakes = {}
    streams = iter(rng.spawn(len(nodes)))  # one generator per device thread (Generators are not thread-safe)
    for role, node in nodes.items():
        stream = next(streams)
        if node is None:
            continue
        name = node.get("name")
        if name == "polcompass_serial":
            hardware = build_hardware(PolCompassSimConfig(lines=list(node.get("lines", [1, 2, 3]))))
            fake = FakeDLPIO8(CompassCounts(hardware, scene, stream, lines=node.get("lines", [1, 2, 3])))
        elif name == "ptu46":
            fake = FakePTU46(scene.set_pose)
        elif name == "tcm2":
            fake = FakeTCM2(lambda stream=stream: simulated_attitude(scene, stream, noise_deg=0.3))
        else:
            continue
        stack.enter_context(fake)
        node["port"] = fake.port
        fakes[role] = fake
    return fakes
