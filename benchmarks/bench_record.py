"""Recording figures in one run: what a 100 Hz recording costs the unthrottled loop, and the
real-time factor while recording and streaming to Foxglove (issue 12).

Targets: the unthrottled world steps at ≥ 0.95 of its speed without a recording (median of
alternating pairs on the same world, same steps), and real time holds 1.00 ± 0.01 while a
recording and a Foxglove stream run. On a shared 2-core machine single pairs swing widely; the
load average is recorded with the figures. The wall ratio counts the encoder process's CPU
against the loop when the machine has no idle core; the loop-CPU ratio (the stepping thread's
own CPU time per step) is what the recorder adds to the loop itself. The thread recorder
(encoding in the loop's process, the design before issue 12's second pass) is measured in the
same run for comparison.
"""

from __future__ import annotations

import os
import statistics
import tempfile
import time
from pathlib import Path

from twin_cli.record import BagRecording, BagSink, LiveStream, Recording
from twin_cli.world import Pose, World, WorldSettings

HUMANOID = Path(__file__).parents[1] / "scenarios" / "robots" / "humanoid.urdf.xacro"
RATE = 100.0  # [Hz] of sim time
STEPS = 10000  # per window (10 s of sim time, 1,000 samples)
PAIRS = 5
REALTIME_SECONDS = 10.0  # [s]
TARGETS = {"record_vs_plain": 0.95, "realtime_factor": (0.99, 1.01)}


def _world(rate: float = 0.0) -> World:
    world = World(WorldSettings(rate=rate))
    world.spawn(HUMANOID, name="h", pose=Pose(z=1.0))
    return world


def _recorder(world: World, out: Path, kind: str):  # noqa: ANN202
    if kind == "thread":  # before: encoded in a thread of the loop's process
        return Recording(world, [BagSink(out)], rate=RATE).start()
    recording = BagRecording(world, out, rate=RATE).start()  # encoder process
    recording.ready()  # the steady state: not the encoder's imports
    return recording


def _window(world: World, out: Path | None, kind: str = "process") -> tuple[float, float]:
    """Steps/s of `world.step` batches (as the loop runs them), by wall and by the stepping
    thread's CPU time, recording into `out` with the `kind` recorder (None: no recording)."""
    recording = _recorder(world, out, kind) if out else None
    start, cpu = time.perf_counter(), time.thread_time()
    for _ in range(STEPS // 500):
        world.step(500)
    took, cpu = time.perf_counter() - start, time.thread_time() - cpu
    if recording is not None:
        recording.stop()
    return STEPS / took, STEPS / cpu


def throughput(tmp: Path) -> dict:
    """Recording vs plain, alternating windows on one world (it keeps falling and lying): the
    process recorder (now) and the thread recorder (before), in the same run."""
    world = _world()
    world.step(2000)  # settled on the ground: the same contacts in every window
    wall: dict[str, list[float]] = {"process": [], "thread": []}
    cpu: dict[str, list[float]] = {"process": [], "thread": []}
    plain = []
    for k in range(PAIRS):
        for kind in ("process", "thread"):
            p, pc = _window(world, None)
            r, rc = _window(world, tmp / f"{kind}{k}.mcap", kind)
            wall[kind].append(r / p)
            cpu[kind].append(rc / pc)
            plain.append(p)
    return {
        "record_vs_plain_median": statistics.median(wall["process"]),
        "record_vs_plain_loop_cpu_median": statistics.median(cpu["process"]),
        "ratios": [round(x, 3) for x in wall["process"]],
        "before_thread_recorder_vs_plain_median": statistics.median(wall["thread"]),
        "before_thread_recorder_loop_cpu_median": statistics.median(cpu["thread"]),
        "plain_steps_per_s": statistics.median(plain),
        "samples_per_wall_s": statistics.median(plain) / 1000.0 * RATE,
    }


def realtime(tmp: Path) -> dict:
    """Real-time factor over 10 s with a 100 Hz recording and a 30 Hz Foxglove stream."""
    world = _world(rate=1000.0)
    live = LiveStream(port=0)
    recording = BagRecording(world, tmp / "rt.mcap", rate=RATE).start()
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
        "recorder_blocked_s": recorded.blocked_s,
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
