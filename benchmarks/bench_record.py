"""Recording figures in one run: what a 100 Hz recording costs the unthrottled loop, and the
real-time factor while recording and streaming to Foxglove (issue 12).

Targets: the unthrottled world steps at ≥ 0.95 of its speed without a recording, and real time
holds 1.00 ± 0.01 while a recording and a Foxglove stream run. The throughput ratio alternates
sampling off and on every 2,000 steps of one world with one recording (benchmarks/paired.py):
five long windows swung 0.58-1.13 on this VM, 40 short pairs repeat within about 1 %. The wall
ratio counts the encoder process's CPU against the loop (a busy second core alone slows `mj_step`
by about 5 % on this VM); the loop-CPU ratio is what sampling adds to the stepping thread.
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

from benchmarks.paired import interleaved_ratio
from twin_cli.record import BagRecording, LiveStream, Recording
from twin_cli.world import Pose, World, WorldSettings

HUMANOID = Path(__file__).parents[1] / "scenarios" / "robots" / "humanoid.urdf.xacro"
RATE = 100.0  # [Hz] of sim time
WINDOW = 2000  # [steps] per arm: 2 s of sim time, ~0.1 s of wall
PAIRS = 40  # alternations per ratio (benchmarks/paired.py)
REALTIME_SECONDS = 10.0  # [s]
TARGETS = {"record_vs_plain": 0.95, "realtime_factor": (0.99, 1.01)}


def _world(rate: float = 0.0) -> World:
    world = World(WorldSettings(rate=rate))
    world.spawn(HUMANOID, name="h", pose=Pose(z=1.0))
    return world


def throughput(tmp: Path) -> dict:
    """Recording vs plain on one world and one running recording, alternating every WINDOW steps
    (sampling suspended in the plain arm): wall time, which counts the encoder process's CPU
    against the loop when the machine has no idle core, and the stepping thread's own CPU."""
    world = _world()
    world.step(2000)  # settled on the ground: the same contacts in every window
    recording = BagRecording(world, tmp / "bench.mcap", rate=RATE).start()
    recording.ready()  # the steady state: not the encoder's imports

    def arm(on: bool):  # noqa: ANN202
        def run() -> None:
            recording.set_sampling(on)
            world.step(WINDOW)

        return run

    plain_s = time.perf_counter()
    world.step(WINDOW * 4)
    plain_rate = WINDOW * 4 / (time.perf_counter() - plain_s)
    wall = interleaved_ratio(arm(False), arm(True), pairs=PAIRS)
    cpu = interleaved_ratio(arm(False), arm(True), pairs=PAIRS, clock=time.thread_time)
    status = recording.stop()
    return {
        "record_vs_plain": wall,
        "record_vs_plain_loop_cpu": cpu,
        "plain_steps_per_s": plain_rate,
        "samples_per_wall_s": plain_rate / 1000.0 * RATE,
        "recorded_samples": status.samples,
        "recorder_blocked_s": status.blocked_s,
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
