"""The contract between sensor / pan-tilt plugins and the experiments that use them.

A plugin in the ``bionav.sensors`` entry-point group is a class with a
``Config`` dataclass (its parameters; Hydra validates them, the user sets them
as ``sensor.<field>=...`` or ``pantilt.<field>=...``) constructed as
``Plugin(config)``. ``config_group`` says where the user selects it:
``"sensor"`` (default) or ``"pantilt"``.

Readings are JSON messages
--------------------------
:meth:`SensorPlugin.read` returns one *raw reading* as a JSON-ready ``dict``
(ADC counts, device lines: what the device said, before any processing) and
the class attributes ``schema_name`` / ``schema`` describe it. Experiments
write every reading to ``run.mcap`` as it is taken and do all processing on
the dicts, so a replayed log (``sensor=replay``) feeds the identical dicts
back and reproduces the results exactly. :meth:`PanTiltPlugin.move_to`
likewise returns the reached state as a dict.

Simulated devices
-----------------
Plugins with ``simulated = True`` get the shared simulation state from the
experiment through :meth:`attach_simulation` before :meth:`open`.
"""

from __future__ import annotations

from typing import Any, ClassVar


class DevicePlugin:
    """Common life cycle: ``open()``, ``close()``, context manager."""

    Config: ClassVar[type]
    config_group: ClassVar[Any] = "sensor"
    simulated: ClassVar[bool] = False
    schema_name: ClassVar[str] = "bionav.Reading"
    schema: ClassVar[dict] = {"type": "object"}

    #: where the user sets this plugin's parameters (``sensor``, ``pantilt``, or e.g.
    #: ``experiment.reference`` when an experiment uses a sensor under another role);
    #: the experiment may overwrite it so error messages name the right key
    config_prefix: str | None = None

    def __init__(self, config: Any) -> None:
        self.config = config

    def config_key(self, field: str) -> str:
        """The full config key of one parameter, for messages (``sensor.port``)."""
        group = self.config_group if isinstance(self.config_group, str) else self.config_group[0]
        return f"{self.config_prefix or group}.{field}"

    def attach_simulation(self, scene: Any, rng: Any) -> None:
        """Receive the simulated world (simulated plugins only; others ignore it)."""

    def open(self) -> None:
        """Connect to the device (idempotent)."""

    def close(self) -> None:
        """Disconnect (idempotent, never raises)."""

    def __enter__(self):
        self.open()
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class SerialDeviceMixin:
    """Open/close of a device behind one serial link (pyserial, timeouts, reconnect).

    The using class sets ``device_name`` (for messages), has a ``config`` with
    ``port``, ``baudrate``, ``timeout_s``, ``reconnect_attempts`` and
    ``reconnect_delay_s``, and implements ``_init_device()``, which is run
    after every (re)connection.
    """

    device_name: ClassVar[str] = "serial device"
    _link: Any = None

    def open(self) -> None:
        from bionav.errors import DeviceError
        from bionav.serialio import SerialLink

        if self._link is not None:
            return
        link = SerialLink(
            self.config.port,
            baudrate=self.config.baudrate,
            timeout=self.config.timeout_s,
            device=self.device_name,
            config_key=self.config_key("port"),
            reconnect_attempts=self.config.reconnect_attempts,
            reconnect_delay=self.config.reconnect_delay_s,
        )
        link.open()
        link.on_reconnect = self._init_device
        self._link = link
        try:
            self._init_device()
        except DeviceError:
            self.close()
            raise

    def _init_device(self) -> None:
        raise NotImplementedError

    def close(self) -> None:
        link, self._link = self._link, None
        if link is not None:
            link.close()


class SensorPlugin(DevicePlugin):
    """A sensor: :meth:`read` returns one raw reading as a JSON-ready dict."""

    def read(self) -> dict:
        """Take one raw reading."""
        raise NotImplementedError


class PanTiltPlugin(DevicePlugin):
    """A pan-tilt unit. Angles are radians; pan counter-clockwise seen from above.

    Tilt turns the payload's optical axis away from the zenith (see
    :mod:`bionav.polcompass.optics`).
    """

    config_group: ClassVar[Any] = "pantilt"
    schema_name: ClassVar[str] = "bionav.PanTiltState"
    schema: ClassVar[dict] = {
        "type": "object",
        "properties": {
            "pan_pos": {"type": "integer", "description": "pan position, device units"},
            "tilt_pos": {"type": "integer", "description": "tilt position, device units"},
            "pan": {"type": "number", "description": "pan angle, radians CCW"},
            "tilt": {"type": "number", "description": "tilt angle, radians"},
            "pan_cmd": {"type": "number", "description": "commanded pan, radians"},
            "tilt_cmd": {"type": "number", "description": "commanded tilt, radians"},
        },
        "required": ["pan_pos", "tilt_pos", "pan", "tilt"],
    }

    def limits(self) -> tuple[float, float, float, float]:
        """``(pan_min, pan_max, tilt_min, tilt_max)`` in radians."""
        raise NotImplementedError

    def resolution(self) -> tuple[float, float]:
        """``(pan, tilt)`` radians per device position."""
        raise NotImplementedError

    def move_to(self, pan: float, tilt: float) -> dict:
        """Move to absolute ``pan``, ``tilt`` (radians), wait until there, return the state."""
        raise NotImplementedError
