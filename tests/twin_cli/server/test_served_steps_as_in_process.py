"""A served world steps as `twin_cli.World` does: the same humanoid, spawned at the same pose
and given the same joint commands, ends in the same integration state in `twin serve` (its
conversion read in a bounded child and built again from the replayed reads, its pose through
JSON, its steps in the server's request thread) as in an in-process World.

Why the tolerance is tight: the humanoid dropped from 1.3 m lands and then tips over slowly
from its feet, so the drop amplifies any difference. Measured on the bundled humanoid, one ulp
of spawn height (2.2e-16 m) is 3.4e-7 m of base position 2 s later, and a free box resting
50 m away in the same world is 6.3e-7 m (the humanoid's qpos differs by 1e-19 from the second
step on, in the air, before any contact). Agreement to `TOLERANCE` therefore means that the
served world runs the very same arithmetic on the very same entities. Measured: the two
states are bit-identical (largest difference 0.0) after the drop, after each command and
after a second spawn into the stepped world; the test fails (4.8e-8 to 9.8) when the served
world's spawn pose passes through float32, its spec through MJCF text, or it sleeps.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import scenarios
from twin_cli.world import World
from twin_cli.world.pose import Pose

TOLERANCE = 1e-9  # [m, rad, m/s, rad/s] largest difference of any integration state value
DROP_STEPS = 2000  # 2 s at the default 1 ms step
FIRST = {"x": 0.37, "y": -1.1, "z": 1.3, "yaw": 0.7}  # [m, rad] decimals no float holds exactly
SECOND = {"x": -2.3, "y": 1.9, "z": 1.3, "roll": 0.05, "pitch": -0.1, "yaw": -2.4}
# (entity, mode, {joint: target [rad, rad/s or N m]}, steps after it): all three modes, held,
# replaced and switched, on arms, legs and the neck.
COMMANDS = [
    ("h", "position", {"left_shoulder": 0.6, "right_elbow": -0.4, "left_hip": 0.2}, 700),
    ("h", "velocity", {"neck": 0.5, "right_knee": 1.0}, 300),
    ("h", "effort", {"left_ankle": 2.0, "right_shoulder": -3.0}, 500),
    ("h", "position", {"left_shoulder": -0.3, "neck": 0.0, "right_knee": 0.8}, 1000),
]
AFTER_SECOND = [
    ("g", "position", {"left_hip": -0.3, "right_hip": 0.3}, 400),
    ("h", "velocity", {"left_elbow": -2.0}, 600),
]


def _served_state(client, path) -> tuple[dict, np.ndarray]:
    client.save(path)
    document = json.loads(path.read_text())
    return document["layout"], np.array(document["state"], dtype=float)


def _local_state(world: World) -> tuple[dict, np.ndarray]:
    snapshot = world.snapshot()
    return dict(snapshot.layout), np.asarray(snapshot.state, dtype=float)


def _agree(client, world: World, path, when: str) -> None:
    served_layout, served = _served_state(client, path)
    local_layout, local = _local_state(world)
    assert served_layout == local_layout, when
    worst = float(np.abs(served - local).max())
    assert worst <= TOLERANCE, f"{when}: served and in-process states differ by {worst:.3g}"
    for name in world.entity_names():
        pose, here = client.pose(name), world.get_pose(name).to_dict()
        assert pose == pytest.approx(here, abs=TOLERANCE), f"{when}: {name} {pose} {here}"


def _command_and_step(client, world: World, plan: list, path) -> None:
    for entity, mode, targets, steps in plan:
        client.command_joints(entity, targets, mode)
        world.command_joints(entity, targets, mode=mode)
        client.step(steps)
        world.step(steps)
        _agree(client, world, path, f"{steps} steps after {mode} {targets} on {entity}")


def test_a_served_humanoid_drops_and_moves_as_in_a_world(tmp_path, serve_world):
    source = str(scenarios.HUMANOID)
    save = tmp_path / "served.json"
    world = World(name="local")
    with serve_world(tmp_path / "rt", "served_as_world", "--paused") as (client, _):
        client.spawn(source, name="h", pose=FIRST)
        world.spawn(source, name="h", pose=Pose(**FIRST))
        _agree(client, world, save, "at spawn")
        client.step(DROP_STEPS)
        world.step(DROP_STEPS)
        _agree(client, world, save, "after a 2 s drop from 1.3 m")
        _command_and_step(client, world, COMMANDS, save)
        client.spawn(source, name="g", pose=SECOND)  # a recompile of a world that has run
        world.spawn(source, name="g", pose=Pose(**SECOND))
        _agree(client, world, save, "after a second spawn")
        _command_and_step(client, world, AFTER_SECOND, save)
