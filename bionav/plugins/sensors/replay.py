"""``sensor=replay`` / ``pantilt=replay``: re-run an experiment from a recorded ``run.mcap``.

Topic and schema convention (every bionav experiment that uses sensors
follows it, so one replay plugin serves every sensor kind):

``/sensor/raw``
    One message per ``read()`` of the ``sensor=`` plugin: the plugin's raw
    reading dict verbatim (e.g. ``{"counts": [...], "lines": [...]}`` for the
    polarized-light compass, the five-channel counts of the spectral sensor),
    schema name = the plugin's ``schema_name``. Written as the reading is
    taken.
``/pantilt/state``
    One message per ``move_to()`` of the ``pantilt=`` plugin: the reached
    state ``{"pan_pos", "tilt_pos", "pan", "tilt", "pan_cmd", "tilt_cmd"}``
    (radians; schema ``bionav.PanTiltState``).
``/pantilt/info``
    One message when the unit is opened:
    ``{"limits": [pan_min, pan_max, tilt_min, tilt_max], "resolution": [pan, tilt]}``
    (radians).
``/<role>/raw``
    Readings of further sensors an experiment uses under its own role name
    (e.g. ``/reference/raw`` for the TCM2 in ``pol_compass mode=vs_em_compass``);
    replay them by setting ``topic``.

As a sensor, :meth:`Replay.read` returns the messages of its topic (default
``/sensor/raw``) one by one in recorded order; as a pan-tilt unit,
:meth:`Replay.move_to` returns the recorded states in order and checks that
the experiment commands the same poses (``pan_cmd``/``tilt_cmd``), so a replay
with a different configuration stops with a clear message instead of silently
producing other numbers. :meth:`Replay.recorded` gives any topic's messages
(experiments read their own session information from it). Because the
experiment processes exactly the recorded dicts, replaying a session
reproduces its metrics exactly.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from bionav.errors import UserError
from bionav.plugins.sensors.base import PanTiltPlugin, SensorPlugin

SENSOR_TOPIC = "/sensor/raw"
PANTILT_TOPIC = "/pantilt/state"
PANTILT_INFO_TOPIC = "/pantilt/info"


def read_topics(path) -> dict[str, list[dict]]:
    """All JSON messages of an MCAP file grouped by topic, in file order."""
    import json

    from mcap.exceptions import McapError
    from mcap.reader import NonSeekingReader

    from bionav.logs.recover import check_mcap

    p = Path(path)
    if not p.is_file():
        raise UserError(
            f"The log to replay, {p}, does not exist. Set sensor.path=/pantilt.path= to the run.mcap of a "
            "recorded run (it lies in that run's output directory)."
        )
    check_mcap(p)  # not a FIFO or a device, within the size of a log, an MCAP file
    out: dict[str, list[dict]] = {}
    try:
        with p.open("rb") as f:
            for _schema, channel, message in NonSeekingReader(f, validate_crcs=True).iter_messages():
                if channel.message_encoding != "json":
                    continue
                out.setdefault(channel.topic, []).append(json.loads(message.data))
    except (McapError, ValueError, OSError) as exc:
        if not out:
            raise UserError(
                f"Cannot read the log {p} ({exc}). If the run crashed, rewrite it with "
                "'python -m bionav.logs recover IN OUT' and replay the recovered file."
            ) from None
        # A truncated log: replay every complete message before the damage.
    return out


@dataclass
class ReplayConfig:
    """Parameters of ``sensor=replay`` / ``pantilt=replay``."""

    path: str = "run.mcap"
    topic: str = ""  # empty: /sensor/raw when read, /pantilt/state when moved


class Replay(SensorPlugin, PanTiltPlugin):
    """Replays the raw readings and pan-tilt states of a recorded run (see the module docstring)."""

    Config = ReplayConfig
    config_group = ("sensor", "pantilt")  # selectable as sensor=replay and as pantilt=replay
    schema_name = "bionav.ReplayedReading"
    schema = {"type": "object"}

    def __init__(self, config: ReplayConfig) -> None:
        SensorPlugin.__init__(self, config)
        self._topics: dict[str, list[dict]] | None = None
        self._cursor: dict[str, int] = {}

    def open(self) -> None:
        if self._topics is None:
            self._topics = read_topics(self.config.path)

    def close(self) -> None:
        pass

    def recorded(self, topic: str) -> list[dict]:
        """Every recorded message of ``topic`` (empty list if none)."""
        self.open()
        return list(self._topics.get(topic, []))

    def _next(self, topic: str) -> dict:
        self.open()
        messages = self._topics.get(topic)
        if not messages:
            raise UserError(
                f"The log {self.config.path} has no messages on topic {topic!r}; it was not recorded by a run "
                f"with this sensor setup (topics present: {sorted(self._topics)})."
            )
        i = self._cursor.get(topic, 0)
        if i >= len(messages):
            raise UserError(
                f"The replayed log {self.config.path} holds only {len(messages)} messages on {topic!r} and the "
                "experiment asks for more; replay it with the configuration of the recorded run "
                "(its .hydra/config.yaml), or it ended early (then replay reproduces the part that was recorded)."
            )
        self._cursor[topic] = i + 1
        return messages[i]

    # -- sensor role ------------------------------------------------------
    def read(self) -> dict:
        return dict(self._next(self.config.topic or SENSOR_TOPIC))

    # -- pan-tilt role ----------------------------------------------------
    def _info(self) -> dict:
        info = self.recorded(PANTILT_INFO_TOPIC)
        if not info:
            raise UserError(f"The log {self.config.path} has no {PANTILT_INFO_TOPIC} message; it holds no pan-tilt session.")
        return info[0]

    def limits(self) -> tuple[float, float, float, float]:
        return tuple(float(v) for v in self._info()["limits"])

    def resolution(self) -> tuple[float, float]:
        return tuple(float(v) for v in self._info()["resolution"])

    def move_to(self, pan: float, tilt: float) -> dict:
        state = dict(self._next(self.config.topic or PANTILT_TOPIC))
        want = (state.get("pan_cmd"), state.get("tilt_cmd"))
        if None not in want and (abs(want[0] - pan) > 1e-9 or abs(want[1] - tilt) > 1e-9):
            raise UserError(
                f"Replay diverged from the recorded run: it moved to pan {want[0]:.6f}, tilt {want[1]:.6f} rad "
                f"here, but the experiment asks for pan {pan:.6f}, tilt {tilt:.6f} rad. Replay with the recorded "
                "run's experiment settings (see its .hydra/config.yaml)."
            )
        return state
