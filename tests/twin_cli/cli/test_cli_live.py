"""`twin topics`, `twin topics echo` and `twin model` against one served world of several robots.

Oracles: a recording of the same world (the topics it holds), the sim-time stamps of echoed
messages (the stated rate), `twin joints` and `twin pose` (the same state read another way),
and `/tf` composed from the world frame (the link poses `twin model` reports).
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from models import CONTROL_RIG, two_wheel_bot
from sensor_models import imu_box, lidar_post
from signal_state import signal_state

import scenarios

WORLD = "live"
DRIVE = (
    '<plugin name="dd" filename="libgazebo_ros_diff_drive.so"><left_joint>lj</left_joint>'
    "<right_joint>rj</right_joint><odometry_frame>odo</odometry_frame>"
    "<robot_base_frame>base</robot_base_frame></plugin>"
)
ROBOTS = {  # name → (URDF text or file, spawn height [m])
    "rig": (CONTROL_RIG, 1.0),
    "box": (imu_box(), 0.5),
    "post": (lidar_post(), 0.0),
    "bot": (two_wheel_bot(DRIVE), 0.3),
}


@pytest.fixture(scope="module")
def world(tmp_path_factory, serve_world):
    """A world with the bundled humanoid and four test robots (IMU, lidar, diff drive, rig)."""
    runtime_dir = tmp_path_factory.mktemp("rt")
    with serve_world(runtime_dir, WORLD) as (client, _proc):
        client.spawn(str(scenarios.HUMANOID), name="humanoid", pose={"x": 2.0, "z": 1.2})
        for name, (text, z) in ROBOTS.items():
            path = runtime_dir / f"{name}.urdf"
            path.write_text(text)
            client.spawn(str(path), name=name, pose={"x": -2.0 * len(name), "z": z})
        client.command_joints("rig", {"spin": 1.5}, mode="velocity")
        yield client, runtime_dir


def twin(world, *args: str, check: bool = True, timeout: float = 60):
    """`twin ARGS --world live` as a user runs it; its completed process."""
    _, runtime_dir = world
    env = {**os.environ, "TWIN_RUNTIME_DIR": str(runtime_dir)}
    env.pop("TWIN_WORLD", None)
    done = subprocess.run(
        [sys.executable, "-m", "twin_cli.cli.app", *args, "--world", WORLD],
        env=env, capture_output=True, text=True, timeout=timeout,
    )  # fmt: skip
    if check:
        assert done.returncode == 0, f"twin {' '.join(args)}: exit {done.returncode}: {done.stderr}"
    return done


def _echo(world, topic: str, n: int, *extra: str) -> list[dict]:
    lines = twin(world, "topics", "echo", topic, "-n", str(n), "--json", *extra).stdout.splitlines()
    assert len(lines) == n, f"{topic}: {len(lines)} messages, asked for {n}"
    return [json.loads(line) for line in lines]


def _stamp(message: dict) -> float:
    stamp = message["message"]["header"]["stamp"]
    return stamp["sec"] + stamp["nanosec"] * 1e-9


def test_topics_lists_each_entitys_streams_as_a_recording_holds_them(world, tmp_path):
    client, _ = world
    listed = {t["name"]: t for t in json.loads(twin(world, "topics", "--json").stdout)}
    expected = {
        "/clock": ("rosgraph_msgs/msg/Clock", 100.0),
        "/tf": ("tf2_msgs/msg/TFMessage", 100.0),
        "/tf_static": ("tf2_msgs/msg/TFMessage", 0.0),
        "/humanoid/joint_states": ("sensor_msgs/msg/JointState", 100.0),
        "/humanoid/odom": ("nav_msgs/msg/Odometry", 100.0),
        "/rig/joint_states": ("sensor_msgs/msg/JointState", 100.0),
        "/rig/robot_description": ("std_msgs/msg/String", 0.0),
        "/box/imu": ("sensor_msgs/msg/Imu", 200.0),
        "/post/scan": ("sensor_msgs/msg/LaserScan", 10.0),
        "/bot/odom": ("nav_msgs/msg/Odometry", 100.0),
    }
    for name, (kind, rate) in expected.items():
        assert name in listed, f"{name} not listed; listed: {sorted(listed)}"
        assert (listed[name]["type"], listed[name]["rate"]) == (kind, rate), listed[name]
    assert "/rig/odom" not in listed, "a fixed base has no odometry"
    assert listed["/tf_static"]["latched"] and not listed["/tf"]["latched"]
    drive = listed["/bot/cmd_vel"]  # an input `twin serve --ros` reads, listed after bot's topics
    assert (drive["type"], drive["rate"], drive["command"]) == ("geometry_msgs/msg/Twist", 0, True)
    assert not any(t["command"] for t in listed.values() if t["name"] in expected)

    out = tmp_path / "all.mcap"  # a recording holds the very same topics and types
    client.request("POST", "/record", body={"path": str(out), "rate": 100, "duration": 0.3})
    deadline = time.monotonic() + 30
    while client.request("GET", "/record")["active"] and time.monotonic() < deadline:
        time.sleep(0.1)
    client.request("DELETE", "/record")
    from mcap.reader import make_reader

    with out.open("rb") as stream:
        summary = make_reader(stream).get_summary()
    recorded = {c.topic: summary.schemas[c.schema_id].name for c in summary.channels.values()}
    sent = {name: t["type"] for name, t in listed.items() if not t["command"]}
    assert recorded == sent, "recorded ≠ listed"

    piped = twin(world, "topics").stdout.splitlines()
    assert piped[0].split("\t") == ["topic", "type", "rate", "entity"], piped[0]
    assert "/box/imu\tsensor_msgs/msg/Imu\t200 Hz\tbox" in piped, piped
    assert "/bot/cmd_vel\tgeometry_msgs/msg/Twist\tcommand (in)\tbot" in piped, piped


def test_echo_stamps_follow_the_stated_rates(world):
    client, _ = world
    client.resume()
    for topic, n in (("/rig/joint_states", 21), ("/box/imu", 21), ("/clock", 11)):
        rate = {t["name"]: t["rate"] for t in client.request("GET", "/topics")}[topic]
        messages = _echo(world, topic, n)
        times = np.array([m["time"] for m in messages])
        if topic != "/clock":
            assert np.allclose(times, [_stamp(m) for m in messages], atol=1e-9), "header stamp"
        gaps = np.diff(times)
        assert np.all(np.abs(gaps * rate - 1.0) < 0.1), f"{topic}: gaps {gaps} s at {rate} Hz"
    slow = _echo(world, "/rig/joint_states", 3, "--rate", "20")
    assert np.allclose(np.diff([m["time"] for m in slow]), 0.05, rtol=0.1), "--rate 20"


def test_echoed_joint_states_equal_twin_joints(world):
    client, _ = world
    client.pause()
    (message,) = _echo(world, "/rig/joint_states", 1)
    joints = {j["name"]: j for j in json.loads(twin(world, "joints", "rig", "--json").stdout)}
    state = message["message"]
    assert sorted(state["name"]) == sorted(joints), (state["name"], list(joints))
    assert abs(joints["spin"]["velocity"]) > 0.1, "the commanded wheel turns"
    for i, name in enumerate(state["name"]):
        for field in ("position", "velocity", "effort"):
            assert state[field][i] == pytest.approx(joints[name][field], abs=1e-12), (name, field)


def _compose(a: tuple, b: tuple) -> tuple:
    """Poses (position, quaternion x y z w): a ∘ b."""
    (pa, qa), (pb, qb) = a, b
    return pa + _rotate(qa, pb), _multiply(qa, qb)


def _rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    u, w = q[:3], q[3]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def _multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    (ax, ay, az, aw), (bx, by, bz, bw) = a, b
    return np.array([
        aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz,
    ])  # fmt: skip


def _world_poses(transforms: list[dict]) -> dict[str, tuple]:
    """Each frame's world pose, composing tf's parent → child transforms from `world`."""
    edges = {t["child_frame_id"]: t for t in transforms}
    poses = {"world": (np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0]))}

    def pose(frame: str) -> tuple:
        if frame not in poses:
            t = edges[frame]
            tr, rot = t["transform"]["translation"], t["transform"]["rotation"]
            local = (np.array([tr[k] for k in "xyz"]), np.array([rot[k] for k in "xyzw"]))
            poses[frame] = _compose(pose(t["header"]["frame_id"]), local)
        return poses[frame]

    for frame in edges:
        pose(frame)
    return poses


def test_tf_composes_to_the_link_poses_twin_model_reports(world):
    client, _ = world
    client.pause()
    (tf,) = _echo(world, "/tf", 1)
    (static,) = _echo(world, "/tf_static", 1)
    poses = _world_poses(tf["message"]["transforms"] + static["message"]["transforms"])
    for entity, root in (("humanoid", "torso"), ("box", "base"), ("bot", "base")):
        model = json.loads(twin(world, "model", entity, "--json").stdout)
        links = {link["name"]: link for link in model["links"]}
        assert root in links, f"{entity}: links {sorted(links)}"
        pose = json.loads(twin(world, "pose", entity, "--json").stdout)
        for key in ("x", "y", "z", "roll", "pitch", "yaw"):
            assert links[root]["pose"][key] == pytest.approx(pose[key], abs=1e-6), (entity, key)
        for name, link in links.items():
            position, quat = poses[link["frame"]]
            reported = link["pose"]
            assert np.allclose(position, [reported[k] for k in "xyz"], atol=1e-9), (entity, name)
            same = min(np.abs(quat - reported["quat"]).max(), np.abs(quat + reported["quat"]).max())
            assert same < 1e-9, f"{entity} link {name}: tf {quat} vs model {reported['quat']}"


def test_model_shows_joints_modes_drives_and_sensors(world):
    client, _ = world
    client.resume()  # a sensor's messages come as the world steps
    rig = json.loads(twin(world, "model", "rig", "--json").stdout)
    joints = {j["name"]: j for j in rig["joints"]}
    assert joints["spin"]["type"] == "hinge" and joints["spin"]["mode"] == "velocity"
    assert sorted(joints["spin"]["modes"]) == ["effort", "velocity"], joints["spin"]
    assert joints["slide"]["type"] == "slide" and joints["slide"]["limits"] == [-0.2, 0.3]
    box = json.loads(twin(world, "model", "box", "--json").stdout)
    (imu,) = box["sensors"]
    assert (imu["ros_topic"], imu["ros_type"]) == ("/box/imu", "sensor_msgs/msg/Imu"), imu
    assert imu["tf_frame"] in {f["name"] for f in box["frames"]}, "the sensor's frame is listed"
    (message,) = _echo(world, "/box/imu", 1)
    assert message["message"]["header"]["frame_id"] == imu["tf_frame"], "echo names that frame"
    bot = json.loads(twin(world, "model", "bot", "--json").stdout)
    (drive,) = bot["drives"]
    assert drive["kind"] == "DiffDrive" and drive["left_joints"] == ["lj"], drive
    assert "bot/odo" in {f["name"] for f in bot["frames"]}, "the drive's odometry frame"
    text = twin(world, "model", "rig").stdout
    assert all(w in text for w in ("spin", "velocity", "slide", "/rig/joint_states")), text


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["topics", "echo", "/rig/joint_state"], ["/rig/joint_state]", "/rig/joint_states"]),
        (["model", "nobody"], ["[nobody]", "humanoid", "twin list"]),
        (["topics", "echo", "/box/imu", "--rate", "5"], ["/box/imu", "leave out --rate"]),
        (["topics", "echo", "/clock", "--rate", "0"], ["/clock", "0 Hz is not in (0, 1000]"]),
        (["topics", "echo", "/clock", "--rate", "nan"], ["/clock", "nan Hz"]),
    ],
)
def test_bad_names_exit_2_with_one_message_naming_them(world, args, words):
    done = twin(world, *args, check=False)
    assert done.returncode == 2, f"exit {done.returncode}: {done.stderr}"
    assert all(w in done.stderr for w in words) and "Traceback" not in done.stderr, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1, f"one message: {done.stderr!r}"


def test_echo_prints_text_and_ends_cleanly_on_ctrl_c_and_a_closed_pipe(world):
    client, runtime_dir = world
    client.resume()
    text = twin(world, "topics", "echo", "/clock", "-n", "2").stdout
    assert text.count("\n---\n") == 2 and "clock:\n  sec:" in text, text
    env = {**os.environ, "TWIN_RUNTIME_DIR": str(runtime_dir)}
    command = [sys.executable, "-m", "twin_cli.cli.app", "topics", "echo", "/tf", "--world", WORLD]
    read, write = os.pipe()
    os.close(read)  # the reader is gone before the first message
    try:
        piped = subprocess.run(command, env=env, stdout=write, stderr=subprocess.PIPE, timeout=60)
    finally:
        os.close(write)
    assert piped.returncode == 0 and not piped.stderr, (
        f"closed pipe: {piped.returncode} {piped.stderr}"
    )
    proc = subprocess.Popen(
        [sys.executable, "-m", "twin_cli.cli.app", "topics", "echo", "/clock", "--world", WORLD],
        env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    assert proc.stdout is not None and proc.stdout.readline(), "a first message"
    proc.send_signal(signal.SIGINT)
    try:
        _, err = proc.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        state = signal_state(proc.pid)  # what it was doing, before the kill below ends it
        proc.kill()
        proc.communicate()
        pytest.fail(f"`twin topics echo` still running 30 s after Ctrl-C: {state}")
    assert proc.returncode == 0 and "Traceback" not in err, f"Ctrl-C: {proc.returncode} {err}"


@pytest.mark.parametrize("gl", ["egl", "glfw"])
def test_a_camera_echoes_its_image_or_ends_naming_why_it_cannot(tmp_path, serve_world, gl):
    """With offscreen GL the image comes cut to 128 bytes of data; without (a desktop backend
    and no display) the echo ends at once, exit 2, naming the sensor and the fix."""
    from camera_models import POST

    patch = pytest.MonkeyPatch()
    patch.setenv("MUJOCO_GL", gl)
    patch.delenv("DISPLAY", raising=False)
    patch.delenv("WAYLAND_DISPLAY", raising=False)
    try:
        with serve_world(tmp_path, WORLD) as (client, _):
            (tmp_path / "post.urdf").write_text(POST)
            client.spawn(str(tmp_path / "post.urdf"), name="post")
            done = twin((client, tmp_path), "topics", "echo", "/post/cam/image_raw", "-n", "1",
                        "--json", check=False)  # fmt: skip
    finally:
        patch.undo()
    if gl == "glfw":
        assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
        assert "sensor 'cam'" in done.stderr and "MUJOCO_GL=egl" in done.stderr, done.stderr
        return
    assert done.returncode == 0, done.stderr
    image = json.loads(done.stdout)["message"]
    assert (image["encoding"], image["step"]) == ("rgb8", 3 * image["width"]), image
    assert len(image["data"]) == 129 and image["data"][-1] == "...", "128 bytes, then ..."
