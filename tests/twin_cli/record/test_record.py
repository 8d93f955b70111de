"""Recording the bundled humanoid falling, read back by readers independent of the writer."""

from __future__ import annotations

import io
import math
import time
from pathlib import Path

import numpy as np
import pytest
from record_helpers import compose_links, pose_error, read_bag, seconds

import scenarios
from twin_cli.errors import EntityNotFoundError, InvalidRequestError, RequestError
from twin_cli.record import BagRecording, BagSink, Recording
from twin_cli.world import Pose, World

HUMANOID = Path(scenarios.HUMANOID)
RATE = 100.0  # [Hz]
STEPS_PER_SAMPLE = 10  # 1 ms world step
SAMPLES = 200  # 2 s
POSITION_TOL = 1e-9  # [m]
QUAT_TOL = 1e-9


@pytest.fixture(scope="module")
def falling(tmp_path_factory) -> tuple[Path, dict[float, dict], dict[float, list], dict]:
    """2 s of the humanoid falling from 1 m, tilted (so its frame is turned while it moves),
    sampled at 100 Hz; the world's own link poses and
    joint states at each sample time, read through World's API as `twin links/joints` do, and
    the free joint's velocity (world-frame linear, body-frame angular: MuJoCo's qvel)."""
    world = World()
    world.spawn(HUMANOID, name="h", pose=Pose(z=1.0, roll=0.3, pitch=0.2))
    path = tmp_path_factory.mktemp("rec") / "fall.mcap"
    recording = BagRecording(world, path, rate=RATE).start()  # encoded in another process
    links, joints = {0.0: world.link_poses("h")}, {0.0: world.joint_states("h")}
    velocities = {0.0: world.data.qvel[:6].copy()}  # the only entity: its free joint comes first
    for _ in range(SAMPLES):
        world.step(STEPS_PER_SAMPLE)
        if not hasattr(world, "add_observer"):
            recording.capture_now()
        t = round(float(world.data.time), 9)
        links[t], joints[t] = world.link_poses("h"), world.joint_states("h")
        velocities[t] = world.data.qvel[:6].copy()
    status = recording.stop()
    assert status.error is None and status.samples == SAMPLES + 1, status
    return path, links, joints, velocities


def test_every_message_deserializes_and_clock_ticks_at_the_rate(falling):
    path, *_ = falling
    bag = read_bag(path)
    assert {"/clock", "/tf", "/tf_static", "/h/joint_states", "/h/odom"} <= set(bag)
    clock = np.array([seconds(m.clock) for _, m in bag["/clock"]])
    assert len(clock) == SAMPLES + 1, "number of /clock messages"
    assert np.allclose(np.diff(clock), 1.0 / RATE, atol=1e-9), "/clock period"
    log_times = np.array([stamp for stamp, _ in bag["/clock"]]) * 1e-9
    assert np.allclose(log_times, clock, atol=1e-9), "log time is sim time"


def test_tf_composes_to_the_worlds_link_poses(falling):
    path, links, *_ = falling
    bag = read_bag(path)
    ((_, tf_static),) = bag["/tf_static"]
    assert {t.child_frame_id for t in tf_static.transforms} == {"h/imu_link"}, "lumped link frame"
    picks = np.linspace(0, SAMPLES, 20).astype(int)
    for k in picks:
        _, tf = bag["/tf"][k]
        t = round(seconds(tf.transforms[0].header.stamp), 9)
        composed = compose_links(tf, tf_static)
        for link, pose in links[t].items():
            dp, dq = pose_error(composed[f"h/{link}"], pose)
            assert dp < POSITION_TOL, f"position of {link} at t={t}: {dp} m"
            assert dq < QUAT_TOL, f"orientation of {link} at t={t}: {dq}"


def test_joint_states_equal_the_worlds(falling):
    path, _, joints, _ = falling
    for _, message in read_bag(path)["/h/joint_states"]:
        t = round(seconds(message.header.stamp), 9)
        expected = joints[t]
        assert list(message.name) == [j.name for j in expected]
        for field in ("position", "velocity", "effort"):
            got = np.asarray(getattr(message, field))
            want = np.array([getattr(j, field) for j in expected])
            assert np.array_equal(got, want), f"{field} at t={t}"


def test_odometry_is_the_root_pose(falling):
    path, links, *_ = falling
    for _, message in read_bag(path)["/h/odom"][::20]:
        t = round(seconds(message.header.stamp), 9)
        p, q = message.pose.pose.position, message.pose.pose.orientation
        composed = (np.array([p.x, p.y, p.z]), np.array([q.w, q.x, q.y, q.z]))
        dp, dq = pose_error(composed, links[t]["torso"])
        assert dp < POSITION_TOL and dq < QUAT_TOL, f"odometry at t={t}"
        assert message.child_frame_id == "h/torso" and message.header.frame_id == "world"


def test_odometry_twist_is_the_root_velocity_in_the_root_frame(falling):
    """nav_msgs/Odometry's twist is in child_frame_id: the linear velocity is the world-frame
    one rotated into the torso's frame (Rᵀ v, R from the recorded orientation, composed here
    with its own formula), the angular one MuJoCo's body-frame rate."""
    path, _, _, velocities = falling
    moving = 0
    for _, message in read_bag(path)["/h/odom"]:
        t = round(seconds(message.header.stamp), 9)
        o, twist = message.pose.pose.orientation, message.twist.twist
        w, x, y, z = o.w, o.x, o.y, o.z
        rotation = np.array(
            [
                [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
            ]
        )
        v = velocities[t]
        linear = np.array([twist.linear.x, twist.linear.y, twist.linear.z])
        angular = np.array([twist.angular.x, twist.angular.y, twist.angular.z])
        assert np.allclose(linear, rotation.T @ v[:3], atol=1e-9), f"linear twist at t={t}"
        assert np.array_equal(angular, v[3:6]), f"angular twist at t={t}"
        moving += np.linalg.norm(v[:3]) > 0.1 and not np.allclose(rotation, np.eye(3), atol=1e-2)
    assert moving > 10, "the check saw the torso moving and turned"


def test_robot_description_is_the_urdf_whose_links_are_the_frames(falling):
    import yourdfpy

    path, links, *_ = falling
    ((_, message),) = read_bag(path)["/h/robot_description"]
    urdf = yourdfpy.URDF.load(io.StringIO(message.data), load_meshes=False)
    assert set(links[0.0]) | {"imu_link"} == set(urdf.link_map), "URDF links vs recorded frames"


def test_mcap_library_validates_chunks_summary_and_rosbag2_metadata(falling):
    import yaml
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    path, _, joints, _ = falling
    with path.open("rb") as stream:
        reader = make_reader(stream, validate_crcs=True, decoder_factories=[DecoderFactory()])
        summary = reader.get_summary()
        assert summary is not None and summary.chunk_indexes, "summary with chunk indexes"
        assert all(s.encoding == "ros2msg" for s in summary.schemas.values())
        assert all(c.message_encoding == "cdr" for c in summary.channels.values())
        latched = {
            c.topic
            for c in summary.channels.values()
            if yaml.safe_load(c.metadata["offered_qos_profiles"])[0]["durability"] == 1
        }  # rmw's RMW_QOS_POLICY_DURABILITY_TRANSIENT_LOCAL
        assert latched == {"/tf_static", "/h/robot_description"}
        decoded = [m for _, _, _, m in reader.iter_decoded_messages(topics=["/h/joint_states"])]
        count = sum(1 for _ in reader.iter_messages())
        (meta,) = [m for m in reader.iter_metadata() if m.name == "rosbag2"]
    info = yaml.safe_load(meta.metadata["serialized_metadata"])
    assert info["message_count"] == count == summary.statistics.message_count
    assert len(decoded) == SAMPLES + 1
    last = decoded[-1]  # a second CDR decoder agrees with the world
    t = round(last.header.stamp.sec + last.header.stamp.nanosec * 1e-9, 9)
    assert list(last.position) == [j.position for j in joints[t]]


def test_bad_requests_name_the_subject_and_the_fix(tmp_path):
    world = World()
    world.spawn(HUMANOID, name="h", pose=Pose(z=1.0))
    with pytest.raises(RequestError, match="cannot be written.*writable directory"):
        BagSink(tmp_path / "missing" / "out.mcap")
    (tmp_path / "taken.mcap").write_bytes(b"")
    with pytest.raises(RequestError, match="already exists.*remove it"):
        BagSink(tmp_path / "taken.mcap")
    with pytest.raises(EntityNotFoundError, match=r"Entity \[nobody\].*entities in this world: h"):
        Recording(world, [], entities=["nobody"])
    with pytest.raises(InvalidRequestError, match="rate"):
        Recording(world, [], rate=0.0)


class FakeClock:
    """The sim clock `Observers.run` reads (`time`) and a `step(k)` that advances it by k ms."""

    def __init__(self) -> None:
        self.time = 0.0
        self.steps: list[int] = []

    def step(self, k: int) -> None:
        self.steps.append(k)
        self.time = round(self.time + k * 0.001, 12)


def test_observers_fire_on_the_rate_grid_across_batch_sizes():
    """The stepping splits batches where an observer is due: any batch size, same sample times."""
    from twin_cli.world.observers import Observers, next_due, steps_until_due

    assert steps_until_due(0.0, 0.01, 0.001) == 10
    assert next_due(0.0100000000001, 0.0, 0.01, 0.001) == pytest.approx(0.02)
    for batch in (1, 7, 10, 333):
        clock = FakeClock()
        seen: list[float] = []
        observers = Observers()
        observers.add(lambda clock=clock, seen=seen: seen.append(clock.time), 100.0, 0.0, 0.001)
        for _ in range(1000 // batch):
            observers.run(batch, clock.step, clock, 0.001)
        expected = [round(0.01 * k, 12) for k in range(1, len(seen) + 1)]
        assert seen == pytest.approx(expected, abs=1e-12), f"batch {batch}"
        assert len(seen) == (1000 // batch) * batch // 10


def test_a_full_ring_makes_the_loop_wait_and_says_so_and_a_spawn_changes_the_layout(tmp_path):
    """A ring of ~12 samples: the loop outruns the encoder, waits, loses nothing, and the wait is
    in the status and in the bag's rosbag2 metadata; a spawn mid-recording adds its topics."""
    import yaml
    from mcap.reader import make_reader

    world = World()
    world.spawn(HUMANOID, name="h", pose=Pose(z=1.0))
    path = tmp_path / "small.mcap"
    recording = BagRecording(world, path, rate=RATE, ring_bytes=8 * 1000).start()
    world.step(1000)  # 100 samples in one batch, far faster than they are encoded
    world.spawn(HUMANOID, name="h2", pose=Pose(x=2.0, z=1.0))
    world.step(1000)
    status = recording.stop()
    assert status.error is None and status.samples == 201, status
    assert status.waits > 0 and status.blocked_s > 0.0, "the full ring was waited for"
    bag = read_bag(path)
    clock = np.array([seconds(m.clock) for _, m in bag["/clock"]])
    assert np.allclose(np.diff(clock), 1.0 / RATE, atol=1e-9), "no sample lost"
    assert len(bag["/h2/joint_states"]) == 100, "the spawned entity from its first sample on"
    assert len(bag["/h2/robot_description"]) == 1
    with path.open("rb") as stream:
        (meta,) = [m for m in make_reader(stream).iter_metadata() if m.name == "rosbag2"]
    custom = yaml.safe_load(meta.metadata["serialized_metadata"])["custom_data"]
    assert int(custom["waits"]) == status.waits and float(custom["blocked_s"]) > 0.0


def test_observers_added_at_different_times_all_restart_when_the_clock_goes_back():
    """An observer added at t = 0 and one added at t = 0.5 s (a spawn re-registers a recording's
    sensor observers): after a reset of the clock to 0.2 s both fire again from there on."""
    from twin_cli.world.observers import Observers

    clock = FakeClock()
    step = clock.step
    early: list[float] = []
    late: list[float] = []
    observers = Observers()
    observers.add(lambda: early.append(clock.time), 100.0, 0.0, 0.001)
    observers.run(500, step, clock, 0.001)
    observers.add(lambda: late.append(clock.time), 100.0, clock.time, 0.001)
    clock.time = 0.2  # the clock goes back (reset), before the late observer's origin
    early.clear()
    observers.run(50, step, clock, 0.001)
    expected = [round(0.2 + 0.01 * k, 12) for k in range(1, 6)]
    assert early == pytest.approx(expected, abs=1e-12)
    assert late == pytest.approx(expected, abs=1e-12), "the later observer re-anchored too"


def test_an_observer_that_removes_itself_or_adds_another_keeps_the_steps_and_the_grid():
    """Callbacks may change the observers (a recording ends at its duration, a spawn adds sensor
    observers): the batch still takes all its steps and later observers keep their own grid."""
    from twin_cli.world.observers import Observers

    clock = FakeClock()
    step, steps = clock.step, clock.steps

    observers = Observers()
    first: list[float] = []
    second: list[float] = []

    def once_then_more() -> None:
        first.append(clock.time)
        if len(first) == 3:
            observers.remove(handle)
            observers.add(lambda: second.append(clock.time), 40.0, clock.time, 0.001)

    handle = observers.add(once_then_more, 100.0, 0.0, 0.001)
    observers.run(200, step, clock, 0.001)
    assert sum(steps) == 200 and clock.time == pytest.approx(0.2)
    assert first == pytest.approx([0.01, 0.02, 0.03], abs=1e-12)
    assert second == pytest.approx([0.03 + 0.025 * k for k in range(1, 7)], abs=1e-12)


def test_two_observers_at_unrelated_rates_each_fire_on_their_own_grid():
    """100 Hz and 30 Hz observers stepped in batches of 7: `Observers.run` splits each batch at
    both grids (30 Hz: the first step at or after k/30 s)."""
    from twin_cli.world.observers import Observers

    clock = FakeClock()
    step = clock.step
    fast: list[float] = []
    slow: list[float] = []
    observers = Observers()
    observers.add(lambda: fast.append(clock.time), 100.0, 0.0, 0.001)
    observers.add(lambda: slow.append(clock.time), 30.0, 0.0, 0.001)
    for _ in range(143):  # 1.001 s
        observers.run(7, step, clock, 0.001)
    assert fast == pytest.approx([0.01 * k for k in range(1, 101)], abs=1e-12)
    expected = [math.ceil(round(k / 30 / 0.001, 9)) * 0.001 for k in range(1, 31)]
    assert slow == pytest.approx(expected, abs=1e-12)


def test_ring_records_keep_their_layout_across_wraps_and_model_changes():
    """The ring's records have no header: writer and reader agree on each model's record length
    and on where a new model's records start, through a wrap that leaves the end unused."""
    import mujoco

    from twin_cli.record import ring

    body = '<body><freejoint/><geom size="0.1"/></body>'
    models = [
        mujoco.MjModel.from_xml_string(
            f'<mujoco><worldbody>{body * n}<body mocap="true"/></worldbody></mujoco>'
        )
        for n in (1, 3)
    ]
    data, header, _ = ring.views(ring.allocate(211)[1])  # no record length (27, 65) divides it
    writer, reader = ring.RingWriter(data, header, lambda: True), ring.RingReader(data, header)
    written, read = [], []
    for k in range(40):
        model = models[(k // 7) % 2]
        if k % 7 == 0:
            reader.add_layout(writer.start_layout(model), k // 7, model)
            d = mujoco.MjData(model)
        d.time, d.qpos[:] = 0.01 * k, np.arange(model.nq) + k
        d.qvel[:], d.qfrc_actuator[:] = -k, 0.5 * k
        d.mocap_pos[:] = k
        assert writer.put(d)
        mocap = [d.mocap_pos.ravel(), d.mocap_quat.ravel()]
        state = np.concatenate([[d.time], d.qpos, d.qvel, *mocap, d.qfrc_actuator])
        written.append((k // 7, state))
        if k % 2 == 1:  # the reader lags a record behind (two always fit, with a wrap's skip)
            read += [(e, r) for e, run in reader.read(int(header[ring.WRITE]), 100) for r in run]
    read += [(e, r) for e, run in reader.read(int(header[ring.WRITE]), 100) for r in run]
    assert len(read) == len(written)
    for (epoch, record), (want_epoch, want) in zip(read, written, strict=True):
        assert epoch == want_epoch and np.array_equal(record, want)


def test_an_observer_that_outlives_another_keeps_its_own_grid():
    """Two observers on different grids; the first removes itself (a follower that finishes):
    the survivor, which was not due at that step, is still called on its own grid only."""
    from twin_cli.world.observers import Observers

    clock = FakeClock()
    observers = Observers()
    survivor: list[float] = []
    handles = {}
    handles["a"] = observers.add(lambda: observers.remove(handles["a"]), 100.0, 0.0, 0.001)
    clock.step(5)
    observers.add(lambda: survivor.append(clock.time), 100.0, clock.time, 0.001)
    observers.run(60, clock.step, clock, 0.001)
    observers.run(20, clock.step, clock, 0.001)
    assert survivor == pytest.approx([0.015 + 0.01 * k for k in range(8)], abs=1e-12)


def test_an_observer_added_by_a_callback_leaves_the_first_on_its_grid():
    """A 100 Hz observer's callback adds a 7 Hz one on its third call: the first observer is
    still called exactly every 10 steps (no extra call from a due time left behind)."""
    from twin_cli.world.observers import Observers

    clock = FakeClock()
    observers = Observers()
    seen: list[float] = []

    def first() -> None:
        seen.append(clock.time)
        if len(seen) == 3:
            observers.add(lambda: None, 7.0, clock.time, 0.001)

    observers.add(first, 100.0, 0.0, 0.001)
    observers.run(100, clock.step, clock, 0.001)
    assert seen == pytest.approx([0.01 * k for k in range(1, 11)], abs=1e-12)


def test_the_encoder_takes_a_record_written_while_it_reads_the_pipe(tmp_path):
    """The encoder reads the write position, then the pipe (layouts, readings, stop). A last
    sample written in between, just before "stop", is still encoded: the encoder looks at the
    ring again before it ends. The pipe is real; a wrapper holds one poll until the test has
    written that sample and sent stop."""
    import threading

    from twin_cli.record import encoder, ring
    from twin_cli.record.bag_recording import _pipe
    from twin_cli.record.sampler import Sampler
    from twin_cli.world.observers import world_view

    world = World()
    world.spawn(HUMANOID, name="h", pose=Pose(z=1.0))
    memory = ring.allocate(1 << 16)[1]
    data, header, _ = ring.views(memory)
    parent, child = _pipe()
    entered, release = threading.Event(), threading.Event()

    class HeldPipe:
        held = False

        def poll(self, *args: float) -> bool:
            if self.held:
                self.held = False
                entered.set()
                release.wait()
            return child.poll(*args)

        def recv(self):  # noqa: ANN202
            return child.recv()

        def send(self, message: tuple) -> None:
            child.send(message)

    pipe = HeldPipe()
    thread = threading.Thread(
        target=encoder.encode_main, args=(memory, pipe, str(tmp_path / "r.mcap"))
    )
    thread.start()
    assert parent.recv()[0] == "ready"
    writer = ring.RingWriter(data, header, lambda: True)
    index, descriptions = Sampler(world).selection(world_view(world))
    start = writer.start_layout(world.model)
    parent.send(("layout", 0, world.model, index, descriptions, start))
    for _ in range(5):
        world.step(10)
        assert writer.put(world.data)
    while header[ring.READ] != header[ring.WRITE]:
        time.sleep(0.001)
    pipe.held = True
    assert entered.wait(10.0)  # the encoder has read the write position and polls the pipe
    world.step(10)
    assert writer.put(world.data)
    parent.send(("stop", {}))
    release.set()
    thread.join(30.0)
    assert int(header[ring.SAMPLES]) == 6 and header[ring.READ] == header[ring.WRITE]


def test_the_encoder_wakes_for_the_parent_at_once_not_after_its_idle_wait(tmp_path, monkeypatch):
    """Between runs of records the encoder waits for the ring to fill, but a layout, sensor
    readings (a camera image is larger than the pipe's buffer: its send blocks until read) or
    stop wake it at once. With a 30 s idle wait, both messages are taken within seconds."""
    import threading

    from twin_cli.record import encoder, ring
    from twin_cli.record.bag_recording import _pipe
    from twin_cli.record.sampler import Sampler
    from twin_cli.world.observers import world_view

    monkeypatch.setattr(encoder, "IDLE_S", 30.0)
    world = World()
    world.spawn(HUMANOID, name="h", pose=Pose(z=1.0))
    memory = ring.allocate(1 << 16)[1]
    data, header, _ = ring.views(memory)
    parent, child = _pipe()
    thread = threading.Thread(
        target=encoder.encode_main, args=(memory, child, str(tmp_path / "r.mcap")), daemon=True
    )
    thread.start()
    assert parent.recv()[0] == "ready"
    time.sleep(0.2)  # the encoder is in its idle wait
    writer = ring.RingWriter(data, header, lambda: True)
    index, descriptions = Sampler(world).selection(world_view(world))
    parent.send(("layout", 0, world.model, index, descriptions, writer.start_layout(world.model)))
    assert writer.put(world.data)
    time.sleep(0.2)
    parent.send(("stop", {}))
    assert parent.poll(10.0), "the encoder answered stop within 10 s, not after its idle wait"
    assert parent.recv() == ("done", None)
    thread.join(10.0)
    assert int(header[ring.SAMPLES]) == 1


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs Linux's /dev/full")
def test_a_full_disk_stops_the_recording_with_the_file_and_the_cause(tmp_path):
    """Every write to /dev/full fails with ENOSPC. foxglove-sdk's MCAP writer only logs its
    write errors, so twin keeps the file's own: the recording ends with it, naming the file."""
    world = World()
    world.spawn(HUMANOID, name="h", pose=Pose(z=1.0))
    out = tmp_path / "full.mcap"
    out.symlink_to("/dev/full")
    recording = BagRecording(world, out, rate=RATE, overwrite=True).start()
    deadline = time.monotonic() + 60.0
    while not _ended(recording.encoder_pid) and time.monotonic() < deadline:
        world.step(100)
        time.sleep(0.01)
    status = recording.stop()
    assert "No space left on device" in str(status.error) and str(out) in str(status.error)


def _ended(pid: int) -> bool:
    """Whether process `pid` has exited (a zombie not yet reaped counts; Linux /proc)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] in "ZX"
    except OSError:
        return True


class _Collect:
    """A sink that keeps each message's topic, time and CDR bytes."""

    def __init__(self) -> None:
        self.messages: list[tuple[str, float, bytes]] = []

    def set_topics(self, topics: list) -> None:
        pass

    def write(self, message) -> None:  # noqa: ANN001
        self.messages.append((message.topic, message.time, message.cdr()))

    def close(self) -> None:
        pass


PENDULUM = """<mujoco><worldbody><body name="upper" pos="0 0 1">
  <joint name="shoulder" type="ball"/><geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/>
  <body name="lower" pos="0.3 0 0"><joint name="elbow" axis="0 1 0"/>
    <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/></body>
</body></worldbody><actuator><motor joint="elbow" gear="2"/></actuator></mujoco>"""


def test_a_batch_of_samples_encodes_as_each_sample_alone_and_skips_a_diverged_one():
    """The encoder turns up to 256 records at once into messages (vectorised poses, joint
    states and twists; reused message objects; serialization into kept buffers). Its bytes
    equal those of each sample published alone, a diverged sample is left out, and a ball
    joint's angle and speed decode to `World.joint_states`."""
    from rosbags.typesys import Stores, get_typestore
    from world_helpers import spec_of

    from twin_cli.record.recorder import Publisher
    from twin_cli.record.sampler import Sampler, Samples

    world = World()
    world.spawn(HUMANOID, name="h", pose=Pose(z=1.0))
    world.spawn(spec_of(PENDULUM), name="p")
    quat = np.array([-0.9, 0.3, 0.3, 0.1])  # w < 0: the angle is 2 acos |w|
    world.data.qpos[-5:-1] = quat / np.linalg.norm(quat)  # the pendulum: ball joint, elbow
    world.data.qvel[-4:] = [1.0, -2.0, 0.5, 3.0]
    world.data.ctrl[:] = 0.3
    sampler, samples, states = Sampler(world), [], []
    for _ in range(12):
        world.step(7)
        with world.lock:
            samples.append(sampler.capture())
        states.append(world.joint_states("p"))
    samples[5].qpos[0] = np.nan  # diverged: the world is resetting it
    batch = Samples(
        samples[0].layout,
        np.array([s.time for s in samples]),
        *(np.stack([getattr(s, k) for s in samples]) for k in ("qpos", "qvel", "qfrc_actuator")),
        np.stack([s.mocap_pos for s in samples]),
        np.stack([s.mocap_quat for s in samples]),
    )
    together, alone = _Collect(), _Collect()
    sent = Publisher().publish(batch, together, new_layout=True)
    one = Publisher()
    for k, sample in enumerate(samples):
        one.publish(Samples.of(sample), alone, new_layout=k == 0)
    assert len(sent) == 11 and samples[5].time not in sent.times.tolist()
    assert together.messages == alone.messages, "a batch encodes as its samples one by one"
    store = get_typestore(Stores.ROS2_JAZZY)  # rosbags' own, not twin's
    joints = [
        (t, store.deserialize_cdr(data, "sensor_msgs/msg/JointState"))
        for topic, t, data in together.messages
        if topic == "/p/joint_states"
    ]
    assert [t for t, _ in joints] == [s.time for k, s in enumerate(samples) if k != 5]
    for (_, message), want in zip(joints, [s for k, s in enumerate(states) if k != 5], strict=True):
        assert list(message.name) == [j.name for j in want]
        assert np.allclose(message.position, [j.position for j in want], atol=1e-12)
        assert np.allclose(message.velocity, [j.velocity for j in want], atol=1e-12)
        assert np.allclose(message.effort, [j.effort for j in want], atol=1e-12)
    assert joints[3][1].position[0] > 0.05 and joints[3][1].effort[1] != 0, "it moved, driven"


def test_a_reencoded_message_that_changes_size_is_encoded_anew():
    """`Reencoder` serializes a refilled message into the buffer of its first encoding; a
    message whose size changed (a longer frame id, fewer joints) gets rosbags' full encoding."""
    from twin_cli.record import messages as ros

    T = ros.types()
    stamp = T["builtin_interfaces/msg/Time"](sec=1, nanosec=2)
    message = T[ros.JOINT_STATE](
        header=T["std_msgs/msg/Header"](stamp=stamp, frame_id="a"),
        name=["j1", "j2"],
        position=np.array([1.0, 2.0]),
        velocity=np.array([3.0, 4.0]),
        effort=np.array([5.0, 6.0]),
    )
    reencoder = ros.Reencoder(message, ros.JOINT_STATE)
    for change in (
        lambda: setattr(stamp, "sec", 7),
        lambda: setattr(message.header, "frame_id", "a much longer frame id"),
        lambda: setattr(message, "name", ["j1"]),
        lambda: setattr(message, "position", np.array([9.0])),
        lambda: (
            setattr(message, "velocity", np.array([8.0])),
            setattr(message, "effort", np.zeros(1)),
        ),
    ):
        change()
        assert reencoder() == ros.encode(message, ros.JOINT_STATE)


def test_the_ring_reads_runs_of_records_of_one_layout_up_to_the_limit():
    """The encoder takes runs: consecutive records of one model as one array, split where a new
    layout starts and where the ring wraps, and no more records than the limit."""
    import mujoco

    from twin_cli.record import ring

    body = '<body><freejoint/><geom size="0.1"/></body>'
    models = [
        mujoco.MjModel.from_xml_string(f"<mujoco><worldbody>{body * n}</worldbody></mujoco>")
        for n in (1, 2)
    ]
    lengths = [ring.record_length(m) for m in models]
    assert lengths == [20, 39]  # time, qpos, qvel, qfrc_actuator
    data, header, _ = ring.views(ring.allocate(500)[1])
    writer, reader = ring.RingWriter(data, header, lambda: True), ring.RingReader(data, header)
    times: list[float] = []

    def put(d: mujoco.MjData, count: int) -> None:
        for _ in range(count):
            d.time = len(times)
            times.append(d.time)
            assert writer.put(d)

    for epoch, count in ((0, 4), (1, 2)):
        reader.add_layout(writer.start_layout(models[epoch]), epoch, models[epoch])
        put(mujoco.MjData(models[epoch]), count)
    runs = reader.read(int(header[ring.WRITE]), limit=3)
    assert [(e, r.shape) for e, r in runs] == [(0, (3, 20))]
    runs += reader.read(int(header[ring.WRITE]), limit=100)
    assert [(e, len(r)) for e, r in runs] == [(0, 3), (0, 1), (1, 2)]
    # from 158, eight records of 39 reach 470; the ninth does not fit the end: it starts at 0
    put(mujoco.MjData(models[1]), 10)
    runs += reader.read(int(header[ring.WRITE]), limit=100)
    assert [(e, len(r)) for e, r in runs[3:]] == [(1, 8), (1, 2)]
    assert [float(t) for _, r in runs for t in r[:, 0]] == times


def test_a_recording_is_private_and_a_fifo_without_reader_is_refused_at_once(tmp_path) -> None:
    import os
    import stat

    from twin_cli.errors import RequestError
    from twin_cli.record.mcap_writer import open_output

    with open_output(tmp_path / "run.mcap") as handle:
        handle.write(b"x")
    assert stat.S_IMODE((tmp_path / "run.mcap").stat().st_mode) == 0o600, "0600, as a save"
    fifo = tmp_path / "pipe.mcap"
    os.mkfifo(fifo)
    with pytest.raises(RequestError, match="cannot be written"):
        open_output(fifo, overwrite=True)  # would block the server for ever without a reader
    assert stat.S_ISFIFO(fifo.stat().st_mode), "the FIFO is untouched"


def test_a_velocity_motors_joint_records_its_motors_force_as_effort(tmp_path):
    """A wheel on Gazebo's velocity motor (converters.mjcf.velocity_motors) holding its speed
    against 0.05 N m: the sampler and the ring both record that load as its effort (the
    tendon's force on the joint; its actuator pushes nothing), as `joint_states` reads it."""
    from models import _control_inertial, write_urdf

    from twin_cli.record import ring
    from twin_cli.record.sampler import Sampler

    urdf = f"""<robot name="w"><link name="world"/>
<link name="base">{_control_inertial(1, 1)}</link>
<link name="disc">{_control_inertial(0.2, 1e-3)}</link>
<joint name="fix" type="fixed"><parent link="world"/><child link="base"/></joint>
<joint name="spin" type="continuous"><parent link="base"/><child link="disc"/>
  <axis xyz="0 0 1"/><limit effort="0.1" velocity="10"/></joint>
<ros2_control name="r" type="system"><joint name="spin">
  <command_interface name="velocity"/></joint></ros2_control></robot>"""
    world = World()
    world.spawn(write_urdf(tmp_path, urdf), name="w", pose=Pose(z=1.0))
    world.command("w", "spin", mode="velocity", value=3.0)
    world.push("w", torque=(0.0, 0.0, -0.05), link="disc", duration=10.0)
    world.step(500)
    dof = int(world.model.joint("w/spin").dofadr[0])
    with world.lock:
        sample = Sampler(world).capture()
        data, header, _ = ring.views(ring.allocate(4 * ring.record_length(world.model))[1])
        writer, reader = ring.RingWriter(data, header, lambda: True), ring.RingReader(data, header)
        reader.add_layout(writer.start_layout(world.model), 0, world.model)
        assert writer.put(world.data)
    (_, run), *_ = reader.read(int(header[ring.WRITE]), 10)
    recorded = run[0][-world.model.nv + dof]
    assert world.joint_states("w")[0].effort == pytest.approx(0.05, rel=1e-6), "joint_states"
    assert sample.qfrc_actuator[dof] == pytest.approx(0.05, rel=1e-6), "sampled effort [N m]"
    assert recorded == pytest.approx(0.05, rel=1e-6), "ring's effort [N m]"
