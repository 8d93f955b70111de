"""Sensor figures in one run: what a 10 Hz 360-ray lidar and a 200 Hz IMU cost the loop.

Every reading is taken at its rate in sim time, as a recording takes them, on one world: the
bundled humanoid lying on the ground, a sensor post and a wall. Arms, each a 200-step window
(two lidar scans, forty IMU samples) started from the same saved state, so every window steps
the identical trajectory (readings never act on physics):
- `plain`: 200 steps with MuJoCo's sensors disabled (`mjDSBL_SENSOR`: the per-step cost of the
  IMU's native sensors is counted against the sensors);
- `observed`: `SensorSuite.read` from world observers at the sensors' rates (every reading
  built in the stepping thread);
- `recorded`: as recordings and the Foxglove stream take them (`SensorFeed`, `SensorPump`):
  the lidar's observer copies the state at 10 Hz; the IMU's samples are kept by MuJoCo
  (`twin_cli.sensors.history`) and copied in batches by an observer at 4 Hz; the pump's
  thread builds the readings (rays cast there) while the loop steps, and finishes them, untimed,
  before the next window.
Ratios come from 100 finely interleaved plain/variant pairs (benchmarks/paired.py: single
windows of this VM swing 0.5-1.3), in the stepping thread's CPU time (what the readings add
to the loop) and in wall time (which also counts the consumer thread's GIL and core). Target:
≥ 0.90 of the plain loop. Per-read costs are printed too.
"""

from __future__ import annotations

import os
import statistics
import tempfile
import time
from pathlib import Path

import mujoco
import numpy as np

from benchmarks.paired import interleaved_ratio
from twin_cli.record.sensor_feed import KEPT, SensorFeed
from twin_cli.record.sensor_pump import SensorPump
from twin_cli.sensors import SensorSuite
from twin_cli.sensors.snapshot import STATE
from twin_cli.world import Pose, World

HUMANOID = Path(__file__).parents[1] / "scenarios" / "robots" / "humanoid.urdf.xacro"
WINDOW = 200  # [steps] per arm: 0.2 s of sim time
IMU_EVERY, LIDAR_EVERY = 5, 100  # steps at 1 ms: 200 Hz and 10 Hz
PAIRS = 100  # interleaved windows per ratio
clock = time.thread_time  # the stepping thread's CPU (observers run in it)
TARGETS = {"observed_vs_plain": 0.90, "recorded_vs_plain": 0.90}
SENSOR_POST = """<robot name="post">
  <link name="base"><inertial><mass value="2"/><inertia ixx="0.01" iyy="0.01" izz="0.01"
    ixy="0" ixz="0" iyz="0"/></inertial><collision><origin xyz="0 0 0.1"/>
    <geometry><cylinder radius="0.05" length="0.2"/></geometry></collision></link>
  <gazebo><static>true</static></gazebo>
  <gazebo reference="base">
    <sensor type="ray" name="lidar"><pose>0 0 0.3 0 0 0</pose><update_rate>10</update_rate>
      <ray><scan><horizontal><samples>360</samples><min_angle>-3.14159</min_angle>
      <max_angle>3.14159</max_angle></horizontal></scan><range><min>0.12</min><max>10</max></range>
      <noise><type>gaussian</type><mean>0</mean><stddev>0.01</stddev></noise></ray></sensor>
    <sensor type="imu" name="imu"><update_rate>200</update_rate><imu><angular_velocity><x>
      <noise type="gaussian"><stddev>2e-4</stddev></noise></x></angular_velocity></imu></sensor>
  </gazebo>
</robot>"""


def _world(tmp: Path) -> World:
    world = World()
    world.spawn(HUMANOID, name="h", pose=Pose(z=1.0))
    post = tmp / "post.urdf"
    post.write_text(SENSOR_POST)
    world.spawn(post, name="post", pose=Pose(x=-2.0))
    wall = mujoco.MjSpec()
    wall.modelname = "wall"
    wall.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.05, 3, 1], pos=[0, 0, 1])
    world.spawn(wall, name="wall", pose=Pose(x=-4.0))
    return world


def _restore(world: World, state: np.ndarray, *, sensors: bool) -> None:
    """The world back at `state`, its MuJoCo sensors on or off."""
    with world.lock:
        mujoco.mj_setState(world.model, world.data, state, STATE)
        flag = int(mujoco.mjtDisableBit.mjDSBL_SENSOR)
        if sensors:
            world.model.opt.disableflags &= ~flag
        else:
            world.model.opt.disableflags |= flag


class _Arms:
    """The benchmark's arms on one world, each a WINDOW-step call from the same state."""

    def __init__(self, world: World, suite: SensorSuite, state: np.ndarray) -> None:
        self.world, self.suite, self.state = world, suite, state
        self.feed = SensorFeed(world, ["post"])
        self.rates = self.feed.rates()
        self.built = self.windows = self.settles = 0
        self.pump = SensorPump(self._count).start()

    def plain(self) -> None:
        _restore(self.world, self.state, sensors=False)
        self.world.step(WINDOW)

    def observed(self) -> None:
        _restore(self.world, self.state, sensors=True)
        self.suite.forget()  # the same readings are due in every window (same sim times)
        world, suite = self.world, self.suite
        handles = [
            world.add_observer(lambda: suite.read(["imu"]), 1000.0 / IMU_EVERY),
            world.add_observer(lambda: suite.read(["lidar"]), 1000.0 / LIDAR_EVERY),
        ]
        world.step(WINDOW)
        for handle in handles:
            world.remove_observer(handle)

    def recorded(self) -> None:
        """One window of a running recording's sensor path (its start and its end, which a
        recording has once, are in `settle`)."""
        _restore(self.world, self.state, sensors=True)
        world, feed, pump = self.world, self.feed, self.pump
        self.windows += 1
        handles = [
            world.add_observer(lambda rate=rate: pump.capture(feed, rate), rate)
            for rate in self.rates
        ]
        world.step(WINDOW)
        for handle in handles:
            world.remove_observer(handle)

    def settle(self) -> None:
        """Untimed, after a recorded window: the samples kept since the last look are taken
        (as a recording's end does), the pump finishes every reading, and the next window
        starts as a recording would (every sensor due, kept samples new from its start on)."""
        world, feed = self.world, self.feed
        self.settles += 1
        with world.lock:
            self.pump.capture(feed, KEPT)
        self.pump.flush()
        for suite in feed._suites.values():
            suite.forget()
        start = float(self.state[0])  # mjSTATE_TIME comes first
        feed._last = {key: start - 1e-9 for key in feed._last}
        with world.lock:
            mujoco.mj_setState(world.model, world.data, self.state, STATE)
            self.pump.capture(feed)  # the lidar's reading at the start
        self.pump.flush()

    def _count(self, readings: list) -> None:
        self.built += len(readings)


def _read_cost(world: World, suite: SensorSuite, name: str, n: int) -> float:
    """Median CPU time [µs] of a fresh reading of `name` (one step between reads)."""
    costs = []
    for _ in range(n):
        world.step(LIDAR_EVERY if name == "lidar" else IMU_EVERY)
        start = clock()
        suite.read([name])
        costs.append(clock() - start)
    return statistics.median(costs) * 1e6


def throughput(tmp: Path) -> dict:
    world = _world(tmp)
    world.step(2000)  # the humanoid lies on the ground: the same contacts in every window
    suite = SensorSuite(world, "post")
    with world.lock:
        start = np.empty(mujoco.mj_stateSize(world.model, STATE))
        mujoco.mj_getState(world.model, world.data, start, STATE)
    arms = _Arms(world, suite, start)
    arms.settle()  # a recording's start
    out = {}
    for name, arm in (("observed", arms.observed), ("recorded", arms.recorded)):
        settle = arms.settle if name == "recorded" else None
        out[f"{name}_vs_plain"] = interleaved_ratio(
            arms.plain, arm, pairs=PAIRS, clock=clock, settle=settle
        )
        out[f"{name}_wall_vs_plain"] = interleaved_ratio(
            arms.plain, arm, pairs=PAIRS, settle=settle
        )
    # Every reading of every recorded window, and the lidar's at each (settled) start.
    expected = arms.windows * (WINDOW // IMU_EVERY + WINDOW // LIDAR_EVERY) + arms.settles
    if arms.built != expected:
        raise RuntimeError(f"built {arms.built} readings, expected {expected}")
    plain_s = time.perf_counter()
    for _ in range(10):
        arms.plain()
    out["plain_steps_per_s"] = 10 * WINDOW / (time.perf_counter() - plain_s)
    out["imu_read_us"] = _read_cost(world, suite, "imu", 200)
    out["lidar_360_read_us"] = _read_cost(world, suite, "lidar", 50)
    return out


def run() -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        return {
            "load_average": os.getloadavg()[0],
            "throughput": throughput(Path(tmp)),
            "targets": TARGETS,
        }
