"""A world file saved before a gz-sim PID's integral ran still loads, state intact: written by
twin at commit d1a6240 (a 1 kg bar 0.5 m out held at 0 by a JointPositionController, p 100, d 2,
gz-math's default integral 0.1 within ±1; and a rig whose fan runs at 3 rad/s on its velocity
motor and whose dial is held at 1 rad by another; saved 0.3 s after the commands). Those
joints' actuators now carry the integral as an activation the file does not have: each is
added empty, and every other saved value keeps its place. Oracle: the file's own state, and
gz-math's PID integrated by hand from the saved angle and speed with an empty integral."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from old_saves import placed_save
from pid_law import gz_held_bar

from twin_cli.world.savefile import load

NAME = "pid_saved_before_integral"


@pytest.fixture
def save(tmp_path: Path) -> Path:
    """The file, naming the robots' URDFs where this test put them."""
    return placed_save(NAME, ("bar", "rig"), tmp_path)


def test_each_joint_goes_on_from_its_saved_state_with_an_empty_integral(save: Path) -> None:
    doc = json.loads(save.read_text())
    world = load(save)
    model, state = world.model, doc["state"]
    saved = {}
    for name in ("bar/hinge", "rig/fan_joint", "rig/dial_joint"):
        joint = model.joint(name)
        saved[name] = (state[1 + joint.qposadr[0]], state[1 + model.nq + joint.dofadr[0]])
    states = {f"{e}/{s.name}": (s.position, s.velocity) for e in ("bar", "rig")
              for s in world.joint_states(e)}  # fmt: skip
    for name, (position, velocity) in saved.items():
        assert states[name] == pytest.approx((position, velocity), abs=1e-12), name
    assert model.na == doc["layout"]["na"] + 2, "one integral for the bar, one for the dial"
    law = gz_held_bar(
        (100.0, 0.1, 2.0), 1.0, 2.0, inertia=0.2501, load=4.905, start=saved["bar/hinge"],
        every=0.5,
    )  # fmt: skip
    angles = []
    for _ in law:
        world.step(round(0.5 / model.opt.timestep))
        angles.append({s.name: s for s in world.joint_states("bar")}["hinge"].position)
    assert angles == pytest.approx(law, abs=2e-5), f"bar [rad]: {angles}"
    rig = {s.name: s for s in world.joint_states("rig")}
    assert rig["fan_joint"].velocity == pytest.approx(3.0, rel=1e-3), "the fan's command kept"
    assert rig["dial_joint"].position == pytest.approx(1.0, abs=2e-3), "the dial's target kept"
