"""Recording figures in one run: what a 100 Hz recording costs the unthrottled loop, and the
real-time factor while recording and streaming to Foxglove.

Targets: the unthrottled world steps at ≥ 0.95 of its speed without a recording, and real time
holds 1.00 ± 0.01 while a recording and a Foxglove stream run. The throughput ratio alternates
sampling off and on every 2,000 steps of one world with one recording (benchmarks/paired.py).
On this 2-vCPU VM single pairs range 0.8-1.1 (the machine's speed drifts by ±25 % within
seconds), so 100 pairs are summed: repeated runs agree within about ±1.5 %. The wall ratio
counts the encoder process's CPU against the loop (a second core kept busy slows `mj_step` by up
to 9 % on this VM, a quarter-busy one not measurably); the loop-CPU ratio is what sampling adds
to the stepping thread. The encoder's CPU per sample is read from /proc.

The encoder works in cycles (it waits up to 50 ms for the ring to fill, then encodes what it
holds), so a 0.1 s window is not a long run in small: its work may start late and end after the
window. Each sampled window is therefore framed by ROLL untimed steps that also sample, before
(the encoder is in its cycle when timing starts) and after (its tail runs beside sampling, as
in a long run); then sampling stops and the next plain window waits, untimed, until the encoder
has written everything, so none of its work runs beside a plain window.
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
ROLL = 3000  # [steps] sampled, untimed, before and after a sampled arm: > the encoder's cycle
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
    recording = BagRecording(world, tmp / "bench.mcap", rate=RATE).start()  # one sample now
    recording.ready()  # the steady state: not the encoder's imports
    recording.set_sampling(False)
    taken = [1]  # samples taken so far, all of which the encoder is to write
    per_window = round(WINDOW * world.model.opt.timestep * RATE)  # samples in WINDOW steps
    per_roll = round(ROLL * world.model.opt.timestep * RATE)

    def plain() -> None:
        world.step(WINDOW)

    def prepare() -> None:  # the encoder in its steady cycle when the sampled window starts
        recording.set_sampling(True)
        world.step(ROLL)

    def sampled() -> None:
        world.step(WINDOW)

    def settle() -> None:  # the encoder's tail runs beside more sampling, then ends, untimed
        world.step(ROLL)
        recording.set_sampling(False)
        taken[0] += 2 * per_roll + per_window
        _wait_encoded(recording, taken[0])

    plain_s = time.perf_counter()
    world.step(WINDOW * 4)
    plain_rate = WINDOW * 4 / (time.perf_counter() - plain_s)
    _wait_encoded(recording, taken[0])
    encoder_cpu, first = _process_cpu(recording), taken[0]
    paired = {"pairs": PAIRS, "prepare": prepare, "settle": settle}
    wall = interleaved_ratio(plain, sampled, **paired)
    cpu = interleaved_ratio(plain, sampled, clock=time.thread_time, **paired)
    encoder_cpu = (_process_cpu(recording) - encoder_cpu) / (taken[0] - first)
    status = recording.stop()
    return {
        "record_vs_plain": wall,
        "record_vs_plain_loop_cpu": cpu,
        "plain_steps_per_s": plain_rate,
        "samples_per_wall_s": plain_rate / 1000.0 * RATE,
        "recorded_samples": status.samples,
        "recorder_blocked_s": status.blocked_s,
        "encoder_cpu_per_sample_us": encoder_cpu * 1e6,
    }


def _wait_encoded(recording: BagRecording, samples: int) -> None:
    """Until the encoder has written `samples` samples (a sampled arm takes an exact number)."""
    deadline = time.monotonic() + 30.0
    while recording.status().samples < samples:
        if time.monotonic() > deadline:
            raise RuntimeError(f"the encoder wrote {recording.status().samples} of {samples}")
        time.sleep(0.0005)


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
