"""Several clients at once for ~10 s (spawn, delete, gravity, stats): a consistent, live world."""

from __future__ import annotations

import threading
import time

import pytest
from models import block

from twin_cli.errors import EntityNotFoundError
from twin_cli.server.client import Client

WORLD = "busy"
DURATION_S = 10.0
BOX_URDF = block(size=0.2, name="box")


@pytest.fixture
def server(tmp_path, serve_world):
    with serve_world(tmp_path, WORLD) as (client, _):
        yield client


class Worker(threading.Thread):
    """Runs `action(client, i)` until the deadline; records errors other than expected races."""

    def __init__(self, action, deadline: float) -> None:
        super().__init__(daemon=True)
        self.action, self.deadline = action, deadline
        self.errors: list[BaseException] = []
        self.calls = 0

    def run(self) -> None:
        with Client(WORLD) as client:
            while time.monotonic() < self.deadline:
                try:
                    self.action(client, self.calls)
                except BaseException as exc:  # noqa: BLE001 - reported by the test
                    self.errors.append(exc)
                    return
                self.calls += 1


def test_concurrent_clients_leave_a_consistent_live_world(server, tmp_path):
    box = tmp_path / "box.urdf"
    box.write_text(BOX_URDF)
    alive: dict[str, set[str]] = {"a": set(), "b": set()}
    gravity_set: list[tuple[float, float, float]] = []
    samples: list[dict] = []

    def spawner(tag):
        def action(client, i):
            name = f"{tag}{i}"
            client.spawn(
                box, name=name, pose={"x": 0.5 * (i % 10), "y": 3.0 * (tag == "b"), "z": 1.0}
            )
            alive[tag].add(name)
            if i % 2:  # delete every other one, the one spawned before
                client.delete(f"{tag}{i - 1}")
                alive[tag].discard(f"{tag}{i - 1}")

        return action

    def gravity(client, i):
        vector = (0.0, 0.0, -1.62) if i % 2 else (0.0, 0.0, -9.81)
        client.set_gravity(vector=vector)
        gravity_set.append(vector)

    def stats(client, i):
        samples.append(client.stats())
        time.sleep(0.05)

    def reader(client, i):
        for entity in client.entities():
            try:
                client.pose(entity["name"])
            except EntityNotFoundError:
                pass  # deleted between list and pose: an expected race

    deadline = time.monotonic() + DURATION_S
    workers = [Worker(a, deadline) for a in (spawner("a"), spawner("b"), gravity, stats, reader)]
    for w in workers:
        w.start()
    for w in workers:
        w.join(timeout=DURATION_S + 120)
    errors = [e for w in workers for e in w.errors]
    assert not errors, f"client errors under concurrency: {errors[:3]}"
    calls = [w.calls for w in workers]
    assert min(calls) > 0, f"calls per worker: {calls}"

    client = server
    assert client.alive(), "server died under concurrent clients"
    names = {e["name"] for e in client.entities()}
    assert names == alive["a"] | alive["b"], f"entities {sorted(names)} vs expected"
    assert tuple(client.gravity()["gravity"]) == pytest.approx(gravity_set[-1])
    sim = [s["sim_time"] for s in samples]
    assert all(b >= a for a, b in zip(sim, sim[1:], strict=False)), "sim_time went backwards"
    assert sim[-1] > sim[0], "world stopped stepping under concurrent clients"
    before = client.stats()["sim_time"]
    time.sleep(0.3)
    assert client.stats()["sim_time"] > before, "world not stepping after the storm"
