"""``bionav.live=PORT``: a running experiment served over the Foxglove WebSocket protocol.

:class:`LiveServer` is a sink of :class:`bionav.logs.writer.McapLog`: every
message the run writes to ``run.mcap`` is also published, with the same
topic, schema name, JSON schema and log time, on a WebSocket server of the
``foxglove-sdk`` package (subprotocol ``foxglove.sdk.v1``, the Foxglove
WebSocket protocol under its current name; Foxglove, Lichtblick and any
client of the protocol connect to ``ws://HOST:PORT``). Only loopback
(``127.0.0.1``) listens unless ``bionav.live_host`` says otherwise; without
``bionav.live`` no server is started and nothing listens.

A client that subscribes to a channel is sent that channel's latest message at
once (as ROS latched topics), so a viewer that connects mid-run, or to a
channel written once (the views' poses), still shows it;
``bionav.live_linger_s`` keeps the server up that long after the run ends.
A client that is slow or goes away never stops the run: the server drops what
a client cannot take (``foxglove-sdk``'s per-client backlog), and a failing
publish detaches the sink with one warning.

Known limit of ``foxglove-sdk`` 0.30: a subscription that reaches the server
within milliseconds of a channel's advertisement, while the run keeps the
CPUs busy, can be refused with the status ``Unknown channel ID: N`` (the
server advertises before it records the channel); a client subscribes again
(the tests' client does, after 0.1 s).
"""

from __future__ import annotations

import logging
import threading
import time

from bionav.errors import UserError, require_extra

log = logging.getLogger(__name__)

#: what ``bionav.live_host`` defaults to: loopback only
LOOPBACK = "127.0.0.1"
#: seconds between a new subscription and the resend of the channel's latest message
RESEND_DELAY_S = 0.2


class LiveServer:
    """A Foxglove WebSocket server fed like an MCAP log (see the module docstring).

    Parameters
    ----------
    port : int
        TCP port, 1..65535 (0: any free port; :attr:`port` tells which).
    host : str
        Address to listen on; loopback by default.
    linger_s : float
        Seconds :meth:`close` keeps serving before it stops the server.
    name : str
        Server name shown by clients.

    Raises
    ------
    UserError
        ``foxglove-sdk`` not installed (its install line named), the port taken or not allowed.
    """

    def __init__(self, port: int, *, host: str = LOOPBACK, linger_s: float = 0.0, name: str = "bionav") -> None:
        fox = require_extra("foxglove", extra="live", what=f"bionav.live={port}")
        fox.set_log_level(logging.WARNING)  # the SDK's own records: warnings and errors only
        self._fox = fox
        self._context = fox.Context()
        self._lock = threading.Lock()
        self._channels: dict[str, object] = {}
        self._by_id: dict[int, str] = {}
        self._latest: dict[str, tuple[bytes, int]] = {}
        self.linger_s = float(linger_s)
        try:
            self._server = fox.start_server(name=name, host=host, port=int(port), context=self._context,
                                            server_listener=_Latch(self))
        except Exception as exc:  # the SDK raises its own error types for bind failures
            raise UserError(f"bionav.live={port}: cannot serve on {host}:{port} ({exc}); choose a free port "
                            "(e.g. bionav.live=8766) or stop the program that holds it.") from None
        self.host = host
        log.info("live view: ws://%s:%d (Foxglove: open connection, Foxglove WebSocket)", host, self.port)

    @property
    def port(self) -> int:
        return int(self._server.port)

    def publish(self, topic: str, schema_name: str, schema_json: bytes, data: bytes, log_time_ns: int) -> None:
        """Publish one JSON message (the bytes ``run.mcap`` holds) on ``topic``."""
        with self._lock:
            channel = self._channels.get(topic)
            if channel is None:
                schema = self._fox.Schema(name=schema_name, encoding="jsonschema", data=schema_json)
                channel = self._fox.Channel(topic, schema=schema, message_encoding="json", context=self._context)
                self._channels[topic] = channel
                self._by_id[channel.id()] = topic
            self._latest[topic] = (data, int(log_time_ns))
        channel.log(data, log_time=int(log_time_ns))

    def _resend(self, channel_id: int) -> None:
        time.sleep(RESEND_DELAY_S)  # foxglove-sdk calls the listener before the subscription delivers messages
        with self._lock:
            topic = self._by_id.get(channel_id)
            latest = self._latest.get(topic) if topic is not None else None
            channel = self._channels.get(topic) if topic is not None else None
        if latest is not None and channel is not None:
            channel.log(latest[0], log_time=latest[1])

    def close(self) -> None:
        """Stop serving (after ``linger_s``). Safe to call twice."""
        server, self._server = getattr(self, "_server", None), None
        if server is None:
            return
        if self.linger_s > 0:
            time.sleep(self.linger_s)
        server.stop()


class _Latch:
    """The server listener: a new subscription gets the channel's latest message."""

    def __init__(self, server: LiveServer) -> None:
        self.server = server

    def on_subscribe(self, client, channel) -> None:
        threading.Thread(target=self.server._resend, args=(int(channel.id),), daemon=True).start()

    def on_unsubscribe(self, client, channel) -> None:
        return None


def live_server(port, *, host=None, linger_s=None) -> LiveServer | None:
    """The :class:`LiveServer` that ``bionav.live`` asks for, or ``None`` when it is null.

    Raises
    ------
    UserError
        A port that is not an integer in 0..65535, a negative linger, or what :class:`LiveServer` raises.
    """
    if port is None or port is False:
        return None
    if isinstance(port, bool) or not isinstance(port, int) or not 0 <= port <= 65535:
        raise UserError(f"bionav.live={port!r} is not a TCP port: give an integer 1..65535 (e.g. bionav.live=8765), "
                        "or null for no live view.")
    linger = 0.0 if linger_s is None else linger_s
    if not isinstance(linger, (int, float)) or isinstance(linger, bool) or not 0 <= linger <= 3600:
        raise UserError(f"bionav.live_linger_s={linger_s!r}: give seconds 0..3600 to keep serving after the run.")
    return LiveServer(port, host=str(host or LOOPBACK), linger_s=float(linger))
