"""A recording survives every way its world ends: `twin stop`, SIGTERM, Ctrl-C, a SIGKILL of the
server, a SIGKILL of every twin process on a loaded machine. Real servers; the files are read
back with the `mcap` library (its summary reader, or its streaming reader for a cut file)."""

from __future__ import annotations

import os
import signal
import struct
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

import scenarios
from twin_cli.server import runtime
from twin_cli.server.client import Client

HUMANOID = str(scenarios.HUMANOID)
STOP_PATIENCE_S = 15.0  # [s] `twin stop` escalates to SIGTERM after this
LOST_MAX_S = 2.0  # [s] of sim time a SIGKILL of every twin process may lose, on any topic


def _twin(runtime_dir: Path, *args: str) -> subprocess.CompletedProcess:
    env = {**os.environ, runtime.RUNTIME_ENV: str(runtime_dir)}
    cmd = [sys.executable, "-m", "twin_cli.cli.app", *args]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=120, env=env)


def _kill(pid: int) -> None:
    try:
        os.kill(pid, signal.SIGKILL)
    except ProcessLookupError:
        pass


def _descendants(pid: int) -> list[int]:
    out = []
    try:
        tasks = list(Path(f"/proc/{pid}/task").iterdir())
    except OSError:
        return out
    for task in tasks:
        try:
            children = [int(c) for c in (task / "children").read_text().split()]
        except OSError:
            continue
        for child in children:
            out += [child, *_descendants(child)]
    return out


def _encoder_of(server: int) -> int:
    (encoder,) = [
        c for c in _descendants(server) if b"record.encoder" in _read(f"/proc/{c}/cmdline")
    ]
    return encoder


def _read(path: str) -> bytes:
    try:
        return Path(path).read_bytes()
    except OSError:
        return b""


def _alive(pid: int) -> bool:
    """Running, not a zombie (an exited child of an exited server is reaped by init)."""
    stat = _read(f"/proc/{pid}/stat")
    return bool(stat) and stat.rsplit(b")", 1)[1].split()[0] != b"Z"


def _wait_sim(client: Client, seconds: float) -> float:
    """Waits until `seconds` more of sim time have passed; the sim time then."""
    until, deadline = client.stats()["sim_time"] + seconds, time.monotonic() + 60.0
    while (now := client.stats()["sim_time"]) < until and time.monotonic() < deadline:
        time.sleep(0.05)
    return now


def _summary(path: Path) -> dict[str, int]:
    """topic → message count from the file's summary (which must be there), CRCs checked."""
    from mcap.reader import make_reader

    with path.open("rb") as stream:
        reader = make_reader(stream, validate_crcs=True)
        summary = reader.get_summary()
        assert summary is not None and summary.statistics is not None, "no summary"
        assert any(m.name == "rosbag2" for m in reader.iter_metadata()), "no rosbag2 metadata"
        counts = summary.statistics.channel_message_counts
        return {c.topic: counts.get(i, 0) for i, c in summary.channels.items()}


def _last_stamps(path: Path) -> dict[str, float]:
    """topic → last log time [s] a streaming reader reaches in a file that may be cut."""
    from mcap.exceptions import McapError
    from mcap.stream_reader import StreamReader

    channels: dict[int, str] = {}
    last: dict[str, float] = {}
    with path.open("rb") as stream:
        try:
            for record in StreamReader(stream).records:
                kind = type(record).__name__
                if kind == "Channel":
                    channels[record.id] = record.topic
                elif kind == "Message":
                    topic = channels[record.channel_id]
                    last[topic] = max(last.get(topic, 0.0), record.log_time * 1e-9)
        except (McapError, EOFError, struct.error):
            pass  # the cut: the chunk being written when the processes died
    return last


ENDINGS = ["twin stop", "SIGTERM", "SIGINT to the group", "SIGTERM to the group"]


def test_a_ctrl_c_while_the_encoder_starts_leaves_a_finished_file(tmp_path, serve_world):
    """Ctrl-C to the world's group the moment its encoder process exists, before the encoder's
    imports: the world ends and the file it opened still gets its header and summary."""
    out, rt = tmp_path / "run.mcap", tmp_path / "rt"
    with serve_world(rt, "early", "--record", str(out), new_session=True) as (_, proc):
        encoder = _encoder_of(proc.pid)
        os.killpg(proc.pid, signal.SIGINT)
        proc.wait(timeout=STOP_PATIENCE_S)
        deadline = time.monotonic() + 60.0
        while _alive(encoder) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not _alive(encoder), "the encoder outlived its world"
    assert "/clock" in _summary(out), "the file has its summary"


@pytest.mark.parametrize("ending", ENDINGS)
def test_a_recording_world_that_is_stopped_leaves_a_finished_file_and_no_process(
    tmp_path: Path, ending: str, serve_world
) -> None:
    """Recording from the start (`--record`), a humanoid spawned: however the world is asked to
    end, it ends well within `twin stop`'s patience, the file has its summary and rosbag2
    metadata, and no encoder is left behind. A signal to the group ends the world, which
    stops its encoder."""
    out, rt = tmp_path / "run.mcap", tmp_path / "rt"
    with serve_world(rt, "ends", "--record", str(out), new_session=True) as (client, proc):
        client.spawn(HUMANOID, name="h", pose={"z": 1.0})
        encoder = _encoder_of(proc.pid)
        _wait_sim(client, 1.0)
        start = time.monotonic()
        if ending == "twin stop":
            done = _twin(rt, "stop", "--world", "ends")
            assert done.returncode == 0, done.stderr
        elif ending == "SIGTERM":
            proc.send_signal(signal.SIGTERM)
        else:  # a terminal's Ctrl-C; a session or service ended
            os.killpg(proc.pid, signal.SIGINT if "SIGINT" in ending else signal.SIGTERM)
        proc.wait(timeout=STOP_PATIENCE_S)
        took = time.monotonic() - start
        print(f"{ending}: the world ended {took:.2f} s after it was asked")
        deadline = time.monotonic() + 10.0
        while _alive(encoder) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not _alive(encoder), "the encoder outlived its world"
    assert took < STOP_PATIENCE_S / 3, f"{ending} took {took:.1f} s"
    counts = _summary(out)
    assert counts["/clock"] >= 100 and counts["/h/joint_states"] >= 90, counts


def test_an_encoder_told_to_stop_finishes_when_its_parent_dies_before_the_answer(tmp_path):
    """`twin stop` escalates to SIGKILL while the server waits for its encoder's "done": the
    encoder has taken "stop" and must not wait on the pipe (a dead parent's pipe is readable,
    at its end, for ever); it closes the file with its summary and returns."""
    from twin_cli.record import encoder, ring
    from twin_cli.record.bag_recording import _pipe
    from twin_cli.record.sampler import Sampler
    from twin_cli.world import Pose, World
    from twin_cli.world.observers import world_view

    world = World()
    world.spawn(HUMANOID, name="h", pose=Pose(z=1.0))
    memory = ring.allocate(1 << 16)[1]
    data, header, _ = ring.views(memory)
    parent, child = _pipe()
    out = tmp_path / "r.mcap"
    thread = threading.Thread(target=encoder.encode_main, args=(memory, child, str(out)))
    thread.daemon = True
    thread.start()
    assert parent.recv()[0] == "ready"
    writer = ring.RingWriter(data, header, lambda: True)
    index, descriptions = Sampler(world).selection(world_view(world))
    parent.send(("layout", 0, world.model, index, descriptions, writer.start_layout(world.model)))
    for _ in range(5):
        world.step(10)
        assert writer.put(world.data)
    parent.send(("stop", {}))
    parent.close()  # the server is killed before it reads "done"
    thread.join(15.0)
    assert not thread.is_alive(), "the encoder waits on its dead parent's pipe"
    assert _summary(out)["/clock"] == 5


def test_a_stop_out_of_patience_lets_the_encoder_finish_the_file_on_its_own(tmp_path):
    """A server shutting down waits for its encoder only so long (`Consumers.close`); past that
    the encoder, which has "stop", still drains the ring, writes the summary and exits. Stopped
    at once, the encoder is still importing: it cannot have answered."""
    from twin_cli.record.bag_recording import BagRecording
    from twin_cli.world import Pose, World

    world = World()
    world.spawn(HUMANOID, name="h", pose=Pose(z=1.0))
    out = tmp_path / "late.mcap"
    recording = BagRecording(world, out, rate=100).start()
    world.step(200)  # 20 samples at 100 Hz after the first
    status = recording.stop(patience=0.0)
    assert status.error == "the encoder finishes the file in the background", status
    assert recording._process.wait(timeout=60.0) == 0
    assert _summary(out)["/clock"] == 21


def test_a_bag_is_flushed_every_second_of_sim_time_and_when_idle(tmp_path):
    """Three seconds of sim time written in under one of wall time reach the file every second
    of sim time (a streaming reader reads them before the file is closed); the last messages
    reach it once the writer has idled a second (`flush_if_due`)."""
    from twin_cli.record import messages as ros
    from twin_cli.record.mcap_writer import FLUSH_PERIOD_S, BagWriter
    from twin_cli.record.topics import CLOCK, Message

    out = tmp_path / "flush.mcap"
    writer = BagWriter(out)
    writer.add_topic(CLOCK)
    clock = ros.types()[ros.CLOCK]
    for k in range(300):  # 3 s at 100 Hz, 0.9 s of wall time
        t = k * 0.01
        writer.write(Message(CLOCK.name, ros.CLOCK, t, clock(clock=ros.stamp(t))))
        if k % 100 == 99:
            time.sleep(0.3)
    assert _last_stamps(out).get("/clock", 0.0) >= 1.99, "not flushed by sim time"
    time.sleep(FLUSH_PERIOD_S + 0.1)
    writer.flush_if_due()
    assert _last_stamps(out)["/clock"] == pytest.approx(2.99)
    writer.close()


def test_a_sigkill_of_every_twin_process_on_a_loaded_machine_loses_under_two_seconds(
    tmp_path: Path, serve_world
) -> None:
    """Two busy processes take both cores; the recording starts on them (the encoder imports
    under load), runs at factor 1 for six seconds of sim time, and server and encoder are
    killed with SIGKILL. A streaming reader reads every topic up to less than `LOST_MAX_S`
    of sim time before the kill."""
    out, rt = tmp_path / "killed.mcap", tmp_path / "rt"
    busy = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(2)]
    try:
        with serve_world(rt, "killall", new_session=True) as (client, proc):
            client.spawn(HUMANOID, name="h", pose={"z": 1.0})
            client.request("POST", "/record", body={"path": str(out), "rate": 100})
            sim = _wait_sim(client, 6.0)
            for pid in (*_descendants(proc.pid), proc.pid):  # the encoder first
                _kill(pid)
            proc.wait(timeout=20)
    finally:
        for p in busy:
            p.kill()
            p.wait()
    last = _last_stamps(out)
    lost = {t: round(sim - last.get(t, 0.0), 2) for t in ("/clock", "/tf", "/h/joint_states")}
    print(f"sim time at the kill {sim:.2f} s; lost [s]: {lost}")
    assert max(lost.values()) < LOST_MAX_S, lost
