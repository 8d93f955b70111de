"""World server figures: `twin gravity --moon` wall time; server steps/s vs raw mj_step.

Targets (design.md §5): median client command under 250 ms wall against a running world; the
unthrottled server loop, while a `twin stats` client reads, keeps at least 95% of raw
`mj_step` throughput on the same model and state (the server's world saved and loaded here).
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import scenarios
from twin_cli import runtime
from twin_cli.client import Client

WORLD = "bench"
COMMAND_RUNS = 15
WINDOW_S = 2.0  # [s] per throughput measurement
ROUNDS = 3  # server and raw alternately; the best of each, as background load only slows
GRAVITY_TARGET_S = 0.250
RATIO_TARGET = 0.95


def _twin(args: list[str], env: dict[str, str], **kwargs) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-m", "twin_cli.app", *args, "--world", WORLD], env=env, **kwargs
    )


def _command_wall_times(env: dict[str, str]) -> list[float]:
    """Wall time [s] of `twin gravity --moon`, process start to exit, COMMAND_RUNS times."""
    times = []
    for _ in range(COMMAND_RUNS):
        start = time.perf_counter()
        proc = _twin(["gravity", "--moon"], env, stdout=subprocess.DEVNULL)
        if proc.wait() != 0:
            raise RuntimeError("twin gravity --moon failed")
        times.append(time.perf_counter() - start)
    return times


def _python_startup_s() -> float:
    """Median wall time [s] of a bare `python -c pass`: the floor under any CLI command."""
    times = []
    for _ in range(5):
        start = time.perf_counter()
        subprocess.run([sys.executable, "-c", "pass"], check=True)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def _server_steps_per_s(client: Client, env: dict[str, str]) -> float:
    """Unthrottled server steps/s over WINDOW_S while a `twin stats` process reads."""
    reader = _twin(["stats"], env, stdout=subprocess.DEVNULL)
    try:
        time.sleep(0.5)
        first, t0 = client.stats()["iterations"], time.perf_counter()
        time.sleep(WINDOW_S)
        last, t1 = client.stats()["iterations"], time.perf_counter()
    finally:
        reader.terminate()
        reader.wait()
    return (last - first) / (t1 - t0)


def _raw_steps_per_s(model, data) -> float:
    """mj_step throughput [steps/s] in this process, in batches of 100 steps, for WINDOW_S."""
    import mujoco

    steps, start = 0, time.perf_counter()
    while time.perf_counter() - start < WINDOW_S:
        mujoco.mj_step(model, data, nstep=100)
        steps += 100
    return steps / (time.perf_counter() - start)


def _measure(client: Client, env: dict[str, str], saved: Path) -> dict:
    from twin_cli.world import World

    client.pause()
    client.save(saved)
    raw_world = World.load(saved)
    server, raw = [], []
    for _ in range(ROUNDS):
        client.resume()
        server.append(_server_steps_per_s(client, env))
        client.pause()
        with raw_world.lock:
            raw.append(_raw_steps_per_s(raw_world.model, raw_world.data))
    return {
        "server_steps_per_s": max(server),
        "raw_mj_step_per_s": max(raw),
        "server_samples": server,
        "raw_samples": raw,
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
            times = _command_wall_times(env)
            client.set_physics(rate=0.0)
            figures = _measure(client, env, Path(tmp) / "world.twin")
        finally:
            client.close()
            server.terminate()
            server.wait(timeout=30)
            if old is None:
                os.environ.pop(runtime.RUNTIME_ENV, None)
            else:
                os.environ[runtime.RUNTIME_ENV] = old
    ratio = figures["server_steps_per_s"] / figures["raw_mj_step_per_s"]
    median = statistics.median(times)
    return {
        "gravity_moon_wall_s": {
            "median": median,
            "min": min(times),
            "max": max(times),
            "target": GRAVITY_TARGET_S,
            "ok": median < GRAVITY_TARGET_S,
            "python_startup": _python_startup_s(),
        },
        **figures,
        "server_over_raw": ratio,
        "server_over_raw_target": RATIO_TARGET,
        "server_over_raw_ok": ratio >= RATIO_TARGET,
    }
