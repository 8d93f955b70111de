"""A world file saved before twin pushed a Gazebo PID's `cmd_offset` beside its integral and ran
gz-sim's VelocityControl still loads, state intact: written by twin at commit 7748c28 (a 1 kg bar
0.5 m out held at 0 by a JointPositionController, p 100, d 2, `cmd_offset` 3, gz-math's default
integral; and a slab whose VelocityControl twin did not run then; saved 0.3 s after the
command). The bar's joint now has the integral as an activation and a `hinge:offset` actuator,
the slab three planar servos; each is added empty and every other saved value keeps its place.
Oracle: the file's own state, and gz-math's PID integrated by hand from the saved angle and
speed with an empty integral and the offset."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from old_saves import placed_save
from pid_law import gz_held_bar

from twin_cli.world.savefile import load

NAME = "pushes_saved_before_offsets"


def test_the_bar_goes_on_from_its_saved_state_with_its_offset_and_an_empty_integral(
    tmp_path: Path,
) -> None:
    save = placed_save(NAME, ("bar", "slab.sdf"), tmp_path)
    doc = json.loads(save.read_text())
    world = load(save)
    model, state = world.model, doc["state"]
    assert (model.nu, model.na) == (doc["layout"]["nu"] + 4, doc["layout"]["na"] + 1)
    joint = model.joint("bar/hinge")
    saved = (state[1 + joint.qposadr[0]], state[1 + model.nq + joint.dofadr[0]])
    now = world.joint_states("bar")[0]
    assert (now.position, now.velocity) == pytest.approx(saved, abs=1e-12), "the bar as saved"
    slab = model.joint("slab/floating_base")
    assert world.data.qpos[slab.qposadr[0] : slab.qposadr[0] + 7] == pytest.approx(
        state[1 + slab.qposadr[0] : 1 + slab.qposadr[0] + 7], abs=1e-12
    ), "the slab where it was saved"
    law = gz_held_bar(
        (100.0, 0.1, 2.0), 1.0, 2.0, inertia=0.2501, load=4.905, start=saved, every=0.5,
        offset=3.0,
    )  # fmt: skip
    angles = []
    for _ in law:
        world.step(round(0.5 / model.opt.timestep))
        angles.append(world.joint_states("bar")[0].position)
    assert angles == pytest.approx(law, abs=2e-5), f"bar [rad]: {angles}"
