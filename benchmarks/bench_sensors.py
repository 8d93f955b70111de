"""Sensor figures in one run: what a 10 Hz 360-ray lidar and a 200 Hz IMU cost the loop (issue 14).

The worst case is measured: every reading is taken at its rate in sim time (as a recorder
would), so the world steps in 5-step batches (the IMU's period at 1 ms) and reads the IMU after
each and the lidar after every twentieth; the plain loop steps the same sim time in 500-step
batches with MuJoCo's sensors disabled (`mjDSBL_SENSOR`: the per-step cost of the IMU's native
sensors is counted against the sensors). Both windows of a pair start from the same saved state,
so they step the identical trajectory (readings never act on physics): a window's cost varies
by ±30 % along a trajectory, which earlier unpaired windows mixed into the ratio. Target:
throughput with sensors ≥ 0.90 of the plain loop (median of pairs on one world: the bundled
humanoid lying on the ground, a sensor post and a wall), in CPU time of the stepping thread.
Four ways of reading: `sensors` (the Python loop above, `SensorSuite.read`), `observed`
(`SensorSuite.read` from world observers at the rates, 500-step batches), `streamed` (a
`SensorStream`: observers copy, readings are built per batch) and `recorded` (as recordings
and the Foxglove stream take them: observers copy, another thread builds; also in wall
time). Per-read costs are printed too.
"""

from __future__ import annotations

import os
import queue
import statistics
import tempfile
import threading
import time
from pathlib import Path

import mujoco
import numpy as np

from twin_cli.record.sensor_feed import SensorFeed
from twin_cli.sensors import SensorStream, SensorSuite
from twin_cli.sensors.snapshot import STATE
from twin_cli.world import Pose, World

HUMANOID = Path(__file__).parents[1] / "scenarios" / "robots" / "humanoid.urdf.xacro"
STEPS = 2000  # per window: 2 s of sim time
IMU_EVERY, LIDAR_EVERY = 5, 100  # steps at 1 ms: 200 Hz and 10 Hz
PAIRS = 7
# Windows are timed in CPU time of the stepping thread (observers and drains run in it too):
# on a shared machine (load ≫ cores) wall time measures the neighbours, ±40 % between pairs.
clock = time.thread_time
TARGETS = {
    "sensors_vs_plain": 0.90,
    "observed_vs_plain": 0.90,
    "streamed_vs_plain": 0.90,
    "recorded_vs_plain": 0.90,
}
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


def _plain(world: World) -> float:
    start = clock()
    for _ in range(STEPS // 500):
        world.step(500)
    return STEPS / (clock() - start)


def _plain_both(world: World) -> tuple[float, float]:
    """`_plain` in the stepping thread's CPU time and in wall time."""
    wall, start = time.perf_counter(), clock()
    for _ in range(STEPS // 500):
        world.step(500)
    return STEPS / (clock() - start), STEPS / (time.perf_counter() - wall)


def _with_sensors(world: World, suite: SensorSuite) -> float:
    suite.forget()  # the same readings are due in every window (same sim times)
    start = clock()
    for k in range(STEPS // IMU_EVERY):
        world.step(IMU_EVERY)
        due = ["imu", "lidar"] if (k * IMU_EVERY) % LIDAR_EVERY == 0 else ["imu"]
        suite.read(due)
    return STEPS / (clock() - start)


def _observed(world: World, suite: SensorSuite) -> float:
    """Steps as a running world does (500-step batches), the readings taken by observers at
    the sensors' rates in sim time (as the recorder takes its samples): no Python step loop."""
    suite.forget()
    handles = [
        world.add_observer(lambda: suite.read(["imu"]), 1000.0 / IMU_EVERY),
        world.add_observer(lambda: suite.read(["lidar"]), 1000.0 / LIDAR_EVERY),
    ]
    start = clock()
    for _ in range(STEPS // 500):
        world.step(500)
    elapsed = clock() - start
    for handle in handles:
        world.remove_observer(handle)
    return STEPS / elapsed


def _streamed(world: World, suite: SensorSuite) -> float:
    """As `_observed`, through a `SensorStream`: the observers only copy (sensordata, or the
    state for the lidar), and every reading is built when drained after each batch (counted)."""
    stream = SensorStream(suite, ["imu", "lidar"])
    start = clock()
    count = 0
    for _ in range(STEPS // 500):
        world.step(500)
        count += len(stream.drain())
    elapsed = clock() - start
    stream.close()
    expected = STEPS // IMU_EVERY + STEPS // LIDAR_EVERY
    if count != expected:
        raise RuntimeError(f"stream drained {count} readings, expected {expected}")
    return STEPS / elapsed


def _recorded(world: World) -> tuple[float, float]:
    """As a recording takes them (`twin_cli.record.sensor_feed`): observers at the sensors'
    rates only copy (`SensorFeed.capture`), a consumer thread builds the readings (rays cast
    there). Steps/s in the stepping thread's CPU time, and in wall time (the consumer runs on
    the other core meanwhile); every reading is built before the window ends."""
    feed = SensorFeed(world, ["post"])
    captured: queue.SimpleQueue = queue.SimpleQueue()
    built = []

    def consume() -> None:
        while (item := captured.get()) is not None:
            built.extend(feed.build(item))

    consumer = threading.Thread(target=consume)
    consumer.start()
    handles = [
        world.add_observer(lambda rate=rate: captured.put(feed.capture(rate)), rate)
        for rate in feed.rates()
    ]
    wall, start = time.perf_counter(), clock()
    for _ in range(STEPS // 500):
        world.step(500)
    cpu = clock() - start
    for handle in handles:
        world.remove_observer(handle)
    captured.put(None)
    consumer.join()
    wall = time.perf_counter() - wall
    expected = STEPS // IMU_EVERY + STEPS // LIDAR_EVERY
    if len(built) != expected:
        raise RuntimeError(f"built {len(built)} readings, expected {expected}")
    return STEPS / cpu, STEPS / wall


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
    ratios, observed, streamed, plain, sensed = [], [], [], [], []
    recorded, recorded_wall = [], []
    for _ in range(PAIRS):
        _restore(world, start, sensors=False)
        p, p_wall = _plain_both(world)
        _restore(world, start, sensors=True)
        r, r_wall = _recorded(world)
        recorded.append(r / p)
        recorded_wall.append(r_wall / p_wall)
        _restore(world, start, sensors=False)
        p = _plain(world)
        _restore(world, start, sensors=True)
        s = _with_sensors(world, suite)
        _restore(world, start, sensors=True)
        o = _observed(world, suite)
        _restore(world, start, sensors=True)
        streamed.append(_streamed(world, suite) / p)
        plain.append(p)
        sensed.append(s)
        ratios.append(s / p)
        observed.append(o / p)
    return {
        "sensors_vs_plain_median": statistics.median(ratios),
        "ratios": [round(x, 3) for x in ratios],
        "observed_vs_plain_median": statistics.median(observed),
        "observed_ratios": [round(x, 3) for x in observed],
        "recorded_vs_plain_median": statistics.median(recorded),
        "recorded_ratios": [round(x, 3) for x in recorded],
        "recorded_wall_vs_plain_median": statistics.median(recorded_wall),
        "recorded_wall_ratios": [round(x, 3) for x in recorded_wall],
        "streamed_vs_plain_median": statistics.median(streamed),
        "streamed_ratios": [round(x, 3) for x in streamed],
        "plain_steps_per_s": statistics.median(plain),
        "sensors_steps_per_s": statistics.median(sensed),
        "imu_read_us": _read_cost(world, suite, "imu", 200),
        "lidar_360_read_us": _read_cost(world, suite, "lidar", 50),
    }


def run() -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        return {
            "load_average": os.getloadavg()[0],
            "throughput": throughput(Path(tmp)),
            "targets": TARGETS,
        }
