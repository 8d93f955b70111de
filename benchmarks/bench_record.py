"""Recording figures in one run: what a 100 Hz recording costs the unthrottled loop, and the
real-time factor while recording and streaming to Foxglove (issue 12).

Targets: the unthrottled world steps at ≥ 0.95 of its speed without a recording, and real time
holds 1.00 ± 0.01 while a recording and a Foxglove stream run. The throughput ratio alternates
sampling off and on every 2,000 steps of one world with one recording (benchmarks/paired.py).
On this 2-vCPU VM single pairs range 0.8-1.1 (the machine's speed drifts by ±25 % within
seconds), so 100 pairs are summed: repeated runs agree within about ±1.5 %. The wall ratio
counts the encoder process's CPU against the loop (a second core kept busy slows `mj_step` by up
to 9 % on this VM, a quarter-busy one not measurably); the loop-CPU ratio is what sampling adds
to the stepping thread. The encoder's CPU per sample is read from /proc. After each sampled
arm, the next plain arm waits (untimed) until the encoder has written that arm's samples: else
the encoder's last run (up to 50 ms of samples) would run beside the plain arm and flatter the
ratio.
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
PAIRS = 100  # alternations per ratio (benchmarks/paired.py)
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
    per_window = round(WINDOW * world.model.opt.timestep * RATE)  # samples in a sampled arm
    encoder_cpu, samples = _process_cpu(recording), recording.status().samples
    expected = [samples]

    def settle() -> None:  # the encoder's last samples must not run beside the next plain arm
        expected[0] += per_window
        deadline = time.monotonic() + 5.0
        while recording.status().samples < expected[0] and time.monotonic() < deadline:
            time.sleep(0.0005)

    wall = interleaved_ratio(arm(False), arm(True), pairs=PAIRS, settle=settle)
    cpu = interleaved_ratio(
        arm(False), arm(True), pairs=PAIRS, clock=time.thread_time, settle=settle
    )
    recording.set_sampling(False)
    while recording.status().samples < expected[0]:  # all encoded
        time.sleep(0.05)
    encoder_cpu = _process_cpu(recording) - encoder_cpu
    status = recording.stop()
    return {
        "record_vs_plain": wall,
        "record_vs_plain_loop_cpu": cpu,
        "plain_steps_per_s": plain_rate,
        "samples_per_wall_s": plain_rate / 1000.0 * RATE,
        "recorded_samples": status.samples,
        "recorder_blocked_s": status.blocked_s,
        "encoder_cpu_per_sample_us": encoder_cpu / (2 * PAIRS * per_window) * 1e6,
    }


def _process_cpu(recording: BagRecording) -> float:
    """User + system CPU [s] of the recording's encoder process so far (Linux /proc)."""
    fields = Path(f"/proc/{recording.encoder_pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


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
