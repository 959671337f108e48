"""bionav.live=PORT: the Foxglove WebSocket server, tested with a real WebSocket client (``websockets``) on loopback.

The client speaks the protocol as Foxglove does: it offers the subprotocols ``foxglove.websocket.v1`` and
``foxglove.sdk.v1``, reads ``serverInfo`` and ``advertise``, subscribes to every advertised channel and
decodes the binary ``messageData`` frames (opcode 1, subscription id, log time, payload).
"""

from __future__ import annotations

import asyncio
import json
import os
import socket
import struct
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers import assert_fails_cleanly, run_bionav

pytest.importorskip("foxglove")
websockets = pytest.importorskip("websockets")

from bionav.logs.live import LiveServer, live_server  # noqa: E402
from bionav.logs.writer import McapLog  # noqa: E402

SUBPROTOCOLS = ["foxglove.websocket.v1", "foxglove.sdk.v1"]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


async def collect(port: int, *, until=None, idle_s: float = 15.0, connect_s: float = 120.0, messages=None):
    """Connect (retrying while the server starts), subscribe to every channel, collect until closed or idle.

    Returns ``(subprotocol, channels {topic: advertised channel}, messages {topic: [(log_time, payload bytes)]})``;
    ``until(messages)`` may end the collection early; ``messages`` may be a dict the caller watches. A subscription refused as ``Unknown channel ID`` is sent
    again (see :mod:`bionav.logs.live`).
    """
    t0 = time.monotonic()
    while True:
        try:
            ws = await websockets.connect(f"ws://127.0.0.1:{port}", subprotocols=SUBPROTOCOLS, max_size=None)
            break
        except OSError:
            if time.monotonic() - t0 > connect_s:
                raise
            await asyncio.sleep(0.1)
    channels, subs, next_id, retries = {}, {}, 1, []
    messages = {} if messages is None else messages
    try:
        while until is None or not until(messages):
            frame = await asyncio.wait_for(ws.recv(), idle_s)
            if isinstance(frame, str):
                msg = json.loads(frame)
                refused = msg["op"] == "status" and msg.get("message", "").startswith("Unknown channel ID: ")
                if refused:  # foxglove-sdk 0.30 may answer a subscription right after an advertisement so: again
                    channel_id = int(msg["message"].rsplit(" ", 1)[1])
                    await asyncio.sleep(0.1)
                    again = [{"id": s, "channelId": channel_id} for s, t in subs.items()
                             if channels[t]["id"] == channel_id]
                    await ws.send(json.dumps({"op": "unsubscribe", "subscriptionIds": [a["id"] for a in again]}))
                    await ws.send(json.dumps({"op": "subscribe", "subscriptions": again}))
                    retries.append(channel_id)
                if msg["op"] == "advertise":
                    new = []
                    for c in msg["channels"]:
                        channels[c["topic"]] = c
                        subs[next_id] = c["topic"]
                        new.append({"id": next_id, "channelId": c["id"]})
                        next_id += 1
                    await ws.send(json.dumps({"op": "subscribe", "subscriptions": new}))
                continue
            op, sub, log_time = struct.unpack_from("<BIQ", frame)
            assert op == 1  # messageData
            messages.setdefault(subs[sub], []).append((log_time, bytes(frame[13:])))
    except (asyncio.TimeoutError, websockets.ConnectionClosed):
        pass
    finally:
        await ws.close()
    return ws.subprotocol, channels, messages


def mcap_contents(path: Path):
    """``{topic: (schema name, schema JSON, [(log_time, data), ...])}`` of a run.mcap."""
    from mcap.reader import make_reader

    out = {}
    with open(path, "rb") as f:
        for schema, channel, message in make_reader(f).iter_messages(log_time_order=False):
            entry = out.setdefault(channel.topic, (schema.name, schema.data.decode(), []))
            entry[2].append((message.log_time, bytes(message.data)))
    return out


def test_server_publishes_what_the_log_writes(tmp_path):
    server = LiveServer(0)
    log = McapLog(tmp_path / "run.mcap")
    log.add_sink(server)
    log.write("/early", {"written": "before any client"}, schema_name="bionav.Early", log_time_ns=5)
    got = {}

    async def client():
        seen: dict = {}
        task = asyncio.ensure_future(collect(server.port, until=lambda m: len(m.get("/late", [])) >= 3, idle_s=30,
                                             messages=seen))
        log.write("/late", {"k": 0, "x": [0.5, None]}, schema_name="bionav.Late", log_time_ns=100)
        while not seen.get("/late") and not task.done():  # the client subscribes and gets k=0 (latched) ...
            await asyncio.sleep(0.05)
        for k in (1, 2):  # ... then every message as it is written
            log.write("/late", {"k": k, "x": [0.5, None]}, schema_name="bionav.Late", log_time_ns=100 + k)
        got["result"] = await task

    asyncio.run(client())
    log.close()
    protocol, channels, messages = got["result"]
    assert protocol in SUBPROTOCOLS
    written = mcap_contents(tmp_path / "run.mcap")
    assert set(channels) == set(written) == {"/early", "/late"}
    for topic, (schema_name, schema, data) in written.items():
        assert channels[topic]["schemaName"] == schema_name and channels[topic]["encoding"] == "json"
        assert json.loads(channels[topic]["schema"]) == json.loads(schema)
    assert messages["/early"] == [(5, written["/early"][2][0][1])]  # latched: sent when the client subscribed
    assert messages["/late"] == written["/late"][2]


def test_bad_ports_fail_cleanly():
    from bionav.errors import UserError

    assert live_server(None) is None
    for bad in ("abc", -1, 70000, 1.5, True):
        with pytest.raises(UserError, match="is not a TCP port"):
            live_server(bad)
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        with pytest.raises(UserError, match=f"bionav.live={taken.getsockname()[1]}: cannot serve on 127.0.0.1"):
            live_server(taken.getsockname()[1])


def _listening(pid: int) -> int:
    """TCP sockets of process ``pid`` in the LISTEN state (from /proc)."""
    inodes = set()
    for fd in Path(f"/proc/{pid}/fd").iterdir():
        try:
            target = os.readlink(fd)
        except OSError:
            continue
        if target.startswith("socket:["):
            inodes.add(target[8:-1])
    count = 0
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        for line in Path(table).read_text().splitlines()[1:]:
            fields = line.split()
            if fields[3] == "0A" and fields[9] in inodes:
                count += 1
    return count


def _watch(args, cwd) -> int:
    """Run ``python -m bionav args`` and return the most listening sockets it had at once."""
    proc = subprocess.Popen([sys.executable, "-m", "bionav", *args], cwd=cwd, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, env=dict(os.environ, BIONAV_CACHE=str(cwd / "cache")))
    most = 0
    while proc.poll() is None:
        try:
            most = max(most, _listening(proc.pid))
        except OSError:
            pass
        time.sleep(0.05)
    assert proc.returncode == 0
    return most


@pytest.fixture(scope="module")
def tiny_db(tmp_path_factory):
    from helpers import write_tiny_folder

    return write_tiny_folder(tmp_path_factory.mktemp("live") / "db")


@pytest.mark.slow
@pytest.mark.skipif(not Path("/proc/net/tcp").exists(), reason="needs Linux /proc to see listening sockets")
def test_nothing_listens_without_the_option(tmp_path, tiny_db):
    args = ["db=folder", f"db.path={tiny_db}", "homing=mfdid"]
    assert _watch([*args, f"hydra.run.dir={tmp_path / 'off'}"], tmp_path) == 0
    port = free_port()
    assert _watch([*args, f"bionav.live={port}", "bionav.live_linger_s=1", f"hydra.run.dir={tmp_path / 'on'}"],
                  tmp_path) == 1


@pytest.mark.slow
def test_a_run_served_live_has_the_topics_and_schemas_of_its_log(tmp_path, tiny_db):
    port = free_port()
    run = tmp_path / "run"
    proc = subprocess.Popen([sys.executable, "-m", "bionav", "db=folder", f"db.path={tiny_db}", "homing=mfdid",
                             "experiment.log_views=true", f"bionav.live={port}", "bionav.live_linger_s=3",
                             f"hydra.run.dir={run}"], cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env=dict(os.environ, BIONAV_CACHE=str(tmp_path / "cache")))
    protocol, channels, messages = asyncio.run(collect(port, idle_s=20))
    out, err = proc.communicate(timeout=300)
    assert proc.returncode == 0, err
    written = mcap_contents(run / "run.mcap")
    assert protocol in SUBPROTOCOLS
    assert set(channels) == set(written)
    for topic, (schema_name, schema, data) in written.items():
        assert channels[topic]["schemaName"] == schema_name
        assert json.loads(channels[topic]["schema"]) == json.loads(schema)
        assert messages[topic], topic
        assert set(messages[topic]) <= set(data), topic  # every message received is one the log holds
        assert messages[topic][-1] == data[-1], topic  # and the latest one arrived
    (tmp_path / "received.json").write_text(json.dumps(
        {t: {"schema": channels[t]["schemaName"], "messages": len(m)} for t, m in sorted(messages.items())}))


@pytest.mark.slow
def test_shipped_layouts_name_topics_the_runs_write(tmp_path, tiny_db):
    from bionav.logs.foxglove import LAYOUTS, foxglove_layout

    runs = {"grid_homing": ["db=folder", f"db.path={tiny_db}", "homing=mfdid", "experiment.log_views=true"],
            "compass": ["experiment=pol_compass", "mode=vs_em_compass", "experiment.vs_em.positions=6",
                        "experiment.vs_em.samples=2"]}
    assert set(runs) == set(LAYOUTS)
    proc = run_bionav("layout", "grid_homing", module="bionav.logs", cwd=tmp_path)
    assert proc.returncode == 0 and json.loads(proc.stdout) == json.loads(foxglove_layout("grid_homing"))
    for name, args in runs.items():
        layout = json.loads(foxglove_layout(name))
        proc = run_bionav(*args, f"hydra.run.dir={tmp_path / name}", cwd=tmp_path)
        assert proc.returncode == 0, proc.stderr
        written = mcap_contents(tmp_path / name / "run.mcap")
        ids = set(layout["configById"])
        tree = json.dumps(layout["layout"])
        assert all(i in tree for i in ids)  # every configured panel is placed
        for panel, config in layout["configById"].items():
            topics = list(config.get("topics", {}))
            topics += [p["value"].split(".")[0] for p in config.get("paths", [])]
            topics += [config["topicPath"].split(".")[0]] if "topicPath" in config else []
            image = config.get("imageMode", {}).get("imageTopic")
            if image:
                assert written[image][0] == "foxglove.RawImage", image
                topics.append(image)
            assert topics, panel
            for topic in topics:
                assert topic in written, f"{name}: {panel} shows {topic}, which the run does not write"
    proc = run_bionav("layout", "nope", module="bionav.logs", cwd=tmp_path)
    assert proc.returncode == 2 and "invalid choice" in proc.stderr


def test_live_view_needs_foxglove_sdk(tmp_path):
    blocker = tmp_path / "site" / "foxglove"
    blocker.mkdir(parents=True)
    (blocker / "__init__.py").write_text("raise ImportError('foxglove is blocked for this test')\n")
    proc = run_bionav("experiment=contrast_lda", "bionav.live=8765", f"hydra.run.dir={tmp_path / 'run'}",
                      cwd=tmp_path, env={"PYTHONPATH": str(tmp_path / "site")})
    assert_fails_cleanly(proc, "bionav.live=8765 needs the Python package 'foxglove'", 'pip install "bionav[live]"')
