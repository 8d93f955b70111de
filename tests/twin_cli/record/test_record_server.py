"""Recording and streaming from a real `twin serve`: the CLI, a SIGKILL mid-recording, and a
WebSocket client speaking the published Foxglove protocol (no Foxglove code on the reading side).
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import os
import signal
import socket
import struct
import subprocess
import time
from pathlib import Path

import numpy as np
from record_helpers import read_bag, seconds
from view_helpers import twin_in

import scenarios

HUMANOID = Path(scenarios.HUMANOID)
# The Foxglove WebSocket protocol's spec names the first; foxglove-sdk servers answer the second.
FOXGLOVE_SUBPROTOCOLS = ["foxglove.websocket.v1", "foxglove.sdk.v1"]
MESSAGE_DATA, TIME = 0x01, 0x02  # binary opcodes, server → client


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def twin(*args: str, world: str) -> subprocess.CompletedProcess:
    return twin_in(world, *args)


def test_twin_record_for_a_duration_writes_a_bag(tmp_path, serve_world):
    with serve_world(tmp_path, "rec") as (client, _):
        client.spawn(str(HUMANOID), name="h", pose={"z": 1.0})
        out = tmp_path / "fall.mcap"
        done = twin("record", str(out), "--duration", "0.5", "--rate", "50", world="rec")
        assert done.returncode == 0, done.stderr
        assert "26 samples" in done.stdout
        bag = read_bag(out)
        clock = np.array([seconds(m.clock) for _, m in bag["/clock"]])
        assert len(clock) == 26 and np.allclose(np.diff(clock), 0.02, atol=1e-9)
        assert "/h/robot_description" in bag


def test_bad_input_is_one_message_and_exit_2(tmp_path, serve_world):
    with serve_world(tmp_path, "recbad") as (client, _):
        client.spawn(str(HUMANOID), name="h", pose={"z": 1.0})
        done = twin("record", str(tmp_path / "no" / "dir" / "x.mcap"), world="recbad")
        assert done.returncode == 2 and "cannot be written" in done.stderr, done.stderr
        done = twin("record", str(tmp_path / "x.mcap"), "--entity", "ghost", world="recbad")
        assert done.returncode == 2 and "Entity [ghost] does not exist" in done.stderr
        with socket.socket() as taken:
            taken.bind(("127.0.0.1", 0))
            taken.listen()
            port = str(taken.getsockname()[1])
            done = twin("foxglove", "--port", port, world="recbad")
        assert done.returncode == 2 and f"{port}" in done.stderr, done.stderr
        assert "choose another port" in done.stderr


def test_a_sigkilled_server_leaves_a_file_readable_up_to_its_last_chunk(tmp_path, serve_world):
    from mcap.exceptions import McapError
    from mcap.stream_reader import StreamReader
    from mcap_ros2.decoder import DecoderFactory

    out = tmp_path / "killed.mcap"
    with serve_world(tmp_path, "reckill") as (client, proc):
        client.spawn(str(HUMANOID), name="h", pose={"z": 1.0})
        client.request("POST", "/record", body={"path": str(out), "rate": 100})
        deadline = time.monotonic() + 60.0  # the encoder starts in ~1 s, more under load
        while time.monotonic() < deadline and (not out.exists() or out.stat().st_size < 50_000):
            time.sleep(0.2)
        time.sleep(1.5)  # > FLUSH_PERIOD_S: more chunks reach the OS
        for child in _children(proc.pid):  # the encoder process first, as a kill -9 of all
            os.kill(child, signal.SIGKILL)
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait()
    schemas, channels, stamps = {}, {}, []
    decoders = DecoderFactory()  # mcap_ros2: a CDR decoder that is not rosbags'
    with out.open("rb") as stream:
        try:
            for record in StreamReader(stream).records:
                kind = type(record).__name__
                if kind == "Schema":
                    schemas[record.id] = record
                elif kind == "Channel":
                    channels[record.id] = record
                elif kind == "Message" and channels[record.channel_id].topic == "/clock":
                    schema = schemas[channels[record.channel_id].schema_id]
                    clock = decoders.decoder_for("cdr", schema)(record.data)
                    assert clock.clock.sec * 10**9 + clock.clock.nanosec == record.log_time
                    stamps.append(record.log_time)
        except (McapError, EOFError, struct.error):
            pass  # the cut: the chunk being written when the process died
    assert len(stamps) >= 50, f"{len(stamps)} /clock messages survived"
    assert np.all(np.diff(stamps) == 10_000_000), "consecutive 100 Hz samples up to the cut"


def test_the_encoder_of_a_sigkilled_server_finishes_the_file_and_exits(tmp_path, serve_world):
    """Only the server is killed: its encoder process sees the pipe close, encodes what the
    ring still holds, writes the summary and the rosbag2 metadata, and exits (an encoder that
    polled the closed pipe would run forever and leave the file without its index)."""
    import yaml
    from mcap.reader import make_reader

    out = tmp_path / "orphan.mcap"
    with serve_world(tmp_path, "recorphan") as (client, proc):
        client.spawn(str(HUMANOID), name="h", pose={"z": 1.0})
        client.request("POST", "/record", body={"path": str(out), "rate": 100})
        deadline = time.monotonic() + 60.0
        while time.monotonic() < deadline and (not out.exists() or out.stat().st_size < 50_000):
            time.sleep(0.2)
        (encoder,) = [c for c in _children(proc.pid) if b"record.encoder" in _cmdline(c)]
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait()
    deadline = time.monotonic() + 30.0
    while time.monotonic() < deadline and Path(f"/proc/{encoder}").exists():
        time.sleep(0.1)
    assert not Path(f"/proc/{encoder}").exists(), "the encoder outlived its server"
    with out.open("rb") as stream:
        reader = make_reader(stream, validate_crcs=True)
        summary = reader.get_summary()
        (meta,) = [m for m in reader.iter_metadata() if m.name == "rosbag2"]
        stamps = [m.log_time for _, c, m in reader.iter_messages() if c.topic == "/clock"]
    info = yaml.safe_load(meta.metadata["serialized_metadata"])
    assert info["custom_data"] == {"parent": "gone"}
    assert summary.statistics.message_count == info["message_count"] > 0
    assert len(stamps) >= 50 and np.all(np.diff(stamps) == 10_000_000), "every sample, in order"


def _cmdline(pid: int) -> bytes:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes()
    except OSError:
        return b""


def _children(pid: int) -> list[int]:
    """Process ids of `pid`'s children (Linux /proc)."""
    out = []
    for task in Path(f"/proc/{pid}/task").iterdir():
        out += [int(c) for c in (task / "children").read_text().split()]
    return out


def _foxglove_session(port: int, client, steps: int) -> dict:
    """Subscribe to /tf and /h/joint_states, step the paused world, spawn a second robot."""
    import websockets
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)

    async def run() -> dict:
        url = f"ws://127.0.0.1:{port}"
        async with websockets.connect(url, subprotocols=FOXGLOVE_SUBPROTOCOLS) as ws:
            channels: dict[str, dict] = {}
            got: dict[str, list] = {"/tf": [], "/h/joint_states": []}
            subscribed: dict[int, str] = {}

            async def pump(until, timeout=20.0) -> None:
                deadline = time.monotonic() + timeout
                while not until():
                    frame = await asyncio.wait_for(ws.recv(), deadline - time.monotonic())
                    if isinstance(frame, str):
                        op = json.loads(frame)
                        if op["op"] == "advertise":
                            channels.update({c["topic"]: c for c in op["channels"]})
                        continue
                    if frame[0] == MESSAGE_DATA:
                        sub, stamp = struct.unpack_from("<IQ", frame, 1)
                        topic = subscribed[sub]
                        msgtype = channels[topic]["schemaName"]
                        got[topic].append((stamp, store.deserialize_cdr(frame[13:], msgtype)))

            await asyncio.to_thread(client.step, 50)  # a paused world is sampled when it steps
            await pump(lambda: {"/tf", "/h/joint_states"} <= set(channels))
            subs = []
            for k, topic in enumerate(("/tf", "/h/joint_states"), start=1):
                subscribed[k] = topic
                subs.append({"id": k, "channelId": channels[topic]["id"]})
            await ws.send(json.dumps({"op": "subscribe", "subscriptions": subs}))
            # The protocol does not acknowledge a subscription, and on a loaded 2-core machine
            # it can take seconds to reach the server (through the stream's guard process):
            # step in tens until both topics arrive, then the rest in one go.
            stepped = 50
            while not (got["/tf"] and got["/h/joint_states"]) and stepped < steps - 10:
                await asyncio.to_thread(client.step, 10)
                stepped += 10
                with contextlib.suppress(TimeoutError):
                    await pump(lambda: bool(got["/tf"] and got["/h/joint_states"]), timeout=1.0)
            assert got["/tf"] and got["/h/joint_states"], "the subscription never took"
            await asyncio.to_thread(client.step, steps - stepped)
            await pump(
                lambda: (
                    got["/tf"] and got["/h/joint_states"][-1:][0][0] == steps * 10**6
                    if got["/h/joint_states"]
                    else False
                )
            )
            joints = await asyncio.to_thread(client.joints, "h")
            await asyncio.to_thread(
                client.spawn, str(HUMANOID), name="h2", pose={"x": 2.0, "z": 1.0}
            )
            await asyncio.to_thread(client.step, steps)
            h2 = {"/h2/joint_states", "/h2/robot_description", "/h2/odom"}
            await pump(lambda: h2 <= set(channels))
            return {"got": got, "joints": joints, "channels": channels}

    return asyncio.run(run())


def test_foxglove_clients_receive_the_worlds_state_and_new_entities(tmp_path, serve_world):
    port = free_port()
    with serve_world(tmp_path, "fox", "--paused", "--foxglove", str(port)) as (client, _):
        client.spawn(str(HUMANOID), name="h", pose={"z": 1.0})
        session = _foxglove_session(port, client, steps=300)
    got, joints = session["got"], session["joints"]
    # The last message before the spawn (later ones may arrive while the spawn's channels do).
    at_300 = [m for stamp, m in got["/h/joint_states"] if stamp == 300_000_000]
    assert at_300, "stamped with sim time (paused world stepped 300 × 1 ms)"
    message = at_300[-1]
    assert list(message.name) == [j["name"] for j in joints]
    assert np.array_equal(message.position, [j["position"] for j in joints]), "positions"
    assert np.array_equal(message.velocity, [j["velocity"] for j in joints]), "velocities"
    _, tf = got["/tf"][-1]
    assert ("world", "h/torso") in {(t.header.frame_id, t.child_frame_id) for t in tf.transforms}
    assert {"/h2/joint_states", "/h2/robot_description", "/h2/odom"} <= set(session["channels"])


def _paused_session(port: int) -> dict:
    """Subscribe to /clock and /h/joint_states of a paused world that is never stepped."""
    import websockets
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)

    async def run() -> dict:
        async with websockets.connect(
            f"ws://127.0.0.1:{port}", subprotocols=FOXGLOVE_SUBPROTOCOLS
        ) as ws:
            channels: dict[str, dict] = {}
            got: dict[str, list] = {}
            subscribed: dict[int, str] = {}
            wanted = ("/clock", "/h/joint_states", "/tf_static")
            deadline = time.monotonic() + 30.0
            next_id, retry_at = 1, deadline
            while not all(got.get(t) for t in wanted):
                assert time.monotonic() < deadline, f"got {sorted(got)} of {wanted} in 30 s"
                try:
                    frame = await asyncio.wait_for(ws.recv(), 2.0)
                except TimeoutError:
                    frame = json.dumps({"op": "silence"})
                if subscribed and time.monotonic() > retry_at:  # the paused world republishes
                    subscribed.clear()  # every 0.5 s: a topic still missing was subscribed on a
                    frame = json.dumps({"op": "retry"})  # channel replaced meanwhile; again
                if isinstance(frame, str) and json.loads(frame)["op"] == "advertise":
                    retry_at = time.monotonic() + 3.0
                if isinstance(frame, str):
                    op = json.loads(frame)
                    if op["op"] == "advertise":
                        channels.update({c["topic"]: c for c in op["channels"]})
                    elif op["op"] == "unadvertise":  # the spawn's new layout replaces channels
                        gone = set(op["channelIds"])
                        channels = {t: c for t, c in channels.items() if c["id"] not in gone}
                        subscribed.clear()  # subscribe again to what is advertised next
                    if set(wanted) <= set(channels) and not subscribed:
                        subs = []
                        for topic in wanted:
                            subscribed[next_id] = topic
                            subs.append({"id": next_id, "channelId": channels[topic]["id"]})
                            next_id += 1
                        await ws.send(json.dumps({"op": "subscribe", "subscriptions": subs}))
                        retry_at = time.monotonic() + 3.0
                elif frame[0] == MESSAGE_DATA:
                    sub, stamp = struct.unpack_from("<IQ", frame, 1)
                    topic = subscribed.get(sub)
                    if topic is None:  # a subscription to a channel since withdrawn
                        continue
                    message = store.deserialize_cdr(frame[13:], channels[topic]["schemaName"])
                    got.setdefault(topic, []).append((stamp, message))
            return got

    return asyncio.run(run())


def test_a_paused_world_still_shows_its_state_to_a_new_foxglove_client(tmp_path, serve_world):
    port = free_port()
    with serve_world(tmp_path, "foxpause", "--paused", "--foxglove", str(port)) as (client, _):
        client.spawn(str(HUMANOID), name="h", pose={"z": 1.0})
        got = _paused_session(port)  # the world never steps
        joints = client.joints("h")
    stamp, clock = got["/clock"][-1]
    assert stamp == 0 and seconds(clock.clock) == 0.0, "sim time of the paused world"
    _, message = got["/h/joint_states"][-1]
    assert np.array_equal(message.position, [j["position"] for j in joints]), "its state"
    assert got["/tf_static"], "latched topics are sent to the new subscriber"


def test_twin_load_moves_a_recording_or_says_it_stopped(tmp_path, serve_world):
    out = tmp_path / "moved.mcap"
    with serve_world(tmp_path, "recload", "--paused") as (client, _):
        client.spawn(str(HUMANOID), name="h", pose={"z": 1.0})
        client.step(200)
        client.save(tmp_path / "with_h.json")  # t = 0.2 s
        client.delete("h")
        client.spawn(str(HUMANOID), name="g", pose={"z": 1.0})
        client.save(tmp_path / "without_h.json")
        client.load(tmp_path / "with_h.json")
        client.request("POST", "/record", body={"path": str(out), "entities": ["h"]})
        client.step(100)  # 0.2 → 0.3 s
        moved = twin("load", str(tmp_path / "with_h.json"), world="recload")
        client.step(50)  # 0.2 → 0.25 s in the loaded world
        stopped = twin("load", str(tmp_path / "without_h.json"), world="recload")
        status = client.request("GET", "/record")
    assert moved.returncode == 0 and "recording moved" in moved.stderr, moved.stderr
    assert "recording stopped: Entity [h] does not exist" in stopped.stderr, stopped.stderr
    assert status["active"] is False and status["error"] is None, status
    clock = [round(seconds(m.clock), 9) for _, m in read_bag(out)["/clock"]]
    first = [round(0.2 + 0.01 * k, 9) for k in range(11)]
    # rosbags yields messages in log-time order: the loaded world's clock restarted at 0.2 s.
    assert clock == sorted(first + [round(0.2 + 0.01 * k, 9) for k in range(6)]), clock


def _image_session(port: int, client, topic: str) -> list:
    """Subscribe to one image topic and step the paused world until an image arrives (a live
    stream drops sensor captures while its worker is busy, as a live view drops frames)."""
    import websockets
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)

    async def run() -> list:
        url = f"ws://127.0.0.1:{port}"
        async with websockets.connect(url, subprotocols=FOXGLOVE_SUBPROTOCOLS) as ws:
            channels: dict[str, dict] = {}
            got: list = []
            live, sub_id, waits = None, 0, 0  # the subscribed channel and subscription
            deadline = time.monotonic() + 60.0
            await asyncio.to_thread(client.step, 10)
            while not got:
                try:
                    frame = await asyncio.wait_for(ws.recv(), 0.5)
                except TimeoutError:  # a live stream skips sensors while it is busy: step on
                    assert time.monotonic() < deadline, "no image within 60 s"
                    waits += 1
                    if live is not None and waits % 10 == 0:  # the channel may have been
                        live = None  # replaced under the subscription: subscribe again
                    elif live is not None:
                        await asyncio.to_thread(client.step, 50)
                    if live is not None or topic not in channels:
                        continue
                    frame = json.dumps({"op": "resubscribe"})
                if isinstance(frame, str):
                    op = json.loads(frame)
                    if op["op"] == "advertise":
                        channels.update({c["topic"]: c for c in op["channels"]})
                    elif op["op"] == "unadvertise":  # a new layout replaces channels
                        gone = set(op["channelIds"])
                        channels = {t: c for t, c in channels.items() if c["id"] not in gone}
                        live = None if live in gone else live
                    if topic in channels and live is None:
                        live, sub_id = channels[topic]["id"], sub_id + 1
                        sub = {"id": sub_id, "channelId": live}
                        await ws.send(json.dumps({"op": "subscribe", "subscriptions": [sub]}))
                        await asyncio.sleep(2.0)  # no acknowledgement: let the server take it
                        await asyncio.to_thread(client.step, 100)
                elif frame[0] == MESSAGE_DATA:
                    if struct.unpack_from("<I", frame, 1)[0] != sub_id:
                        continue  # a subscription to a channel since withdrawn
                    schema = channels[topic]["schemaName"]
                    got.append((schema, store.deserialize_cdr(frame[13:], schema)))
            return got

    return asyncio.run(run())


def test_foxglove_clients_receive_camera_images_as_sensor_msgs_image(tmp_path, serve_world):
    from camera_models import CAM_Z, POST, H, W, red
    from view_helpers import egl_missing, red_box

    if why := egl_missing():
        import pytest

        pytest.skip(why)
    (tmp_path / "campost.urdf").write_text(POST)
    static = "<gazebo><static>true</static></gazebo></robot>"
    (tmp_path / "redbox.urdf").write_text(red_box(0.2).replace("</robot>", static))
    port = free_port()
    with serve_world(tmp_path, "foxcam", "--paused", "--foxglove", str(port)) as (client, _):
        client.spawn(str(tmp_path / "campost.urdf"), name="post")
        # 2 m ahead of the camera and 0.3 m to its left: the left half of the picture.
        client.spawn(
            str(tmp_path / "redbox.urdf"), name="box", pose={"x": 2.0, "y": 0.3, "z": CAM_Z}
        )
        got = _image_session(port, client, "/post/cam/image_raw")
    schema, image = got[-1]
    assert schema == "sensor_msgs/msg/Image"
    assert (image.width, image.height, image.encoding, image.step) == (W, H, "rgb8", 3 * W)
    rgb = np.asarray(image.data, np.uint8).reshape(H, W, 3).astype(np.float64)
    red_pixels = red(rgb)
    assert red_pixels.sum() > 20, "the red box is in the picture"
    assert not red_pixels[:, W // 2 :].any(), "to the camera's left: nothing red in the right half"


def test_serve_record_begins_its_tf_static_with_the_first_entitys_frames(tmp_path, serve_world):
    """`twin serve --record` starts on an empty world: no empty `/tf_static` comes first (a
    late subscriber to a latched topic gets only its last message, and an empty one hides the
    fixed frames from tools that read the first)."""
    out = tmp_path / "served.mcap"
    with serve_world(tmp_path, "srec", "--record", str(out)) as (client, _):
        client.spawn(str(HUMANOID), name="h", pose={"z": 1.0})
        until, deadline = client.stats()["sim_time"] + 0.2, time.monotonic() + 30.0
        while client.stats()["sim_time"] < until and time.monotonic() < deadline:
            time.sleep(0.05)
    bag = read_bag(out)
    assert [len(m.transforms) for _, m in bag["/tf_static"]][:1] == [1], "h/imu_link first"
