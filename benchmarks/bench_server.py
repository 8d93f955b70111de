"""World server figures: `twin gravity --moon` wall time; server steps/s vs raw mj_step.

Targets (design.md §5): median client command under 250 ms wall against a running world; the
unthrottled server loop, while a `twin stats` client reads, keeps at least 95% of raw
`mj_step` throughput on the same model and state (the server's world saved and loaded here).

On a shared machine wall-clock rates swing with other people's load, so each figure is also
given per CPU second (the server process's user+system time, all threads, including the HTTP
thread answering `twin stats`; the command's own CPU time): that ratio does not depend on load.
"""

from __future__ import annotations

import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import scenarios
from twin_cli.server import runtime
from twin_cli.server.client import Client

WORLD = "bench"
COMMAND_RUNS = 15
WINDOW_S = 2.0  # [s] per throughput measurement
ROUNDS = 3  # server and raw alternately; the best of each, as background load only slows
GRAVITY_TARGET_S = 0.250
RATIO_TARGET = 0.95
CLOCK_TICK_S = 1.0 / os.sysconf("SC_CLK_TCK")


@dataclass(frozen=True)
class Rate:
    """Steps counted over a window of wall time [s] and of CPU time [s]."""

    steps: int
    wall_s: float
    cpu_s: float

    @property
    def per_wall_s(self) -> float:
        return self.steps / self.wall_s

    @property
    def per_cpu_s(self) -> float:
        return self.steps / self.cpu_s


def _twin(args: list[str], env: dict[str, str], **kwargs) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-m", "twin_cli.cli.app", *args, "--world", WORLD], env=env, **kwargs
    )


def _children_cpu_s() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _command_times(env: dict[str, str], args: list[str]) -> tuple[list[float], list[float]]:
    """Wall and CPU time [s] of `twin ARGS`, process start to exit, COMMAND_RUNS times."""
    walls, cpus = [], []
    for _ in range(COMMAND_RUNS):
        cpu0, start = _children_cpu_s(), time.perf_counter()
        if _twin(args, env, stdout=subprocess.DEVNULL).wait() != 0:
            raise RuntimeError(f"twin {' '.join(args)} failed")
        walls.append(time.perf_counter() - start)
        cpus.append(_children_cpu_s() - cpu0)
    return walls, cpus


def _process_cpu_s(pid: int) -> float:
    """User + system CPU time [s] of process `pid`, all threads (/proc/PID/stat fields 14-15)."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) * CLOCK_TICK_S


def _server_rate(client: Client, env: dict[str, str], pid: int) -> Rate:
    """Unthrottled server steps over WINDOW_S while a `twin stats` process reads."""
    reader = _twin(["stats"], env, stdout=subprocess.DEVNULL)
    try:
        time.sleep(0.5)
        it0, t0, c0 = client.stats()["iterations"], time.perf_counter(), _process_cpu_s(pid)
        time.sleep(WINDOW_S)
        it1, t1, c1 = client.stats()["iterations"], time.perf_counter(), _process_cpu_s(pid)
    finally:
        reader.terminate()
        reader.wait()
    return Rate(it1 - it0, t1 - t0, c1 - c0)


def _raw_rate(model, data) -> Rate:
    """mj_step in this process, in batches of 100 steps, for WINDOW_S."""
    import mujoco

    steps, start, cpu0 = 0, time.perf_counter(), time.process_time()
    while time.perf_counter() - start < WINDOW_S:
        mujoco.mj_step(model, data, nstep=100)
        steps += 100
    return Rate(steps, time.perf_counter() - start, time.process_time() - cpu0)


def _throughput(client: Client, env: dict[str, str], pid: int, saved: Path) -> dict:
    """Server vs raw mj_step, alternating ROUNDS times on the same saved world."""
    from twin_cli.world import World

    client.set_physics(rate=0.0)
    client.pause()
    client.save(saved)
    raw_world = World.load(saved)
    server, raw = [], []
    for _ in range(ROUNDS):
        client.resume()
        server.append(_server_rate(client, env, pid))
        client.pause()
        with raw_world.lock:
            raw.append(_raw_rate(raw_world.model, raw_world.data))
    best = {
        "server_steps_per_wall_s": max(r.per_wall_s for r in server),
        "raw_steps_per_wall_s": max(r.per_wall_s for r in raw),
        "server_steps_per_cpu_s": max(r.per_cpu_s for r in server),
        "raw_steps_per_cpu_s": max(r.per_cpu_s for r in raw),
    }
    wall = best["server_steps_per_wall_s"] / best["raw_steps_per_wall_s"]
    cpu = best["server_steps_per_cpu_s"] / best["raw_steps_per_cpu_s"]
    return {
        **best,
        "server_over_raw_wall": wall,
        "server_over_raw_cpu": cpu,
        "target": RATIO_TARGET,
        "ok": cpu >= RATIO_TARGET,
    }


def _command_figures(env: dict[str, str]) -> dict:
    walls, cpus = _command_times(env, ["gravity", "--moon"])
    bare = []
    for _ in range(5):
        start = time.perf_counter()
        subprocess.run([sys.executable, "-c", "pass"], check=True)
        bare.append(time.perf_counter() - start)
    median = statistics.median(walls)
    return {
        "median_wall_s": median,
        "min_wall_s": min(walls),
        "max_wall_s": max(walls),
        "median_cpu_s": statistics.median(cpus),
        "python_startup_wall_s": statistics.median(bare),
        "target_s": GRAVITY_TARGET_S,
        "ok": median < GRAVITY_TARGET_S,
    }


def run() -> dict:
    """Start a server for the bundled humanoid in a private runtime dir, measure, stop it."""
    with tempfile.TemporaryDirectory(prefix="twin-bench-") as tmp:
        env = {**os.environ, runtime.RUNTIME_ENV: tmp}
        old = os.environ.get(runtime.RUNTIME_ENV)
        os.environ[runtime.RUNTIME_ENV] = tmp
        server = _twin(["serve"], env, stderr=subprocess.DEVNULL)
        client = Client(WORLD)
        try:
            runtime.wait_until(client.paths, client.alive, server, 120.0)
            client.spawn(scenarios.HUMANOID, pose={"z": 1.2})
            time.sleep(1.0)
            figures = {
                "gravity_moon": _command_figures(env),
                "throughput": _throughput(client, env, server.pid, Path(tmp) / "w.twin"),
                "load_average_1min": os.getloadavg()[0],
                "cpus": os.cpu_count(),
            }
        finally:
            client.close()
            server.terminate()
            server.wait(timeout=30)
            if old is None:
                os.environ.pop(runtime.RUNTIME_ENV, None)
            else:
                os.environ[runtime.RUNTIME_ENV] = old
    return figures
