"""Recording figures in one run: what a 100 Hz recording costs the unthrottled loop, and the
real-time factor while recording and streaming to Foxglove (issue 12).

Targets: the unthrottled world steps at ≥ 0.95 of its speed without a recording (median of
alternating pairs on the same world, same steps), and real time holds 1.00 ± 0.01 while a
recording and a Foxglove stream run. On a shared 2-core machine single pairs swing widely; the
load average is recorded with the figures.
"""

from __future__ import annotations

import os
import statistics
import tempfile
import time
from pathlib import Path

from twin_cli.record import BagSink, LiveStream, Recording
from twin_cli.world import Pose, World, WorldSettings

HUMANOID = Path(__file__).parents[1] / "scenarios" / "robots" / "humanoid.urdf.xacro"
RATE = 100.0  # [Hz] of sim time
STEPS = 3000  # per window (3 s of sim time, 300 samples)
PAIRS = 7
REALTIME_SECONDS = 10.0  # [s]
TARGETS = {"record_vs_plain": 0.95, "realtime_factor": (0.99, 1.01)}


def _world(rate: float = 0.0) -> World:
    world = World(WorldSettings(rate=rate))
    world.spawn(HUMANOID, name="h", pose=Pose(z=1.0))
    return world


def _window(world: World, out: Path | None) -> float:
    """Steps/s of `world.step(STEPS)` (a batch as the loop runs it), recording into `out`."""
    recording = Recording(world, [BagSink(out)], rate=RATE).start() if out else None
    start = time.perf_counter()
    for _ in range(STEPS // 500):
        world.step(500)
    took = time.perf_counter() - start
    if recording is not None:
        recording.stop()
    return STEPS / took


def throughput(tmp: Path) -> dict:
    """Recording vs plain, alternating pairs on one world (it keeps falling and lying)."""
    world = _world()
    world.step(2000)  # settled on the ground: the same contacts in every window
    ratios, plain, recorded = [], [], []
    for k in range(PAIRS):
        p = _window(world, None)
        r = _window(world, tmp / f"pair{k}.mcap")
        plain.append(p)
        recorded.append(r)
        ratios.append(r / p)
    return {
        "record_vs_plain_median": statistics.median(ratios),
        "ratios": [round(x, 3) for x in ratios],
        "plain_steps_per_s": statistics.median(plain),
        "recording_steps_per_s": statistics.median(recorded),
        "samples_per_wall_s": statistics.median(recorded) / 1000.0 * RATE,
    }


def realtime(tmp: Path) -> dict:
    """Real-time factor over 10 s with a 100 Hz recording and a 30 Hz Foxglove stream."""
    world = _world(rate=1000.0)
    live = LiveStream(port=0)
    recording = Recording(world, [BagSink(tmp / "rt.mcap")], rate=RATE).start()
    stream = Recording(world, [live], rate=30.0, latest_only=True).start()
    world.start()
    time.sleep(REALTIME_SECONDS)
    stats, figures = world.stats(), world.loop_figures()
    world.stop()
    recorded, streamed = recording.stop(), stream.stop()
    return {
        "factor": stats.factor,
        "sim_over_wall": stats.sim_time / stats.real_time,
        "dropped_steps": figures.dropped,
        "recorded_samples": recorded.samples,
        "streamed_samples": streamed.samples,
    }


def run() -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        return {
            "load_average": os.getloadavg()[0],
            "throughput": throughput(Path(tmp)),
            "realtime": realtime(Path(tmp)),
            "targets": TARGETS,
        }
