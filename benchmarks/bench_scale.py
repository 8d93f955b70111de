"""Many robots in one world: real-time factor against the robot count with and without
MuJoCo's engine thread pool and sleeping, spawn cost in a full world, and the conversion cache.

Targets: 64 humanoids at a factor ≥ 1.0 in real-time mode; the pool's speed-up ≥ 1.6× at 32
robots on 2 cores; a spawn into a world of 50 entities ≤ 20 ms; the tenth booster_t1 into a world
of nine ≤ 2× the first spawn. Pool and no-pool windows alternate on the same world and state, so
their ratio holds under a shared machine's load; the load average is recorded with them.
"""

from __future__ import annotations

import os
import statistics
import time
from pathlib import Path

from twin_cli.spawn_request import SpawnRequest

ROBOT_COUNTS = (1, 8, 32, 64)
WINDOW_S = 1.0  # [s] wall time per unthrottled window
PAIRS = 3  # alternating pool / no-pool windows per count; the median ratio is reported
REALTIME_S = 4.0  # [s] real-time window for the 64-humanoid goal
SPAWN_WORLD = 50  # entities already in the world for the spawn-latency figure
SPAWN_REPEATS = 5
CORPUS = Path(__file__).resolve().parents[1].parent / "shared" / "corpus"  # as bench_collision
BOOSTER = CORPUS / "packages" / "booster_gym" / "resources" / "T1" / "T1_serial.urdf"
BOOSTERS = 10


def _standing(count: int, rate: float = 0.0):  # noqa: ANN202
    """A world of `count` humanoids on the ground, holding their joints at 0 (position mode)."""
    from scenarios import HUMANOID
    from twin_cli.world import Pose, World, WorldSettings

    world = World(WorldSettings(rate=rate))
    side = max(1, round(count**0.5))
    poses = [Pose(x=1.5 * (k % side), y=1.5 * (k // side), z=1.3) for k in range(count)]
    results = world.spawn_batch(SpawnRequest(HUMANOID, on_ground=True), base="h", poses=poses)
    for r in results:
        for joint in world.joint_states(r.name):
            world.command(r.name, joint.name, mode="position", value=0.0)
    world.step(200)  # settle before measuring
    return world


def _factor(world, seconds: float) -> float:  # noqa: ANN001
    """Sim seconds per wall second of the world's own loop over `seconds`."""
    sim0, wall0 = float(world.data.time), time.perf_counter()
    time.sleep(seconds)
    with world.lock:
        sim1 = float(world.data.time)
    return (sim1 - sim0) / (time.perf_counter() - wall0)


def _unthrottled(count: int, threads: int) -> dict:
    """Factors with the pool off/on (alternating), then with sleeping on, for `count` robots."""
    world = _standing(count)
    world.start()
    try:
        off, on = [], []
        for _ in range(PAIRS):
            world.set_engine(threads=1)
            off.append(_factor(world, WINDOW_S))
            world.set_engine(threads=threads)
            on.append(_factor(world, WINDOW_S))
        world.set_engine(threads=1, sleep=True)
        sleep_off_pool = _factor(world, WINDOW_S)
        world.set_engine(threads=threads)
        sleep_pool = _factor(world, WINDOW_S)
        awake = int(world.data.ntree_awake)
    finally:
        world.stop()
    ratios = [b / a for a, b in zip(off, on, strict=True)]
    return {
        "factor_single": round(statistics.median(off), 2),
        "factor_pool": round(statistics.median(on), 2),
        "pool_speedup": round(statistics.median(ratios), 2),
        "factor_sleep": round(sleep_off_pool, 2),
        "factor_sleep_pool": round(sleep_pool, 2),
        "trees_awake_with_sleep": f"{awake}/{int(world.model.ntree)}",
    }


def _realtime(count: int, threads: int, sleep: bool = False) -> float:
    world = _standing(count, rate=1000.0)
    world.set_engine(threads=threads, sleep=sleep)
    world.start()
    try:
        time.sleep(REALTIME_S)
        return round(world.loop_figures().factor, 3)
    finally:
        world.stop()


def _realtime_sleeping(count: int) -> dict:
    """Real-time factor of `count` standing humanoids with sleeping on, and how many slept.

    Robots on their servos may sleep since twin_cli.world.sleeping; they rest still enough to
    sleep at MuJoCo's default tolerance (1e-3 m/s) within 0.1 s of standing.
    """
    world = _standing(count, rate=1000.0)
    world.set_engine(sleep=True)
    world.start()
    try:
        time.sleep(REALTIME_S)
        with world.lock:
            asleep = int(world.model.ntree) - int(world.data.ntree_awake)
        return {"factor": round(world.loop_figures().factor, 3), "asleep": asleep}
    finally:
        world.stop()


BOX_URDF = """<robot name="box"><link name="base"><inertial><mass value="10"/>
<inertia ixx="0.15" iyy="0.15" izz="0.15" ixy="0" ixz="0" iyz="0"/></inertial>
<visual><geometry><box size="0.3 0.3 0.3"/></geometry></visual>
<collision><geometry><box size="0.3 0.3 0.3"/></geometry></collision></link></robot>"""


def _spawn_latency() -> dict:
    """Median spawn (cached conversion) and delete of a humanoid into a world of SPAWN_WORLD
    humanoids, and into one of SPAWN_WORLD boxes [ms], with MuJoCo's bare compile of the world.

    The compile is most of a spawn, and it grows with the square of the robot count (mj_setConst
    solves with the full mass matrix per body and actuator), so the two worlds differ.
    """
    import tempfile

    from scenarios import HUMANOID
    from twin_cli.world import Pose, World

    with tempfile.TemporaryDirectory() as tmp:
        box = Path(tmp) / "box.urdf"
        box.write_text(BOX_URDF)
        boxes = World()
        side = round(SPAWN_WORLD**0.5)
        poses = [Pose(x=1.0 * (k % side), y=1.0 * (k // side), z=0.5) for k in range(SPAWN_WORLD)]
        boxes.spawn_batch(SpawnRequest(box, on_ground=True), base="b", poses=poses)
        return {
            "humanoids": _spawn_delete(_standing(SPAWN_WORLD), HUMANOID),
            "boxes": _spawn_delete(boxes, HUMANOID),
            "target_spawn_ms": 20.0,
        }


def _spawn_delete(world, source: Path) -> dict:  # noqa: ANN001
    from twin_cli.world import Pose

    spawns, deletes = [], []
    for k in range(SPAWN_REPEATS):
        start = time.perf_counter()
        world.spawn(source, name="extra", pose=Pose(x=-3.0, y=1.5 * k, z=1.3))
        spawns.append(time.perf_counter() - start)
        start = time.perf_counter()
        world.delete("extra")
        deletes.append(time.perf_counter() - start)
    start = time.perf_counter()
    world._state.spec.compile()  # MuJoCo alone, the floor under a spawn
    return {
        "spawn_ms": round(1e3 * statistics.median(spawns), 1),
        "delete_ms": round(1e3 * statistics.median(deletes), 1),
        "compile_ms": round(1e3 * (time.perf_counter() - start), 1),
    }


def _boosters() -> dict:
    """Spawn times [s] of booster_t1 number 1..BOOSTERS into one world (the first converts)."""
    from twin_cli.world import Pose, World

    if not BOOSTER.is_file():
        return {"skipped": f"{BOOSTER} not found"}
    world = World()
    times, cached = [], []
    for k in range(BOOSTERS):
        start = time.perf_counter()
        result = world.spawn(BOOSTER, name=f"t{k}", pose=Pose(x=1.2 * k, z=1.0))
        times.append(round(time.perf_counter() - start, 3))
        cached.append(result.cached)
    return {
        "spawn_s": times,
        "cached": cached,
        "tenth_over_first": round(times[-1] / times[0], 2),
        "tenth_over_second": round(times[-1] / times[1], 2),
    }


def run() -> dict:
    threads = max(2, len(os.sched_getaffinity(0)))
    scaling = {str(n): _unthrottled(n, threads) for n in ROBOT_COUNTS}
    best = max(
        (1, threads), key=lambda t: scaling["64"]["factor_pool" if t > 1 else "factor_single"]
    )
    return {
        "threads": threads,
        "unthrottled": scaling,
        "realtime_64_factor": _realtime(64, best),
        "realtime_64_threads": best,
        "realtime_64_sleeping": _realtime_sleeping(64),
        "spawn_into_50": _spawn_latency(),
        "booster_t1": _boosters(),
        "load_average_1min": os.getloadavg()[0],
        "cpus": os.cpu_count(),
    }
