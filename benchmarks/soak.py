"""Soak: 4 clients drive one world server for N minutes; errors must be 0, memory bounded.

`make soak` (SOAK_MINUTES, default 10) or `python -m benchmarks.soak --minutes 3`. A real
`twin serve` runs in a private runtime directory; four client threads, each with its own
connections, loop over: spawn a robot (a box or the bundled humanoid), read its pose and the
world's stats, change gravity, pause and resume, read the entity list, delete the robot. Every
request's reply is checked (the spawned name comes back, the pose is finite, the list holds the
entity until it is deleted). A sampler records the server's resident memory (VmRSS from
/proc) and the real-time factor every 5 s. Not part of `make test`: it runs for minutes.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import random
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import scenarios
from twin_cli.server import runtime
from twin_cli.server.client import Client

CLIENTS = 4
SAMPLE_S = 5.0  # [s] between memory and factor samples
BOX = """<robot name="box"><link name="base"><inertial><mass value="1"/>
<inertia ixx="0.0067" iyy="0.0067" izz="0.0067" ixy="0" ixz="0" iyz="0"/></inertial>
<collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision>
<visual><geometry><box size="0.2 0.2 0.2"/></geometry></visual></link></robot>"""


class Tally:
    """Requests served and errors, shared by the client threads."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.requests = 0
        self.errors: list[str] = []

    def call(self, what: str, function, *args, **kwargs):  # noqa: ANN001, ANN201
        try:
            result = function(*args, **kwargs)
        except Exception as exc:  # noqa: BLE001 - counted and reported, never hidden
            with self.lock:
                self.requests += 1
                self.errors.append(f"{what}: {type(exc).__name__}: {exc}")
            return None
        with self.lock:
            self.requests += 1
        return result

    def fail(self, what: str) -> None:
        with self.lock:
            self.errors.append(what)


def rss_mib(pid: int) -> float:
    """Resident memory [MiB] of process `pid` (VmRSS)."""
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    return math.nan


def client_loop(index: int, world: str, box: str, tally: Tally, stop: threading.Event) -> None:
    """One client's cycle until `stop`: spawn, pose, stats, gravity, pause/resume, list, delete."""
    rng = random.Random(index)
    client = Client(world)
    k = 0
    while not stop.is_set():
        k += 1
        name = f"c{index}-{k}"
        source = str(scenarios.HUMANOID) if k % 5 == 0 else box
        pose = {"x": 2.0 * index, "y": 0.5 * (k % 7), "z": 1.2}
        spawned = tally.call("spawn", client.spawn, source, name=name, pose=pose)
        if spawned is not None and spawned.get("name") != name:
            tally.fail(f"spawn returned {spawned.get('name')} for {name}")
        got = tally.call("pose", client.pose, name)
        if got is not None and not all(math.isfinite(got[key]) for key in ("x", "y", "z")):
            tally.fail(f"pose of {name} not finite: {got}")
        tally.call("stats", client.stats)
        preset = rng.choice(("earth", "moon", "mars", "earth"))
        tally.call("gravity", client.set_gravity, preset=preset)
        if k % 3 == 0:
            tally.call("pause", client.pause)
            time.sleep(0.05)
            tally.call("resume", client.resume)
        listed = tally.call("list", client.entities)
        if listed is not None and name not in {e["name"] for e in listed}:
            tally.fail(f"{name} missing from the list before its delete")
        tally.call("delete", client.delete, name)
    client.close()


def sampler(pid: int, client: Client, samples: list, stop: threading.Event) -> None:
    """Every SAMPLE_S: elapsed [s], resident memory [MiB], real-time factor, entities."""
    start = time.monotonic()
    while not stop.wait(SAMPLE_S):
        try:
            stats = client.stats()
            count = len(client.entities())
        except Exception as exc:  # noqa: BLE001
            stats, count = {"factor": math.nan, "error": str(exc)}, -1
        row = {
            "t": round(time.monotonic() - start, 1),
            "rss_mib": round(rss_mib(pid), 1),
            "factor": stats.get("factor"),
            "entities": count,
        }
        samples.append(row)
        print(json.dumps(row), file=sys.stderr, flush=True)


def run(minutes: float) -> dict:
    """Soak one world for `minutes`; returns the figures (and the errors, which must be none)."""
    with tempfile.TemporaryDirectory(prefix="twin-soak-") as tmp:
        os.environ[runtime.RUNTIME_ENV] = tmp
        box = Path(tmp) / "box.urdf"
        box.write_text(BOX)
        world = "soak"
        server = subprocess.Popen(
            [sys.executable, "-m", "twin_cli.cli.app", "serve", "--world", world],
            stdout=subprocess.DEVNULL,
            stderr=open(Path(tmp) / "serve.err", "wb"),  # noqa: SIM115
        )
        probe = Client(world)
        runtime.wait_until(probe.paths, probe.alive, server, runtime.START_TIMEOUT_S)
        pid = runtime.read_pid(probe.paths) or server.pid
        tally, samples, stop = Tally(), [], threading.Event()
        rss_start = rss_mib(pid)
        threads = [threading.Thread(target=sampler, args=(pid, probe, samples, stop))]
        threads += [
            threading.Thread(target=client_loop, args=(i, world, str(box), tally, stop))
            for i in range(CLIENTS)
        ]
        started = time.monotonic()
        for thread in threads:
            thread.start()
        stop.wait(minutes * 60)
        stop.set()
        for thread in threads:
            thread.join()
        elapsed = time.monotonic() - started
        rss_end = rss_mib(pid)
        alive = server.poll() is None
        server.terminate()
        server.wait(timeout=30)
    factors = [s["factor"] for s in samples if isinstance(s["factor"], float)]
    return {
        "minutes": round(elapsed / 60, 2),
        "clients": CLIENTS,
        "requests": tally.requests,
        "requests_per_s": round(tally.requests / elapsed, 1),
        "errors": len(tally.errors),
        "first_errors": tally.errors[:10],
        "server_alive_at_end": alive,
        "rss_mib_start": round(rss_start, 1),
        "rss_mib_end": round(rss_end, 1),
        "rss_mib_max": max((s["rss_mib"] for s in samples), default=math.nan),
        "factor_min": min(factors, default=math.nan),
        "factor_mean": round(sum(factors) / len(factors), 3) if factors else math.nan,
        "factor_max": max(factors, default=math.nan),
        "samples": samples,
    }


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=float(os.environ.get("SOAK_MINUTES", 10)))
    figures = run(parser.parse_args(argv).minutes)
    summary = {k: v for k, v in figures.items() if k != "samples"}
    print(json.dumps(summary, indent=2))
    return 0 if figures["errors"] == 0 and figures["server_alive_at_end"] else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
