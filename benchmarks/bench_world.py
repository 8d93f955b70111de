"""World engine figures in one run: loop vs raw mj_step, real-time factor, spawn latency, scaling.

Targets: the unthrottled loop keeps ≥ 0.95 of raw `mj_step`
throughput on the same model, options and state while a stats reader polls, and ≥ 0.97 without
one (identical steps compared, see `benchmarks.throughput`); real-time factor 1.00 ± 0.01 over
10 s; spawn latency and steps/s against the number of humanoids are recorded. Ratios hold on any
machine; absolute figures depend on the load (the load average is recorded with them).
"""

from __future__ import annotations

import os
import statistics
import tempfile
import threading
import time
from pathlib import Path

import mujoco

from benchmarks.throughput import Window, raw_profile
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import savefile

RAW_SECONDS = 2.0  # [s] per throughput measurement
LOOP_WARMUP_S = 0.3  # [s] before a loop window: the batch size settles
LOOP_WINDOW_S = 0.5  # [s] per loop window (each paired with raw over the same steps)
LOOP_PAIRS = 9  # loop/raw pairs per case; the median is reported
RATIO_TARGETS = {"no_reader": 0.97, "stats_reader": 0.95}
STATS_POLL_S = 0.2  # [s] a `twin stats` client polls at gz stats' 5 Hz
REALTIME_SECONDS = 10.0  # [s] the window the 1.00 ± 0.01 real-time target is judged over
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
            SpawnRequest(spec, on_ground=True),
            name=name,
            pose=Pose(x=1.5 * (k % side), y=1.5 * (k // side)),
        )
        for joint in world.joint_states(name):
            world.command(name, joint.name, mode="position", value=0.0)
    return world


def _loop_thread() -> threading.Thread:
    return next(t for t in threading.enumerate() if t.name == "twin-world-loop")


def _loop_window(world, reader: bool) -> tuple[Window, float]:  # noqa: ANN001
    """Steps, wall and stepping-thread CPU time of the unthrottled loop over LOOP_WINDOW_S, and
    the share of that wall time spent inside mj_step (`World.stepping_time`).

    Args:
        world: a stopped world, as loaded from the saved state.
        reader: whether a thread polls `world.stats()` like a `twin stats` client.
    """
    stop = threading.Event()

    def poll() -> None:
        while not stop.wait(STATS_POLL_S):
            world.stats()

    poller = threading.Thread(target=poll, daemon=True)
    origin = world.stats().iterations
    if reader:
        poller.start()
    world.start()
    clock = time.pthread_getcpuclockid(_loop_thread().ident)
    time.sleep(LOOP_WARMUP_S)
    it0, wall0, cpu0 = world.stats().iterations, time.perf_counter(), time.clock_gettime(clock)
    in_step0 = world.stepping_time
    time.sleep(LOOP_WINDOW_S)
    it1, wall1, cpu1 = world.stats().iterations, time.perf_counter(), time.clock_gettime(clock)
    in_step1 = world.stepping_time
    world.stop()
    stop.set()
    if reader:
        poller.join()
    window = Window(it0 - origin, it1 - origin, wall1 - wall0, cpu1 - cpu0)
    return window, (in_step1 - in_step0) / window.wall_s


def _paired_ratios(saved: Path, reader: bool) -> dict[str, float]:
    """One loop window, then raw mj_step over the same steps from the same saved state."""

    window, in_mj_step = _loop_window(savefile.load(saved), reader)
    fresh = savefile.load(saved)
    ratios = window.ratios([raw_profile(fresh.model, fresh.data, window.last)])
    return {**ratios, "in_mj_step_share": in_mj_step}


def loop_vs_raw(spec: mujoco.MjSpec) -> dict:
    """Unthrottled loop, without and with a stats reader, vs raw mj_step on the same steps.

    Every loop window and raw run starts from one saved world (the standing humanoid holding
    its posture), so all of them step the same trajectory. On a shared 2-core machine the same
    raw run swings 40k-53k steps/s from one second to the next, so loop and raw are measured in
    adjacent pairs, LOOP_PAIRS times per case, and the median pair is reported with the range.
    The share of the loop's wall time spent inside mj_step, measured in the same window on the
    same steps, is immune to that swing; the targets are judged on it, the pairs corroborate.
    """
    with tempfile.TemporaryDirectory(prefix="twin-bench-") as tmp:
        saved = Path(tmp) / "standing.twin"
        savefile.save(_standing_world(spec), saved)
        pairs: dict[str, list[dict[str, float]]] = {case: [] for case in RATIO_TARGETS}
        for k in range(LOOP_PAIRS):
            for case in sorted(RATIO_TARGETS, reverse=k % 2 == 1):  # alternate which goes first
                pairs[case].append(_paired_ratios(saved, case == "stats_reader"))
    out: dict = {}
    for case, target in RATIO_TARGETS.items():
        cpu = [p["loop_over_raw_cpu"] for p in pairs[case]]
        wall = [p["loop_over_raw_wall"] for p in pairs[case]]
        share = statistics.median(p["in_mj_step_share"] for p in pairs[case])
        out[case] = {
            "in_mj_step_share": share,
            "loop_over_raw_cpu": statistics.median(cpu),
            "loop_over_raw_wall": statistics.median(wall),
            "cpu_range": [min(cpu), max(cpu)],
            "target": target,
            "ok": share >= target,
        }
    return out


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
