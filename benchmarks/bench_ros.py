"""ROS 2 bridge figures in one run: what publishing the world on DDS costs the stepping loop.

A humanoid with an IMU (100 Hz) and a 360-ray lidar (10 Hz) on its IMU link, published at 100 Hz
of sim time (/clock, /tf, joint_states, odom; the sensors at their rates) over loopback DDS in a
domain of its own, with a subscriber in another process taking the state topics (the tests' peer
in its `drain` mode: every message received, none decoded).

- `ros_vs_plain`: the unthrottled loop's throughput with the bridge's sampling over without,
  alternating every WINDOW steps on one world and one running bridge (benchmarks/paired.py;
  `set_sampling`). Unthrottled, the world runs ~15x real time, so the bridge observes every
  k-th sample of its 100 Hz grid (`live_recording.stride`, k from the world's speed) and
  publishes at most WALL_SPEEDUP × RATE samples per wall second. Target ≥ 0.95.
  `thread_vs_plain`: the same for the bridge's former design, measured in the same run: the
  messages built and published by a worker thread of the server (`Recording` with the
  participant as its sink) instead of the publisher process. `publisher_ms_per_sample`: the
  publisher process's CPU per published sample (/proc); `server_threads_ms_per_sample`: the
  CPU of the server's threads other than the stepping one (the interpreter's work beside the
  loop: sensor readings, command polling, and in the former design the messages) per sample;
  `subscriber_ms_per_sample`: the subscriber's (it takes the state topics' bytes and decodes
  none, as a compiled node's receiving costs; the tests' peer decodes each message twice in
  Python, ~1 ms a sample, which on two vCPUs would weigh more than the bridge itself).
- `realtime`: the real-time factor over 10 s at 1 kHz with the bridge publishing. Target 1.00.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from benchmarks.paired import interleaved_ratio
from twin_cli.live.budget import WALL_SPEEDUP
from twin_cli.record.recorder import Recording
from twin_cli.ros import RosBridge, scope_from
from twin_cli.ros.participant import Participant
from twin_cli.world import Pose, World, WorldSettings

ROBOTS = Path(__file__).parents[1] / "scenarios" / "robots"
PEER = Path(__file__).parents[1] / "tests" / "twin_cli" / "ros" / "ros_peer.py"
DOMAIN_ID = "231"  # a domain of the benchmark's own
RATE = 100.0  # [Hz] of sim time
WINDOW = 2000  # [steps] per arm
ROLL = 1000  # [steps] sampled, untimed, before a sampled arm: the worker in its steady state
PAIRS = 60
REALTIME_SECONDS = 10.0  # [s]
TARGETS = {"ros_vs_plain": 0.95, "realtime_factor": (0.99, 1.01)}
SENSORS = """
  <gazebo reference="imu_link"><sensor type="imu" name="imu"><always_on>true</always_on>
    <update_rate>100</update_rate><topic>imu</topic></sensor></gazebo>
  <gazebo reference="imu_link"><sensor type="ray" name="lidar"><update_rate>10</update_rate>
    <ray><scan><horizontal><samples>360</samples><resolution>1</resolution>
    <min_angle>-3.14159</min_angle><max_angle>3.14159</max_angle></horizontal></scan>
    <range><min>0.12</min><max>10</max><resolution>0.015</resolution></range></ray>
    <topic>scan</topic></sensor></gazebo>
</robot>"""


def _humanoid_with_sensors(tmp: Path) -> Path:
    """The scenario humanoid with an IMU and a lidar added (its macros copied beside it)."""
    shutil.copy(ROBOTS / "humanoid_macros.xacro", tmp / "humanoid_macros.xacro")
    text = (ROBOTS / "humanoid.urdf.xacro").read_text()
    head, _, _ = text.rpartition("</robot>")
    path = tmp / "humanoid_sensors.urdf.xacro"
    path.write_text(head + SENSORS)
    return path


def _world(robot: Path, rate: float = 0.0) -> World:
    world = World(WorldSettings(rate=rate))
    world.spawn(robot, name="h", pose=Pose(z=1.0))
    world.step(2000)  # settled on the ground: the same contacts in every window
    return world


def throughput(robot: Path) -> dict:
    """The loop's throughput with the bridge's sampling over without, in its process design
    and in the former worker-thread one (see module docstring)."""
    world = _world(robot)
    bridge = RosBridge(world, scope_from({"ROS_DOMAIN_ID": DOMAIN_ID})).start()
    bridge.commands.stop()  # no command comes: its thread only polls
    bridge.services.stop()
    with _subscriber() as peer:
        time.sleep(2.0)  # discovery done before timing
        cpu_before, peer_before = _cpu_s(bridge.recording.encoder_pid), _cpu_s(peer)
        now = _paired(world, bridge.recording)
        cpu = _cpu_s(bridge.recording.encoder_pid) - cpu_before
        peer_cpu = _cpu_s(peer) - peer_before
    bridge.stop()
    thread = Recording(
        world, [Participant(scope_from({"ROS_DOMAIN_ID": DOMAIN_ID}))], rate=RATE,
        latest_only=True, max_wall_rate=WALL_SPEEDUP * RATE,
    ).start()  # fmt: skip
    with _subscriber() as peer:
        time.sleep(2.0)
        peer_before = _cpu_s(peer)
        before = _paired(world, thread)
        thread_peer_cpu = _cpu_s(peer) - peer_before
    thread.stop()
    return {
        "ros_vs_plain": now["wall"],
        "ros_vs_plain_loop_cpu": now["cpu"],
        "published_samples": now["samples"],
        "publisher_ms_per_sample": 1e3 * cpu / max(1, now["samples"]),
        "server_threads_ms_per_sample": 1e3 * now["others_s"] / max(1, now["samples"]),
        "subscriber_ms_per_sample": 1e3 * peer_cpu / max(1, now["samples"]),
        "thread_vs_plain": before["wall"],
        "thread_vs_plain_loop_cpu": before["cpu"],
        "thread_published_samples": before["samples"],
        "thread_server_threads_ms_per_sample": 1e3 * before["others_s"] / max(1, before["samples"]),
        "thread_subscriber_ms_per_sample": 1e3 * thread_peer_cpu / max(1, before["samples"]),
    }


def _paired(world: World, recording: Any) -> dict:
    """Wall and loop-CPU ratios of WINDOW steps with `recording` sampling over without."""

    def plain() -> None:
        world.step(WINDOW)

    def prepare() -> None:  # the worker in its steady state when the sampled window starts
        recording.set_sampling(True)
        world.step(ROLL)

    def sampled() -> None:
        world.step(WINDOW)

    def settle() -> None:  # the worker's last sample built, then the loop hot again, untimed
        recording.set_sampling(False)
        time.sleep(2.0 / (WALL_SPEEDUP * RATE))
        world.step(ROLL)  # a plain arm that followed a sleep ran ~30 % slower (a cold core)

    recording.set_sampling(False)
    before = recording.status().samples
    paired = {"pairs": PAIRS, "prepare": prepare, "settle": settle}
    process, loop = _cpu_s(os.getpid()), time.thread_time()
    wall = interleaved_ratio(plain, sampled, **paired)
    cpu = interleaved_ratio(plain, sampled, clock=time.thread_time, **paired)
    time.sleep(0.1)  # the last samples published
    others = _cpu_s(os.getpid()) - process - (time.thread_time() - loop)
    samples = recording.status().samples - before
    return {"wall": wall, "cpu": cpu, "samples": samples, "others_s": others}


def _cpu_s(pid: int | None) -> float:
    """User + system CPU [s] of process `pid` so far (Linux /proc)."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def realtime(robot: Path) -> dict:
    """Real-time factor over REALTIME_SECONDS at 1 kHz with the bridge publishing."""
    world = _world(robot, rate=1000.0)
    bridge = RosBridge(world, scope_from({"ROS_DOMAIN_ID": DOMAIN_ID})).start()
    with _subscriber():
        world.start()
        time.sleep(REALTIME_SECONDS)
        stats, figures = world.stats(), world.loop_figures()
        world.stop()
    status = bridge.stop()
    return {
        "factor": stats.factor,
        "sim_over_wall": stats.sim_time / stats.real_time,
        "dropped_steps": figures.dropped,
        "published_samples": status["samples"],
    }


class _subscriber:  # noqa: N801 - a context manager used as `with _subscriber():`
    """The tests' ROS peer in another process, taking the state topics of `h`."""

    def __enter__(self) -> int:
        env = {**os.environ, "ROS_DOMAIN_ID": DOMAIN_ID}
        self._proc = subprocess.Popen(
            [sys.executable, str(PEER), "drain", "600", "h"],
            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )  # fmt: skip
        return self._proc.pid

    def __exit__(self, *_: object) -> None:
        self._proc.terminate()
        self._proc.wait(timeout=10)


def run() -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        robot = _humanoid_with_sensors(Path(tmp))
        return {
            "load_average": os.getloadavg()[0],
            "throughput": throughput(robot),
            "realtime": realtime(robot),
            "targets": TARGETS,
        }
