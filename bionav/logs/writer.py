"""Writing ``run.mcap``: JSON messages with JSON-schema schemas, flushed as it goes.

Conventions readers (the Foxglove app, ``@mcap/core``, Python's ``json``) rely on:

* a channel whose schema name is Foxglove's (``foxglove.PoseInFrame``,
  ``foxglove.RawImage``, ...) carries Foxglove's own JSON schema
  (:func:`bionav.logs.foxglove.foxglove_schema`, required fields included);
* messages are strict JSON: NaN and infinities become ``null`` on ``bionav.*``
  channels and are refused (``ValueError``) on Foxglove channels, whose fields
  are required numbers;
* log times are nanoseconds since the Unix epoch; simulated sessions add their
  simulated time to :attr:`McapLog.start_ns`, the wall-clock time the log was opened.
"""

from __future__ import annotations

import json
import math
import threading
import time
from pathlib import Path
from typing import Any, Mapping

import numpy as np
from mcap.writer import CompressionType, Writer

#: permissive schema used when a caller gives none
ANY_OBJECT_SCHEMA = {"type": "object"}


def _json_default(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f"{type(value).__name__} is not JSON serialisable")


def _finite_or_none(value: Any) -> Any:
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, Mapping):
        return {k: _finite_or_none(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite_or_none(v) for v in value]
    if isinstance(value, (np.ndarray, np.generic)):
        return _finite_or_none(_json_default(value))
    return value


def to_json_bytes(message: Mapping[str, Any], *, non_finite: str = "null") -> bytes:
    """Serialise a message to compact, strict UTF-8 JSON (numpy arrays become lists).

    Parameters
    ----------
    message : mapping
        The message.
    non_finite : {"null", "refuse"}
        What NaN and infinities become: JSON ``null``, or a ``ValueError``.
    """
    try:
        return json.dumps(message, default=_json_default, separators=(",", ":"), allow_nan=False).encode()
    except ValueError:
        if non_finite == "refuse":
            raise
    return json.dumps(_finite_or_none(message), default=_json_default, separators=(",", ":"), allow_nan=False).encode()


class McapLog:
    """An MCAP log of JSON messages that survives crashes.

    The header, attachments and metadata reach the file (the operating
    system's cache) at once; messages are collected in a chunk that a
    background thread writes out every ``flush_interval_s`` seconds, also
    while the experiment is busy computing and writes nothing. A crash (even
    SIGKILL) therefore loses at most the messages of the last interval;
    :func:`bionav.logs.recover.recover` turns the truncated file into a
    valid, indexed one. All methods are thread-safe.

    Parameters
    ----------
    path : path-like
        Output file (created or overwritten).
    flush_interval_s : float
        Longest time between flushes, in seconds.
    profile : str
        MCAP profile string written in the header.
    """

    def __init__(self, path: str | Path, *, flush_interval_s: float = 2.0, profile: str = "bionav") -> None:
        self.path = Path(path)
        self._file = open(self.path, "wb")
        self._writer = Writer(self._file, compression=CompressionType.ZSTD)
        self._writer.start(profile=profile, library="bionav")
        self._schemas: dict[tuple[str, str], int] = {}
        self._channels: dict[str, int] = {}
        self._sequence: dict[str, int] = {}
        self._flush_interval = float(flush_interval_s)
        self._last_flush = time.monotonic()
        self._closed = False
        #: wall-clock time the log was opened (ns since the Unix epoch): simulated time starts here
        self.start_ns = time.time_ns()
        self._lock = threading.RLock()
        self._dirty = False
        self._file.flush()
        self._stop = threading.Event()
        self._flusher = threading.Thread(target=self._flush_loop, name=f"mcap-flush {self.path.name}", daemon=True)
        self._flusher.start()

    def _flush_loop(self) -> None:
        """Background thread: flush pending messages every interval until closed."""
        while not self._stop.wait(self._flush_interval / 2):
            with self._lock:
                if self._closed:
                    return
                if self._dirty and time.monotonic() - self._last_flush >= self._flush_interval:
                    try:
                        self.flush()
                    except OSError:  # reported by the next write or close in the main thread
                        return

    @property
    def n_messages(self) -> int:
        """Messages written so far (attachments and metadata not counted)."""
        return sum(self._sequence.values())

    # -- channels -------------------------------------------------------------
    def _channel(self, topic: str, schema_name: str, schema: Mapping[str, Any] | None) -> int:
        if topic in self._channels:
            return self._channels[topic]
        if schema_name.startswith("foxglove."):
            from bionav.logs.foxglove import foxglove_schema

            try:
                schema = foxglove_schema(schema_name)  # Foxglove's own, whatever the caller passed
            except KeyError as exc:
                raise ValueError(f"topic {topic}: {exc.args[0]}") from None
        schema_json = json.dumps(dict(schema or ANY_OBJECT_SCHEMA), sort_keys=True)
        key = (schema_name, schema_json)
        if key not in self._schemas:
            self._schemas[key] = self._writer.register_schema(
                name=schema_name, encoding="jsonschema", data=schema_json.encode()
            )
        self._channels[topic] = self._writer.register_channel(
            topic=topic, message_encoding="json", schema_id=self._schemas[key]
        )
        self._sequence[topic] = 0
        return self._channels[topic]

    # -- writing --------------------------------------------------------------
    def write(
        self,
        topic: str,
        message: Mapping[str, Any],
        *,
        schema_name: str,
        schema: Mapping[str, Any] | None = None,
        log_time_ns: int | None = None,
    ) -> None:
        """Append one JSON message.

        Parameters
        ----------
        topic : str
            Channel topic, e.g. ``/homing/home_vectors``. The channel is created
            on the first message of a topic with the given schema.
        message : mapping
            JSON-serialisable content (numpy arrays and scalars are converted).
        schema_name : str
            Schema name; Foxglove's well-known names where one fits
            (``foxglove.PoseInFrame``, ``foxglove.RawImage``...), else ``bionav.<Thing>``.
        schema : mapping, optional
            JSON schema of the message; a permissive object schema if omitted.
            Ignored for Foxglove names: Foxglove's own schema is written.
        log_time_ns : int, optional
            Log time in nanoseconds since the Unix epoch; now if omitted. Replayed
            and simulated sessions pass their own clock (``start_ns`` plus simulated time).
        """
        data = self._encode(topic, schema_name, message)
        with self._lock:
            if self._closed:
                raise RuntimeError(f"the log {self.path} is already closed")
            channel = self._channel(topic, schema_name, schema)
            now = time.time_ns()
            t = now if log_time_ns is None else int(log_time_ns)
            self._writer.add_message(
                channel_id=channel,
                log_time=t,
                publish_time=t,
                data=data,
                sequence=self._sequence[topic],
            )
            self._sequence[topic] += 1
            self._dirty = True
            if time.monotonic() - self._last_flush >= self._flush_interval:
                self.flush()

    @staticmethod
    def _encode(topic: str, schema_name: str, message: Mapping[str, Any]) -> bytes:
        if not schema_name.startswith("foxglove."):
            return to_json_bytes(message)
        try:
            return to_json_bytes(message, non_finite="refuse")
        except ValueError:
            raise ValueError(
                f"topic {topic}: a {schema_name} message holds NaN or infinity, which Foxglove's schema does not "
                f"allow; log such values on a bionav.* channel (they become null there)."
            ) from None

    def attach(self, name: str, data: bytes, *, media_type: str) -> None:
        """Attach a file (e.g. the resolved config as YAML)."""
        t = time.time_ns()
        with self._lock:
            self._writer.add_attachment(create_time=t, log_time=t, name=name, media_type=media_type, data=data)
            self.flush()

    def metadata(self, name: str, values: Mapping[str, Any]) -> None:
        """Add a metadata record (string keys and values)."""
        with self._lock:
            self._writer.add_metadata(name=name, data={str(k): str(v) for k, v in values.items()})
            self.flush()

    def flush(self) -> None:
        """Write the chunk in progress to the file now (not fsync'ed: survives a crash, not a power cut)."""
        with self._lock:
            self._writer.flush()
            self._last_flush = time.monotonic()
            self._dirty = False

    def close(self) -> None:
        """Finish the file: write the summary and index. Safe to call twice."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            self._stop.set()
            try:
                self._writer.finish()
            finally:
                self._file.close()

    def __enter__(self) -> "McapLog":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
