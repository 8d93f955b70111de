"""World engine figures in one run: loop vs raw mj_step, real-time factor, spawn latency, scaling.

Targets (design.md §5, issue 4): unthrottled loop ≥ 0.95 of raw `mj_step` steps/s on the same
model while a stats reader polls; real-time factor 1.00 ± 0.01 over 10 s; spawn latency and
steps/s against the number of humanoids are recorded. Ratios hold on any machine; absolute
figures depend on the load (the load average is recorded with them).
"""

from __future__ import annotations

import os
import statistics
import threading
import time

import mujoco

RAW_SECONDS = 2.0  # [s] per throughput measurement
REALTIME_SECONDS = 10.0  # [s] real-time window (issue 4)
SPAWN_COUNTS = (1, 10, 50)
ROBOT_COUNTS = (1, 2, 4, 8, 16, 32, 64)
SCALING_SECONDS = 0.5  # [s] per robot count


def _humanoid() -> mujoco.MjSpec:
    from converters.pipeline import convert
    from scenarios import HUMANOID

    spec, _ = convert(HUMANOID)
    return spec


def _standing_world(spec: mujoco.MjSpec, robots: int = 1, rate: float = 0.0):  # noqa: ANN202
    from twin_cli.world import Pose, World, WorldSettings

    world = World(WorldSettings(rate=rate))
    side = max(1, round(robots**0.5))
    for k in range(robots):
        name = f"h{k}"
        world.spawn(
            spec, name=name, pose=Pose(x=1.5 * (k % side), y=1.5 * (k // side)), on_ground=True
        )
        for joint in world.joint_states(name):
            world.command(name, joint.name, mode="position", value=0.0)
    return world


def _raw_steps_per_second(model: mujoco.MjModel, data: mujoco.MjData) -> float:
    steps, start = 0, time.perf_counter()
    while time.perf_counter() - start < RAW_SECONDS:
        mujoco.mj_step(model, data, nstep=100)
        steps += 100
    return steps / (time.perf_counter() - start)


def _loop_steps_per_second(world) -> float:  # noqa: ANN001
    stop = threading.Event()

    def reader() -> None:  # a `twin stats` client polling at gz stats' 5 Hz
        while not stop.wait(0.2):
            world.stats()

    poller = threading.Thread(target=reader, daemon=True)
    poller.start()
    world.start()
    time.sleep(0.3)  # batch size settles
    start_iter, start = world.stats().iterations, time.perf_counter()
    time.sleep(RAW_SECONDS)
    steps = world.stats().iterations - start_iter
    elapsed = time.perf_counter() - start
    world.stop()
    stop.set()
    poller.join()
    return steps / elapsed


def loop_vs_raw(spec: mujoco.MjSpec) -> dict:
    """Unthrottled loop vs raw mj_step(nstep=100) on the same compiled model and state."""
    world = _standing_world(spec)
    data = mujoco.MjData(world.model)
    data.qpos[:] = world.data.qpos
    raw = _raw_steps_per_second(world.model, data)
    loop = _loop_steps_per_second(world)
    return {"raw_steps_per_s": round(raw), "loop_steps_per_s": round(loop), "ratio": loop / raw}


def realtime(spec: mujoco.MjSpec) -> dict:
    """Real-time mode at 1000 Hz: gz-stats factor, sim/wall over the window, lateness."""
    world = _standing_world(spec, rate=1000.0)
    world.start()
    time.sleep(REALTIME_SECONDS)
    with world.lock:
        fig, stats = world.loop_figures(), world.stats()
    world.stop()
    return {
        "window_s": REALTIME_SECONDS,
        "gz_stats_factor": fig.factor,
        "sim_over_wall": stats.sim_time / fig.real_time,
        "lateness_mean_ms": fig.lateness.mean * 1e3,
        "lateness_worst_ms": fig.lateness.worst * 1e3,
        "batches_late_over_1_step": fig.lateness.over_period,
        "batches": fig.lateness.count,
        "dropped_steps": fig.dropped,
    }


def spawn_latency(spec: mujoco.MjSpec) -> dict:
    """Wall time of one humanoid spawn (MjSpec source: no conversion) into N-entity worlds."""
    from twin_cli.world import Pose, World

    out = {}
    for count in SPAWN_COUNTS:
        world = World()
        for k in range(count):
            world.spawn(spec, name=f"h{k}", pose=Pose(x=1.5 * k, z=0.95))
        samples = []
        for trial in range(5):
            start = time.perf_counter()
            world.spawn(spec, name=f"new{trial}", pose=Pose(y=3.0 + 1.5 * trial, z=0.95))
            samples.append(time.perf_counter() - start)
            world.delete(f"new{trial}")
        out[f"{count}_entities_ms"] = statistics.median(samples) * 1e3
    return out


def scaling(spec: mujoco.MjSpec) -> dict:
    """Steps/s (World.step, standing humanoids holding posture) against the number of robots."""
    out = {}
    for robots in ROBOT_COUNTS:
        world = _standing_world(spec, robots)
        world.step(50)
        steps, start = 0, time.perf_counter()
        while time.perf_counter() - start < SCALING_SECONDS:
            world.step(20)
            steps += 20
        out[str(robots)] = round(steps / (time.perf_counter() - start))
    return out


def run() -> dict:
    spec = _humanoid()
    return {
        "load_average_1min": os.getloadavg()[0],
        "cpus": os.cpu_count(),
        "loop_vs_raw": loop_vs_raw(spec),
        "realtime": realtime(spec),
        "spawn_latency": spawn_latency(spec),
        "steps_per_s_vs_robots": scaling(spec),
    }
